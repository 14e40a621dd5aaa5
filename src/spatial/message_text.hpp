// Small text helpers of the library's messages, written once.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace kdl_space::detail {

/// A text from an input as a message shows it: whole up to 80 characters, else its first 40 and
/// last 36 around "...", and how long it was ("abc...xyz (20971520 characters)"): a field of
/// megabytes must not become a message of megabytes.
inline std::string cut(const std::string& text) {
  if (text.size() <= 80) return text;
  return text.substr(0, 40) + "..." + text.substr(text.size() - 36) + " (" + std::to_string(text.size()) + " characters)";
}

/// 'name', as every message quotes a link, joint or file (cut as cut() says).
inline std::string quoted(const std::string& s) {
  if (s.size() <= 80) return "'" + s + "'";
  return "'" + s.substr(0, 40) + "..." + s.substr(s.size() - 36) + "' (" + std::to_string(s.size()) + " characters)";
}

/// A text from an input, quoted for a message: cut as quoted(), anything but printable ASCII
/// shown as '?' (a binary file must not flood the terminal).
inline std::string echo(const std::string& text) {
  const auto printable = [](std::string t) {
    for (char& c : t)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    return t;
  };
  if (text.size() <= 80) return "'" + printable(text) + "'";
  return "'" + printable(text.substr(0, 40)) + "..." + printable(text.substr(text.size() - 36)) + "' (" +
         std::to_string(text.size()) + " characters)";
}

/// A path as a message shows it: cut as cut() says (a field of megabytes named as a file must
/// not become a message of megabytes).
inline std::string shownPath(const std::string& path) { return cut(path); }

/// A number as a message shows it: 6 significant digits, the stream's default ("0.2", "1e+06").
inline std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

/// "a, b, c" of names, for messages that list what a model has ("none" for an empty list); of a
/// longer list than 40 names the first 40 and "... and N more" (a model of thousands of links).
inline std::string listNames(const std::vector<std::string>& names) {
  constexpr std::size_t kShown = 40;
  std::string list;
  for (std::size_t i = 0; i < names.size() && i < kShown; ++i) list += (list.empty() ? "" : ", ") + names[i];
  if (names.size() > kShown) list += ", ... and " + std::to_string(names.size() - kShown) + " more";
  return list.empty() ? "none" : list;
}

}  // namespace kdl_space::detail
