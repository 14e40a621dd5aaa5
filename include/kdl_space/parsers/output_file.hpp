// The rules of every output file the library, the reports and the tool write (the counterpart of
// input_file.hpp): it is checked before any work, it never
// replaces an input, and it appears whole or not at all (written under a fresh temporary name in
// its folder and renamed into place).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

/// A request the caller must change before anything runs (an output that would replace an input,
/// an empty file name): the tool's exit 2, Python's ValueError.
struct KDL_SPACE_EXPORT UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// \brief Why the last write failed, for a message: the system's reason (strerror(errno): "No
/// space left on device"), or "disk full?" when the stream kept none.
KDL_SPACE_EXPORT std::string writeFailure();

/// \brief Refuses, before any work, an output file that could not be written: its folder is
/// missing, not a folder or not writable, or the path is a folder. Throws InputError naming the
/// option (e.g. "--csv run.csv: the folder 'out' does not exist"); UsageError for an empty name.
KDL_SPACE_EXPORT void checkOutputFile(const std::string& path, const std::string& option);

/// A file a run reads, with what it is for messages ("the scenario file", "the robot's URDF").
struct InputFile {
  std::string what, path;
};

/// \brief No output replaces an input: throws UsageError (before any work) when the output
/// `path` of `option` is one of `inputs`, by canonical path or as the same file (device and inode:
/// a hard or symbolic link to it), naming both ("--csv a.urdf: is the robot's URDF
/// robots/a.urdf; it would be overwritten").
KDL_SPACE_EXPORT void refuseOverwritingInputs(const std::string& option, const std::string& path,
                                              const std::vector<InputFile>& inputs);

/// \brief Creates a new empty file `folder`/`stem`PID-XXXXXX (six random characters), exclusively
/// (O_CREAT | O_EXCL: an existing name, a planted symbolic link included, is never opened or
/// followed; mkostemp draws another), with the mode the user's umask gives a new file, and returns
/// its path; `fd`, if given, receives the open descriptor (else it is closed). The PID in the name
/// lets a later run remove the temporaries of runs that are gone. Throws InputError `where` +
/// "cannot create a file in the folder ...: REASON".
KDL_SPACE_EXPORT std::string createFreshFile(const std::string& folder, const std::string& stem,
                                             const std::string& where, int* fd = nullptr);

/// \brief A file written under a fresh temporary name in the same folder (createFreshFile: created
/// at construction, unpredictable, never through a link someone planted) and renamed into place by
/// commit(), so that a failed run never leaves a partial file that looks complete; the temporary
/// is removed if the object is destroyed without a commit.
class KDL_SPACE_EXPORT AtomicFile {
 public:
  /// `option` names the file in messages (e.g. "--csv"). Creates the temporary `.NAME.tmpPID-XXXXXX`
  /// beside `path`; throws InputError if it cannot.
  AtomicFile(std::string path, std::string option);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  const std::string& path() const { return path_; }
  const std::string& tmp() const { return tmp_; }
  /// Renames the temporary to the final name (its bytes on the disk first); throws InputError if
  /// that fails.
  void commit();
  /// Removes the final file after a commit (a later output failed); best effort.
  void retract();

 private:
  std::string path_, option_, tmp_;
  bool committed_ = false;
};

}  // namespace kdl_space
