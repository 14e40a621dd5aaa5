#include "kdl_space/parsers/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
namespace fs = std::filesystem;
using detail::quoted;
}  // namespace

std::string writeFailure() { return errno ? std::string(std::strerror(errno)) : std::string("disk full?"); }

void checkOutputFile(const std::string& path, const std::string& option) {
  const std::string where = option + " " + path + ": ";
  if (path.empty()) throw UsageError(option + ": the file name is empty");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(where + "is a folder; give a file name");
  // The finished file is renamed over the name: that would replace a device such as /dev/null.
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))
    throw InputError(where + "exists and is not a regular file; give the name of a file");
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  const fs::file_status status = fs::status(folder, ec);
  if (ec || !fs::exists(status)) throw InputError(where + "the folder " + quoted(folder.string()) + " does not exist");
  if (!fs::is_directory(status)) throw InputError(where + quoted(folder.string()) + " is not a folder");
  // Whether a file can be created there is known only by creating one (access() says yes to
  // root on a read-only /sys).
  unlink(createFreshFile(folder.string(), "." + fs::path(path).filename().string() + ".probe", where).c_str());
}

namespace {
/// The process's file mode creation mask, read without changing it (/proc/self/status; umask()
/// would set it, racing other threads); 022 when it cannot be read.
mode_t processUmask() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::strtoul(line.c_str() + 6, nullptr, 8));
  return 022;
}
}  // namespace

std::string createFreshFile(const std::string& folder, const std::string& stem, const std::string& where, int* fd) {
  std::string name = (fs::path(folder.empty() ? "." : folder) / (stem + std::to_string(getpid()) + "-XXXXXX")).string();
  const int created = mkostemp(name.data(), O_CLOEXEC);  // O_CREAT | O_EXCL, mode 0600
  if (created < 0)
    throw InputError(where + "cannot create a file in the folder " + quoted(folder.empty() ? "." : folder) + ": " +
                     std::strerror(errno));
  fchmod(created, 0666 & ~processUmask());  // the mode any new file of the user's gets (0644 by default)
  if (fd) *fd = created;
  else close(created);
  return name;
}

void refuseOverwritingInputs(const std::string& option, const std::string& path, const std::vector<InputFile>& inputs) {
  if (path.empty()) return;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(path, ec);
  for (const InputFile& in : inputs) {
    if (in.path.empty()) continue;
    std::error_code e1, e2;
    const bool same_name = !ec && fs::weakly_canonical(in.path, e1) == out && !e1;
    if (same_name || fs::equivalent(path, in.path, e2))
      throw UsageError(option + " " + path + ": is " + in.what + (in.path == path ? "" : " " + in.path) +
                       "; it would be overwritten: give the output another name");
  }
}

AtomicFile::AtomicFile(std::string path, std::string option)
    : path_(std::move(path)), option_(std::move(option)) {
  // Same folder (the rename is atomic there), a name that says what it is and that no one can
  // plant a link at beforehand.
  const fs::path p(path_);
  tmp_ = createFreshFile(p.parent_path().string(), "." + p.filename().string() + ".tmp", option_ + " " + path_ + ": ");
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(tmp_.c_str());
}

namespace {
/// Flushes a file or a folder to the disk (best effort where the file system cannot: EINVAL).
bool syncPath(const std::string& path, int flags) {
  const int fd = open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = fsync(fd) == 0 || errno == EINVAL || errno == EROFS;
  close(fd);
  return ok;
}
}  // namespace

void AtomicFile::commit() {
  // The data on the disk before the name: a crash (power, kernel) after the rename never leaves a
  // file that has its name but not its bytes. Then the folder, so that the rename itself lasts.
  if (!syncPath(tmp_, O_RDONLY))
    throw InputError(option_ + " " + path_ + ": cannot write (fsync): " + std::strerror(errno));
  std::error_code ec;
  fs::rename(tmp_, path_, ec);
  if (ec) throw InputError(option_ + " " + path_ + ": cannot write: " + ec.message());
  committed_ = true;
  const fs::path folder = fs::path(path_).parent_path();
  syncPath(folder.empty() ? "." : folder.string(), O_RDONLY | O_DIRECTORY);
}

void AtomicFile::retract() {
  if (committed_) std::remove(path_.c_str());
}

}  // namespace kdl_space
