#include "kdl_space/parsers/input_file.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <locale>
#include <sstream>

#include "spatial/message_text.hpp"

namespace kdl_space {

std::string fileTooLarge(const std::string& path, const std::string& kind, std::uintmax_t max_bytes) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size <= max_bytes) return "";
  const auto mib = [](std::uintmax_t bytes) {
    std::ostringstream s;
    s << std::setprecision(3) << static_cast<double>(bytes) / (1 << 20) << " MiB";
    return s.str();
  };
  return "is " + std::to_string(size) + " bytes (" + mib(size) + "), more than the " + mib(max_bytes) + " a " + kind +
         " may have (is it the right file?)";
}

void checkInputFile(const std::string& path, const std::string& kind, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  const std::string shown = detail::shownPath(path);  // a path of megabytes is not a message of megabytes
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw InputError(shown + ": no such file");
  if (fs::is_directory(status)) throw InputError(shown + ": is a folder, not a " + kind);
  // A device, FIFO or socket could block or never end (/dev/zero): only regular files are read.
  if (!fs::is_regular_file(status)) throw InputError(shown + ": is not a regular file; expected a " + kind);
  if (const std::string why = fileTooLarge(path, kind, max_bytes); !why.empty()) throw InputError(shown + ": " + why);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(shown + ": cannot open the file: " + std::strerror(errno));
  if (in.peek() == std::ifstream::traits_type::eof()) throw InputError(shown + ": the file is empty; expected a " + kind);
}

NumberText readNumber(const std::string& text, double& value, bool space_before) {
  std::size_t i = space_before ? text.find_first_not_of(" \t\n\r\f\v") : 0;
  if (i == std::string::npos || i == text.size()) return NumberText::NotANumber;
  const std::size_t start = i;
  if (text[i] == '+' || text[i] == '-') ++i;
  const std::size_t after_sign = i;
  const auto digits = [&] {
    const std::size_t from = i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    return i - from;
  };
  std::size_t mantissa = digits();
  if (i < text.size() && text[i] == '.') {
    ++i;
    mantissa += digits();
  }
  bool decimal = mantissa > 0;
  if (decimal && i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    decimal = digits() > 0;
  }
  if (decimal && i == text.size()) {
    // The C locale's reading, as urdfdom's (a stream extraction); well formed, it fails only
    // beyond the range of a double (an underflow reads as the nearest double).
    std::istringstream in(text.substr(start));
    in.imbue(std::locale::classic());
    double v = 0.0;
    in >> v;
    if (in.fail() || !std::isfinite(v)) return NumberText::TooLarge;
    value = v;
    return NumberText::Finite;
  }
  // The names strtod reads as no finite number.
  std::string word;
  for (std::size_t k = after_sign; k < text.size(); ++k)
    word += static_cast<char>(std::tolower(static_cast<unsigned char>(text[k])));
  if (word == "nan" || word == "inf" || word == "infinity") return NumberText::NotFinite;
  if (word.size() >= 5 && word.compare(0, 4, "nan(") == 0 && word.back() == ')' &&
      std::all_of(word.begin() + 4, word.end() - 1, [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
    return NumberText::NotFinite;
  return NumberText::NotANumber;
}

bool parseFiniteNumber(const std::string& text, double& value, std::string& why) {
  switch (readNumber(text, value)) {
    case NumberText::Finite:
      return true;
    case NumberText::TooLarge:
      why = detail::echo(text) + " is too large (not a finite number)";
      return false;
    case NumberText::NotFinite:
      why = detail::echo(text) + " is not a finite number";
      return false;
    case NumberText::NotANumber:
      break;
  }
  why = detail::echo(text) + " is not a number";
  return false;
}

}  // namespace kdl_space
