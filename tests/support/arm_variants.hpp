// Variants of the bundled arm's URDF for the tests that need another mass split (issue 38: a
// heavy arm on a light bus), made by editing its text.
#pragma once

#include <regex>
#include <string>

namespace kdl_space::test {

/// The bundled arm (urdf/space_arm7.urdf's text) with its links four times as heavy (their
/// inertias as they are: still physical) and its 400 kg bus 80 kg.
inline std::string heavyArmOnLightBus(const std::string& urdf) {
  const std::regex mass("<mass value=\"([0-9.]+)\"/>");
  std::string out;
  std::size_t last = 0;
  for (auto it = std::sregex_iterator(urdf.begin(), urdf.end(), mass); it != std::sregex_iterator(); ++it) {
    const double m = std::stod((*it)[1]);
    out += urdf.substr(last, static_cast<std::size_t>(it->position()) - last);
    out += "<mass value=\"" + std::to_string(m == 400.0 ? 80.0 : 4.0 * m) + "\"/>";
    last = static_cast<std::size_t>(it->position() + it->length());
  }
  return out + urdf.substr(last);
}

}  // namespace kdl_space::test
