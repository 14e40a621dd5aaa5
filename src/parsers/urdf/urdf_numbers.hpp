// Numbers as urdfdom reads them, so that the checker refuses exactly what the loader refuses: the
// library's one number reader (readNumber) with urdfdom's leading space, and urdfdom's split of a
// vector. Private to the library.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "kdl_space/parsers/input_file.hpp"

namespace kdl_space::detail {

/// One number as urdfdom reads it (urdf::strToDouble: the C locale's stream extraction, space
/// allowed before it, nothing after). urdfdom refuses TooLarge and NotFinite alike.
inline NumberText urdfNumber(const std::string& text, double& value) { return readNumber(text, value, true); }

/// The pieces of a vector as urdfdom splits them (urdf::Vector3::init): at single spaces, empty
/// pieces skipped.
inline std::vector<std::string> vectorPieces(const std::string& text) {
  std::vector<std::string> out;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find(' ', start), text.size());
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

}  // namespace kdl_space::detail
