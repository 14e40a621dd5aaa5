// Small text helpers of the library's messages, written once.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace kdl_space::detail {

/// 'name', as every message quotes a link, joint or file.
inline std::string quoted(const std::string& s) { return "'" + s + "'"; }

/// A text from an input, quoted for a message: at most 40 characters, anything but printable
/// ASCII shown as '?' (a binary file must not flood the terminal).
inline std::string echo(const std::string& text) {
  std::string shown;
  for (std::size_t i = 0; i < text.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    shown += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  return "'" + shown + (text.size() > 40 ? "...'" : "'");
}

/// A path as a message shows it: whole up to 80 characters, else its first 40 and last 36 around
/// "..." (a field of megabytes named as a file must not become a message of megabytes).
inline std::string shownPath(const std::string& path) {
  if (path.size() <= 80) return path;
  return path.substr(0, 40) + "..." + path.substr(path.size() - 36);
}

/// A number as a message shows it: 6 significant digits, the stream's default ("0.2", "1e+06").
inline std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

/// "a, b, c" of names, for messages that list what a model has ("none" for an empty list).
inline std::string listNames(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list.empty() ? "none" : list;
}

}  // namespace kdl_space::detail
