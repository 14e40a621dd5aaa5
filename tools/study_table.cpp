#include "study_table.hpp"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "cli_common.hpp"

namespace kdl_space::cli {
std::string fingerprintText(const Study& study) {
  char fp[17];
  std::snprintf(fp, sizeof fp, "%016" PRIx64, study.fingerprint);
  return fp;
}

namespace {

/// The comment line that heads a part: which study (its fingerprint) and which rows.
std::string headLine(const Study& study, std::uint64_t begin, std::uint64_t end) {
  return "# kdl_space study; fingerprint " + fingerprintText(study) + "; samples " + std::to_string(study.samples) + "; rows " +
         std::to_string(begin) + "-" + std::to_string(end);
}

std::string joined(const std::vector<std::string>& columns) {
  std::string line;
  for (const std::string& c : columns) line += (line.empty() ? "" : ",") + c;
  return line;
}

}  // namespace

void writeStudyPart(const std::string& path, const std::string& option, const Study& study,
                    const std::vector<std::string>& columns, std::uint64_t begin, std::uint64_t end, const double* rows) {
  AtomicFile file(path, option);
  {
    std::FILE* f = std::fopen(file.tmp().c_str(), "w");
    if (!f) throw InputError(option + " " + path + ": cannot write the file");
    std::fprintf(f, "%s\n%s\n", headLine(study, begin, end).c_str(), joined(columns).c_str());
    const std::size_t m = columns.size();
    for (std::uint64_t r = 0; r < end - begin; ++r) {
      const double* row = rows + r * m;
      std::fprintf(f, "%.0f,%.0f", row[0], row[1]);  // sample and status: whole numbers
      for (std::size_t c = 2; c < m; ++c) std::fprintf(f, ",%.17g", row[c]);  // round-trips exactly
      std::fputc('\n', f);
    }
    const bool ok = std::ferror(f) == 0;
    if (std::fclose(f) != 0 || !ok) throw InputError(option + " " + path + ": cannot write the file (disk full?)");
  }
  file.commit();
}

StudyPart readStudyPart(const std::string& path, const Study& study, const std::vector<std::string>& columns) {
  checkInputFile(path, "study table (CSV written by kdl_space study)");
  std::ifstream in(path);
  std::string head, header;
  std::getline(in, head);
  std::getline(in, header);
  StudyPart part;
  unsigned long long b = 0, e = 0;
  if (std::sscanf(head.c_str(), "# kdl_space study; fingerprint %*16[0-9a-f]; samples %*u; rows %llu-%llu", &b, &e) != 2)
    throw InputError(path + ": is no table written by kdl_space study (its first line is not '# kdl_space study; ...')");
  part.begin = b, part.end = e;
  if (head != headLine(study, part.begin, part.end) || part.end > study.samples || part.begin > part.end)
    throw InputError(path + ": holds rows of another study, or of another version of its files (" + head.substr(2) +
                     "; this study: " + headLine(study, 0, study.samples).substr(2) + ")");
  if (header != joined(columns)) throw InputError(path + ": its columns are not this study's");
  const std::size_t m = columns.size();
  part.rows.reserve(static_cast<std::size_t>(part.end - part.begin) * m);
  std::string line;
  std::uint64_t expected = part.begin;
  for (long line_no = 3; std::getline(in, line); ++line_no) {
    std::istringstream cells(line);
    std::string cell;
    std::size_t count = 0;
    while (std::getline(cells, cell, ',')) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0')
        throw InputError(path + ":" + std::to_string(line_no) + ": '" + cell.substr(0, 40) + "' is not a number");
      part.rows.push_back(v);
      ++count;
    }
    if (count != m)
      throw InputError(path + ":" + std::to_string(line_no) + ": has " + std::to_string(count) + " values, the study " +
                       std::to_string(m) + " columns");
    if (part.rows[part.rows.size() - m] != static_cast<double>(expected))
      throw InputError(path + ":" + std::to_string(line_no) + ": expected sample " + std::to_string(expected));
    ++expected;
  }
  if (expected != part.end)
    throw InputError(path + ": is incomplete: rows " + std::to_string(part.begin) + "-" + std::to_string(part.end) +
                     " announced, " + std::to_string(expected - part.begin) + " found");
  return part;
}

}  // namespace kdl_space::cli
