#include "kdl_space/study/study_table.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>

namespace kdl_space {
namespace fs = std::filesystem;

std::string fingerprintText(const Study& study) {
  char fp[17];
  std::snprintf(fp, sizeof fp, "%016" PRIx64, study.fingerprint);
  return fp;
}

std::uint32_t crc32(std::uint32_t crc, const char* data, std::size_t n) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;  // reflected 0x04C11DB7
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ static_cast<unsigned char>(data[i])) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

namespace {

/// The comment line that heads a part: which study (its fingerprint) and which rows.
std::string headLine(const Study& study, std::uint64_t begin, std::uint64_t end) {
  return "# kdl_space study; fingerprint " + fingerprintText(study) + "; samples " + std::to_string(study.samples) + "; rows " +
         std::to_string(begin) + "-" + std::to_string(end);
}

/// The comment line that ends a part: its rows again and the CRC-32 of the row lines' bytes (each
/// with its '\n'; a \r before it is not counted).
std::string endLine(std::uint64_t begin, std::uint64_t end, std::uint32_t crc) {
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08" PRIx32, crc);
  return "# end; rows " + std::to_string(begin) + "-" + std::to_string(end) + "; crc32 " + hex;
}

std::string joined(const std::vector<std::string>& columns) {
  std::string line;
  for (const std::string& c : columns) line += (line.empty() ? "" : ",") + c;
  return line;
}

/// A status a sample can have: 0, KDL's SolverI codes, the library's own.
bool knownStatus(double status) {
  if (!(status >= -1000 && status <= 1000)) return false;
  const int s = static_cast<int>(status);
  return (s >= -8 && s <= 1) || std::strcmp(strError(s), "unknown error") != 0;
}

bool processGone(long pid) { return pid > 0 && kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH; }

std::string hostName() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return host;
}

}  // namespace

StudyTableWriter::StudyTableWriter(const std::string& path, const std::string& option, const Study& study,
                                   const std::vector<std::string>& columns, std::uint64_t begin, std::uint64_t end)
    : file_(path, option), option_(option), begin_(begin), end_(end), columns_(columns.size()) {
  f_ = std::fopen(file_.tmp().c_str(), "w");
  if (!f_) throw InputError(option + " " + path + ": cannot write the file: " + std::strerror(errno));
  const std::string head = headLine(study, begin, end) + "\n" + joined(columns) + "\n";
  put(head.data(), head.size());
}

StudyTableWriter::~StudyTableWriter() {
  if (f_) std::fclose(f_);
}

void StudyTableWriter::put(const char* text, std::size_t n) {
  if (std::fwrite(text, 1, n, f_) != n)
    throw InputError(option_ + " " + file_.path() + ": cannot write the file (disk full?): " + std::strerror(errno));
}

void StudyTableWriter::addRow(const double* row) {
  char buffer[32];
  std::string line;
  line.reserve(columns_ * 24);
  std::snprintf(buffer, sizeof buffer, "%.0f,%.0f", row[0], row[1]);  // sample and status: whole numbers
  line += buffer;
  for (std::size_t c = 2; c < columns_; ++c) {
    std::snprintf(buffer, sizeof buffer, ",%.17g", row[c]);  // round-trips exactly
    line += buffer;
  }
  addLine(line);
}

void StudyTableWriter::addLine(const std::string& line) {
  if (rows_ == end_ - begin_) throw std::logic_error("StudyTableWriter: more rows than announced");
  put(line.data(), line.size());
  put("\n", 1);
  crc_ = crc32(crc32(crc_, line.data(), line.size()), "\n", 1);
  ++rows_;
}

void StudyTableWriter::commit() {
  if (rows_ != end_ - begin_) throw std::logic_error("StudyTableWriter: fewer rows than announced");
  const std::string last = endLine(begin_, end_, crc_) + "\n";
  put(last.data(), last.size());
  const bool ok = std::fflush(f_) == 0 && std::ferror(f_) == 0;
  const int closed = std::fclose(f_);
  f_ = nullptr;
  if (!ok || closed != 0) throw InputError(option_ + " " + file_.path() + ": cannot write the file (disk full?)");
  file_.commit();
}

void writeStudyPart(const std::string& path, const std::string& option, const Study& study,
                    const std::vector<std::string>& columns, std::uint64_t begin, std::uint64_t end, const double* rows) {
  StudyTableWriter w(path, option, study, columns, begin, end);
  for (std::uint64_t r = 0; r < end - begin; ++r) w.addRow(rows + r * columns.size());
  w.commit();
}

StudyPartReader::StudyPartReader(const std::string& path, const Study& study, const std::vector<std::string>& columns)
    : path_(path), study_(study), names_(columns), columns_(columns.size()) {
  checkInputFile(path, "study table (CSV written by kdl_space study)");
  in_.open(path, std::ios::binary);
  first_outcome_ = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), "impulse.fx") - columns.begin());
  unsigned long long b = 0, e = 0;
  if (!readLine() ||
      std::sscanf(line_.c_str(), "# kdl_space study; fingerprint %*16[0-9a-f]; samples %*u; rows %llu-%llu", &b, &e) != 2)
    failFile("is no table written by kdl_space study (its first line is not '# kdl_space study; ...')");
  begin_ = b, end_ = e, expected_ = b;
  if (line_ != headLine(study, begin_, end_) || end_ > study.samples || begin_ > end_)
    failFile("holds rows of another study, or of another version of its files (" + line_.substr(2) +
         "; this study: " + headLine(study, 0, study.samples).substr(2) + ")");
  if (!readLine() || line_ != joined(columns)) failFile("its columns are not this study's");
  row_.resize(columns_);
}

void StudyPartReader::fail(const std::string& why) const {
  throw InputError(path_ + (line_no_ > 0 ? ":" + std::to_string(line_no_) : std::string()) + ": " + why);
}

void StudyPartReader::failFile(const std::string& why) const { throw InputError(path_ + ": " + why); }

bool StudyPartReader::readLine() {
  if (!std::getline(in_, line_)) return false;
  ++line_no_;
  if (!line_.empty() && line_.back() == '\r') line_.pop_back();  // the same part after Windows
  return true;
}

bool StudyPartReader::next() {
  if (done_) return false;
  if (!readLine()) {
    if (expected_ == end_)
      failFile("has no last line with the checksum of its rows ('# end; rows " + std::to_string(begin_) + "-" +
           std::to_string(end_) + "; crc32 ...'): it was cut short, or written by an older kdl_space, which wrote "
           "none; compute it again (or merge it with that older version)");
    failFile("is incomplete: rows " + std::to_string(begin_) + "-" + std::to_string(end_) + " announced, " +
         std::to_string(expected_ - begin_) + " found (cut short: compute it again)");
  }
  if (line_.rfind("# end;", 0) == 0) {
    checkEnd();
    done_ = true;
    return false;
  }
  checkRow();
  crc_ = crc32(crc32(crc_, line_.data(), line_.size()), "\n", 1);
  ++expected_;
  return true;
}

void StudyPartReader::checkRow() {
  if (expected_ == end_)
    fail("a row after the last one announced (rows " + std::to_string(begin_) + "-" + std::to_string(end_) + ")");
  std::size_t count = 0;
  const char* p = line_.data();
  const char* const stop = p + line_.size();
  while (p <= stop) {
    const char* comma = static_cast<const char*>(std::memchr(p, ',', static_cast<std::size_t>(stop - p)));
    const char* cell_end = comma ? comma : stop;
    double v = 0.0;
    const auto [at, ec] = std::from_chars(p, cell_end, v);
    if (p == cell_end || ec != std::errc() || at != cell_end)
      fail("'" + std::string(p, std::min<std::size_t>(static_cast<std::size_t>(cell_end - p), 40)) + "' is not a number");
    if (count < columns_) row_[count] = v;
    ++count;
    p = cell_end + 1;
  }
  if (count != columns_)
    fail("has " + std::to_string(count) + " values, the study " + std::to_string(columns_) + " columns");
  if (row_[0] != static_cast<double>(expected_)) fail("expected sample " + std::to_string(expected_));
  if (!(std::floor(row_[1]) == row_[1]) || !knownStatus(row_[1])) {
    const std::size_t a = line_.find(',') + 1;
    fail("status " + line_.substr(a, line_.find(',', a) - a) + " is no status a sample can have (0, or an error code of the library)");
  }
  for (std::size_t c = 2; c < first_outcome_ && c < columns_; ++c)
    if (!std::isfinite(row_[c])) fail(names_[c] + " is " + std::to_string(row_[c]) + ": an input is drawn finite");
}

void StudyPartReader::checkEnd() {
  unsigned long long b = 0, e = 0;
  unsigned crc = 0;
  int n = 0;
  if (std::sscanf(line_.c_str(), "# end; rows %llu-%llu; crc32 %8x%n", &b, &e, &crc, &n) != 3 ||
      static_cast<std::size_t>(n) != line_.size() || b != begin_ || e != end_)
    fail("is not the last line of rows " + std::to_string(begin_) + "-" + std::to_string(end_) + " ('" +
         endLine(begin_, end_, 0).substr(0, endLine(begin_, end_, 0).size() - 8) + "XXXXXXXX')");
  if (expected_ != end_)
    fail("the part ends after " + std::to_string(expected_ - begin_) + " of its rows " + std::to_string(begin_) + "-" +
         std::to_string(end_) + " (a line is missing: compute it again)");
  if (crc != crc_) {
    char got[9];
    std::snprintf(got, sizeof got, "%08" PRIx32, crc_);
    fail("the rows' checksum is " + std::string(got) + ", this line says " + line_.substr(line_.size() - 8) +
         ": a row was changed after it was written (compute it again)");
  }
  std::string extra;
  if (std::getline(in_, extra)) {
    ++line_no_;
    fail("a line after the last one (the checksum)");
  }
}

namespace {
// The lock is written whole to a fresh temporary (createFreshFile), then linked to its name: link()
// fails when the name exists, so the lock appears at once with its holder in it (a run killed while
// taking it leaves at most a temporary of a dead PID, never an empty lock that would name no holder).
bool writeWhole(int fd, const std::string& text) {
  const bool ok = write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && fsync(fd) == 0;
  return close(fd) == 0 && ok;
}
}  // namespace

TableLock::TableLock(const std::string& table) : path_(table + ".lock") {
  const std::string host = hostName();
  char since_now[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(since_now, sizeof since_now, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const std::string text = "pid " + std::to_string(getpid()) + "\nhost " + host + "\nsince " + since_now + "\n";
  const fs::path l(path_);
  int fd = -1;
  const std::string tmp = createFreshFile(l.parent_path().string(), "." + l.filename().string() + ".tmp",
                                          table + ": its lock " + path_ + ": ", &fd);
  if (!writeWhole(fd, text)) {
    unlink(tmp.c_str());
    throw InputError(table + ": cannot write its lock " + path_ + " (disk full, or the folder is not writable?)");
  }
  struct RemoveTemporary {
    const std::string& path;
    ~RemoveTemporary() { unlink(path.c_str()); }
  } remove_temporary{tmp};
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (link(tmp.c_str(), path_.c_str()) == 0) return;
    if (errno != EEXIST) throw InputError(table + ": cannot create its lock " + path_ + ": " + std::strerror(errno));
    std::ifstream in(path_);
    long pid = 0;
    std::string key, holder_host, since;
    in >> key >> pid >> key >> holder_host >> key >> since;
    if (pid <= 0)
      throw InputError(table + " has a lock " + path_ + " that names no holder (not written by this version of " +
                       "kdl_space?); remove it if no run is writing the table");
    if (attempt == 0 && holder_host == host && processGone(pid)) {
      note_ = path_ + ": removed a stale lock (PID " + std::to_string(pid) + ", since " + since + ", is no longer running)";
      unlink(path_.c_str());
      continue;
    }
    throw InputError(table + " is being written by kdl_space (PID " + std::to_string(pid) +
                     (holder_host == host ? "" : " on " + holder_host) + ") since " + since +
                     "; wait for it to end, or remove " + path_ + " if no such process runs");
  }
  throw InputError(table + ": another run took its lock " + path_ + " as this one removed a stale one; try again");
}

TableLock::~TableLock() { unlink(path_.c_str()); }

void removeStaleTemporaries(const std::string& table, const std::string& parts) {
  // AtomicFile's temporaries: ".NAME.tmpPID-XXXXXX" (createFreshFile; ".NAME.tmpPID" of earlier
  // versions); only those of processes that are gone.
  const auto stale = [](const std::string& name, const std::string& prefix) {
    if (name.rfind(prefix, 0) != 0) return false;
    const std::string rest = name.substr(prefix.size());
    long pid = 0;
    const auto [at, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), pid);
    const std::size_t digits = static_cast<std::size_t>(at - rest.data());
    const bool suffix = digits == rest.size() || (rest[digits] == '-' && rest.size() - digits == 7);
    return digits > 0 && ec == std::errc() && suffix && processGone(pid);
  };
  std::error_code ec;
  const fs::path t(table);
  const fs::path folder = t.parent_path().empty() ? fs::path(".") : t.parent_path();
  // Beside the table: its own temporary, and the probe checkOutputFile creates and removes at once.
  const std::string own = "." + t.filename().string() + ".tmp", probe = "." + t.filename().string() + ".probe",
                    lock = "." + t.filename().string() + ".lock.tmp";
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (stale(name, own) || stale(name, probe) || stale(name, lock)) fs::remove(it->path(), ec);
  }
  if (!fs::is_directory(parts, ec)) return;
  for (fs::directory_iterator it(parts, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::size_t tmp = name.rfind(".tmp");
    if (name[0] == '.' && tmp != std::string::npos && stale(name, name.substr(0, tmp + 4))) fs::remove(it->path(), ec);
  }
}

}  // namespace kdl_space
