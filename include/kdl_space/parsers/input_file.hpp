// Checks of what a user hands to a loader or the tool, written once: a file that cannot be read
// and a text that is no finite number are refused with a message a user can act on, before a
// parser sees them.
#pragma once

#include <string>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {

/// \brief Refuses an input file that cannot be read: missing, a folder, not a regular file (a
/// device or FIFO could block or never end), unreadable or empty. A set-up call: \throws
/// InputError "PATH: what is wrong"; `kind` names what the file should be ("URDF file").
KDL_SPACE_EXPORT void checkInputFile(const std::string& path, const std::string& kind);

/// \brief Parses a whole text as a finite double ("1e400", "nan", "1.5x", " 1" are refused).
/// \return false, with `why` saying what is wrong ("'abc' is not a number", "'1e400' is too large
/// (not a finite number)", "'inf' is not a finite number"); `value` is untouched then.
KDL_SPACE_EXPORT bool parseFiniteNumber(const std::string& text, double& value, std::string& why);

}  // namespace kdl_space
