// kdl_space.ImpactLaw as the binding files share it (impact.cpp, capture.cpp).
#pragma once

#include "conversions.hpp"
#include "kdl_space/impact/impact.hpp"

namespace kdl_space::python {

/// An impact law and whether its normal was given (a capture's is optional).
struct PyImpactLaw {
  ImpactLaw law;
  bool has_normal = false;
};

const char* kindName(ImpactKind k);

}  // namespace kdl_space::python
