// A study's table on disk: CSV parts (a comment line that says which study and rows they hold,
// the header, one row per sample, a last comment line with the rows' checksum), written whole or
// not at all and read back row by row, each checked (for `--merge`, for resuming an interrupted
// run, for the summary and the plots); the lock that keeps two runs off one table; the
// temporaries that killed runs left behind.
#pragma once

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space {

/// The study's fingerprint as the table's head line and the summary JSON write it (16 hex digits).
KDL_SPACE_EXPORT std::string fingerprintText(const Study& study);

/// \brief CRC-32 (IEEE 802.3, the polynomial of zlib's and Python's `zlib.crc32`) of `n` bytes
/// continued from `crc` (0 to start). The table's checksum: any change of up to 32 bits in a row
/// (a digit cut or changed, a line dropped) changes it.
KDL_SPACE_EXPORT std::uint32_t crc32(std::uint32_t crc, const char* data, std::size_t n);

/// \brief Writes rows [begin, end) of a study to `path` as they come (under a temporary name,
/// renamed into place by commit(), after the trailer with the rows' checksum). `option` names the
/// file in messages. Throws InputError if it cannot be written.
class KDL_SPACE_EXPORT StudyTableWriter {
 public:
  StudyTableWriter(const std::string& path, const std::string& option, const Study& study,
                   const std::vector<std::string>& columns, std::uint64_t begin, std::uint64_t end);
  ~StudyTableWriter();
  StudyTableWriter(const StudyTableWriter&) = delete;
  StudyTableWriter& operator=(const StudyTableWriter&) = delete;
  /// The next row: columns.size() values (sample and status written as whole numbers, the rest
  /// with 17 significant digits: they read back exactly).
  void addRow(const double* row);
  /// The next row as its text (a line of a part already checked, without its newline).
  void addLine(const std::string& line);
  /// Writes the last line (rows and checksum), flushes and renames the file into place (fsync'd).
  void commit();

 private:
  void put(const char* text, std::size_t n);
  AtomicFile file_;
  std::string option_;
  std::FILE* f_ = nullptr;
  std::uint64_t begin_, end_, rows_ = 0;
  std::size_t columns_;
  std::uint32_t crc_ = 0;
};

/// Writes rows [begin, end) (row-major, columns.size() wide) to `path`, whole or not at all.
KDL_SPACE_EXPORT void writeStudyPart(const std::string& path, const std::string& option, const Study& study,
                    const std::vector<std::string>& columns, std::uint64_t begin, std::uint64_t end,
                    const double* rows);

/// \brief Reads a part written by StudyTableWriter (or StudyTableWriter's of another run, shard or process) row by row and
/// checks it: this study's (fingerprint, sample count, columns), each row whole (every column a
/// number; sample and status whole numbers, the status a known code, the inputs finite, the
/// samples begin..end-1 in order), and the last line's checksum that of the rows read. Lines may
/// end in \r\n (a file moved through Windows reads as the same part). Throws InputError
/// "PATH[:LINE]: what is wrong".
class KDL_SPACE_EXPORT StudyPartReader {
 public:
  StudyPartReader(const std::string& path, const Study& study, const std::vector<std::string>& columns);
  std::uint64_t begin() const { return begin_; }
  std::uint64_t end() const { return end_; }
  /// Reads the next row; false once the last line (the checksum) is read and verified.
  bool next();
  /// The row just read: its values (columns.size()) and its text (without a line end).
  const std::vector<double>& row() const { return row_; }
  const std::string& line() const { return line_; }
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& why) const;      ///< "PATH:LINE: why"
  [[noreturn]] void failFile(const std::string& why) const;  ///< "PATH: why"
  bool readLine();
  void checkRow();
  void checkEnd();
  std::string path_;
  std::ifstream in_;
  const Study& study_;
  const std::vector<std::string>& names_;  ///< the columns (the caller's: outlives the reader)
  std::size_t columns_, first_outcome_;
  std::uint64_t begin_ = 0, end_ = 0, expected_ = 0;
  long line_no_ = 0;
  std::uint32_t crc_ = 0;
  bool done_ = false;
  std::string line_;
  std::vector<double> row_;
};

/// \brief A table's lock: `TABLE.lock`, created with O_EXCL, holding the PID, the host and the
/// time, while a run writes the table or its parts; removed by the destructor (at the end, on an
/// error, on Ctrl-C). A lock of a live process, or of another host, is refused (InputError); one
/// whose process is gone (same host) is stale: removed, and note() says so.
class KDL_SPACE_EXPORT TableLock {
 public:
  explicit TableLock(const std::string& table);
  ~TableLock();
  /// "PATH: removed a stale lock (PID ..., since ..., is no longer running)", or empty.
  const std::string& note() const { return note_; }
  TableLock(const TableLock&) = delete;
  TableLock& operator=(const TableLock&) = delete;

 private:
  std::string path_, note_;
};

/// \brief Removes the temporaries (`.NAME.tmpPID`, AtomicFile's; `.NAME.probePID`,
/// checkOutputFile's) of processes that are gone: those of `table` beside it, and any in `parts`.
/// Call it holding the table's lock. Best effort.
KDL_SPACE_EXPORT void removeStaleTemporaries(const std::string& table, const std::string& parts);

}  // namespace kdl_space
