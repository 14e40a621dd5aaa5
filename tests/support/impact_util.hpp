// collide() in tests that expect it to succeed.
#pragma once

#include <gtest/gtest.h>

#include "kdl_space/impact/collision.hpp"

namespace kdl_space::test {

/// collide() that must succeed: the impulse on A, or a test failure naming the code.
inline Impulse collideOk(ImpactSide& A, ImpactSide& B, const ImpactLaw& law) {
  Impulse impulse;
  const int rc = collide(A, B, law, impulse);
  EXPECT_EQ(rc, E_NOERROR) << "collide: " << strError(rc);
  return impulse;
}

}  // namespace kdl_space::test
