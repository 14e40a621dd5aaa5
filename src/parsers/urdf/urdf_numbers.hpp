// Numbers as urdfdom reads them, so that the checker refuses exactly what the loader refuses.
// Private to the library.
#pragma once

#include <string>
#include <vector>

namespace kdl_space::detail {

/// How a number attribute reads.
enum class Parsed { Ok, NotFinite, Bad };

/// \brief One number as urdfdom reads it (urdf::strToDouble: the C locale's stream extraction,
/// space allowed before, nothing after). What urdfdom refuses is `NotFinite` for NaN, infinities
/// and numbers too large for a double, `Bad` otherwise.
Parsed parseNumber(const std::string& text, double& value);

/// The pieces of a vector as urdfdom splits them (urdf::Vector3::init): at single spaces, empty
/// pieces skipped.
std::vector<std::string> vectorPieces(const std::string& text);

}  // namespace kdl_space::detail
