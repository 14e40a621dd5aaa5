// A study's table on disk: CSV parts (a comment line that says which study and rows they hold,
// the header, one row per sample), written whole or not at all, read back and checked for
// `--merge` and for resuming an interrupted run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kdl_space/study/study.hpp"

namespace kdl_space::cli {

/// Rows [begin, end) of a study, row-major, studyColumns() wide.
struct StudyPart {
  std::uint64_t begin = 0, end = 0;
  std::vector<double> rows;
};

/// The study's fingerprint as the table's head line and the summary JSON write it (16 hex digits).
std::string fingerprintText(const Study& study);

/// \brief Writes rows [begin, end) to `path` (under a temporary name, renamed into place).
/// `option` names the file in messages. Throws InputError if it cannot be written.
void writeStudyPart(const std::string& path, const std::string& option, const Study& study,
                    const std::vector<std::string>& columns, std::uint64_t begin, std::uint64_t end,
                    const double* rows);

/// \brief Reads a part written by writeStudyPart and checks it is this study's (fingerprint,
/// sample count, columns) and complete (its rows are begin..end-1, each with every column).
/// Throws InputError "PATH: what is wrong".
StudyPart readStudyPart(const std::string& path, const Study& study, const std::vector<std::string>& columns);

}  // namespace kdl_space::cli
