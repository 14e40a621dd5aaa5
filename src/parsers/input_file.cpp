#include "kdl_space/parsers/input_file.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace kdl_space {

void checkInputFile(const std::string& path, const std::string& kind) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw InputError(path + ": no such file");
  if (fs::is_directory(status)) throw InputError(path + ": is a folder, not a " + kind);
  // A device, FIFO or socket could block or never end (/dev/zero): only regular files are read.
  if (!fs::is_regular_file(status)) throw InputError(path + ": is not a regular file; expected a " + kind);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file: " + std::strerror(errno));
  if (in.peek() == std::ifstream::traits_type::eof()) throw InputError(path + ": the file is empty; expected a " + kind);
}

bool parseFiniteNumber(const std::string& text, double& value, std::string& why) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = text.empty() || std::isspace(static_cast<unsigned char>(text[0])) ? 0.0 : std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size()) {
    why = "'" + text + "' is not a number";
    return false;
  }
  if (errno == ERANGE && std::isinf(v)) {
    why = "'" + text + "' is too large (not a finite number)";
    return false;
  }
  if (!std::isfinite(v)) {
    why = "'" + text + "' is not a finite number";
    return false;
  }
  value = v;  // (a denormal underflow to 0 or a tiny value is a number: accepted)
  return true;
}

}  // namespace kdl_space
