// A symmetric 6x6 (a spatial or articulated inertia, an inverse inertia) as four 3x3 blocks of
// four-lane columns (detail/lanes.hpp), for the recursions of the O(n) solver: each of their
// steps is a few lane-wide fused multiply-adds. A speed internal of the library, not API.
#pragma once

#include "detail/lanes.hpp"
#include "spatial/symmetric6d.hpp"

namespace kdl_space::detail {

/// [[A11, A12], [A21, A22]], A21 = A12^T, about a reference point, world axes, (v; w) order.
struct LaneSymmetric6d {
  LaneMatrix A11, A12, A21, A22;

  /// The spatial inertia of a rigid body: mass m, CoM at c relative to the reference point,
  /// inertia I_c about the CoM: [[m E, -m c^], [m c^, I_c - m c^ c^]] (zero for a massless frame; I_c alone
  /// for a body with a rotational inertia but no mass).
  void setRigidBody(double m, const Vector3d& c, const Matrix3d& I_c) {
    if (!(m > 0.0)) {  // no mass: its rotational inertia alone (zero for a frame)
      const Lanes zero{0.0, 0.0, 0.0, 0.0};
      A11 = A12 = A21 = {{zero, zero, zero}};
      A22 = lanes(I_c);
      return;
    }
    const double x = m * c.x(), y = m * c.y(), z = m * c.z(), mc2 = m * c.squaredNorm();
    const Lanes mc = x * unit[0] + y * unit[1] + z * unit[2];
    A11 = {{m * unit[0], m * unit[1], m * unit[2]}};
    A21 = {{z * unit[1] - y * unit[2], x * unit[2] - z * unit[0], y * unit[0] - x * unit[1]}};  // m c^
    A22 = lanes(I_c);
    for (int k = 0; k < 3; ++k) {
      A12.c[k] = -A21.c[k];                            // (m c^)^T = -m c^
      A22.c[k] += mc2 * unit[k] - mc * c(k);           // + m (|c|^2 E - c c^T)
    }
  }
  LaneSymmetric6d& operator+=(const LaneSymmetric6d& o) {
    for (int k = 0; k < 3; ++k) {
      A11.c[k] += o.A11.c[k];
      A12.c[k] += o.A12.c[k];
      A21.c[k] += o.A21.c[k];
      A22.c[k] += o.A22.c[k];
    }
    return *this;
  }
  /// U = this S, S = (v; w): top = A11 v + A12 w, bottom = A21 v + A22 w.
  void times(const Vector6d& S, Lanes& top, Lanes& bottom) const {
    top = detail::times(A11, S(0), S(1), S(2)) + detail::times(A12, S(3), S(4), S(5));
    bottom = detail::times(A21, S(0), S(1), S(2)) + detail::times(A22, S(3), S(4), S(5));
  }
  /// this -= alpha U U^T, U = (top; bottom).
  void subtractRank1(const Lanes& top, const Lanes& bottom, double alpha) {
    const Lanes a = alpha * top, b = alpha * bottom;
    for (int k = 0; k < 3; ++k) {
      A11.c[k] -= a * top[k];
      A12.c[k] -= a * bottom[k];
      A21.c[k] -= b * top[k];
      A22.c[k] -= b * bottom[k];
    }
  }
  /// this -= S y^T + y S^T, S = (S_top; S_bottom), y = (y_top; y_bottom).
  void subtractRank2(const Lanes& S_top, const Lanes& S_bottom, const Lanes& y_top, const Lanes& y_bottom) {
    for (int k = 0; k < 3; ++k) {
      A11.c[k] -= S_top * y_top[k] + y_top * S_top[k];
      A12.c[k] -= S_top * y_bottom[k] + y_top * S_bottom[k];
      A21.c[k] -= S_bottom * y_top[k] + y_bottom * S_top[k];
      A22.c[k] -= S_bottom * y_bottom[k] + y_bottom * S_bottom[k];
    }
  }
  /// From and to the dense form (column-major: each block column is three doubles in a row).
  static LaneSymmetric6d from(const Matrix6d& M) {
    const double* a = M.data();
    LaneSymmetric6d L;
    for (int k = 0; k < 3; ++k) {
      L.A11.c[k] = load3(a + 6 * k);
      L.A21.c[k] = load3(a + 6 * k + 3);
      L.A12.c[k] = load3(a + 6 * (k + 3));
      L.A22.c[k] = load3(a + 6 * (k + 3) + 3);
    }
    return L;
  }
  Matrix6d dense() const {
    Matrix6d M;
    double* a = M.data();
    for (int k = 0; k < 3; ++k) {
      store3(A11.c[k], a + 6 * k);
      store3(A21.c[k], a + 6 * k + 3);
      store3(A12.c[k], a + 6 * (k + 3));
      store3(A22.c[k], a + 6 * (k + 3) + 3);
    }
    return M;
  }
  /// The packed form (its lower triangle).
  Symmetric6d packed() const {
    Symmetric6d P;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c <= r; ++c) {
        P.a[Symmetric6d::index(r, c)] = A11.c[c][r];
        P.a[Symmetric6d::index(r + 3, c + 3)] = A22.c[c][r];
      }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) P.a[Symmetric6d::index(r + 3, c)] = A21.c[c][r];
    return P;
  }
};

}  // namespace kdl_space::detail
