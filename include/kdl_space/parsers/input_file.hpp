// Checks of what a user hands to a loader or the tool, written once: a file that cannot be read
// and a text that is no finite number are refused with a message a user can act on, before a
// parser sees them.
#pragma once

#include <cstdint>
#include <string>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/export.hpp"

namespace kdl_space {

/// The largest URDF file the library reads: 64 MiB (the largest robots' are a few MB). Scenario
/// and study files (YAML or JSON), whose parse costs more per byte, are bounded at 16 MiB.
inline constexpr std::uintmax_t max_input_file_bytes = std::uintmax_t{64} << 20;

/// \brief Refuses an input file that cannot be read: missing, a folder, not a regular file (a
/// device or FIFO could block or never end), larger than `max_bytes` (checked before it is read),
/// unreadable or empty. A set-up call: \throws InputError "PATH: what is wrong"; `kind` names
/// what the file should be ("URDF file"). The default `max_bytes` sets no limit (a study's table
/// may be any size): the loaders pass max_input_file_bytes.
KDL_SPACE_EXPORT void checkInputFile(const std::string& path, const std::string& kind,
                                     std::uintmax_t max_bytes = ~std::uintmax_t{0});

/// \brief "" if the file at `path` (a regular file) has at most `max_bytes`, else why it is
/// refused: "is 70000000 bytes (66.8 MiB), more than the 64 MiB a KIND may have".
KDL_SPACE_EXPORT std::string fileTooLarge(const std::string& path, const std::string& kind, std::uintmax_t max_bytes);

/// What a text is as a number (readNumber).
enum class NumberText {
  Finite,      ///< a finite double, in `value`
  TooLarge,    ///< well formed, beyond the range of a double ("1e400")
  NotFinite,   ///< a name of no finite number: nan, inf, infinity (any case, signed), nan(chars)
  NotANumber,  ///< anything else ("abc", "1.5x", "0x5", "5,0", "5 ", "")
};

/// \brief The library's one reader of a number: the whole text in decimal form, [+|-] digits
/// [. digits] [(e|E) [+|-] digits] with a digit before or after the point, read in the C locale
/// whatever the program's (no hexadecimal, nothing after the number). White space before it only
/// if `space_before` (urdfdom reads so: a stream extraction). A number too small for a double reads
/// as the nearest one (a denormal, or 0). `value` is set only for Finite.
KDL_SPACE_EXPORT NumberText readNumber(const std::string& text, double& value, bool space_before = false);

/// \brief Parses a whole text as a finite double by readNumber ("1e400", "nan", "1.5x", " 1" are
/// refused). \return false, with `why` saying what is wrong ("'abc' is not a number", "'1e400' is
/// too large (not a finite number)", "'inf' is not a finite number"); `value` is untouched then.
KDL_SPACE_EXPORT bool parseFiniteNumber(const std::string& text, double& value, std::string& why);

}  // namespace kdl_space
