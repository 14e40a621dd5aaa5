// Four-lane double vectors (the GCC and Clang vector extension) for the per-body products of
// forward kinematics, a speed internal of the library: a 3-vector in lanes 0-2 (lane 3 zero) and
// a 3x3 matrix as three such columns. In a function compiled for x86-64-v3 each is one AVX2
// register and a matrix-vector product three fused multiply-adds; in the baseline, SSE2 pairs.
// Needs __builtin_shufflevector: GCC 12 or later, or clang.
#pragma once

#include <cstring>

#include "kdl_space/spatial/spatial.hpp"

// These inline helpers pass vectors by value inside one translation unit, never across the
// library's ABI: GCC's note that an AVX vector argument changes the ABI does not apply.
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace kdl_space::detail {

/// Aligned as a double: the baseline x86-64 ABI aligns a 32-byte vector to 16 only, while code
/// compiled for x86-64-v3 would move it with instructions that need 32; unaligned moves cost
/// nothing on the CPUs that run either, and heap arrays of it need no over-aligned allocation.
typedef double Lanes __attribute__((vector_size(32), aligned(8)));

/// A 3x3 matrix by columns.
struct LaneMatrix {
  Lanes c[3];
};

/// Three doubles from memory into lanes 0-2, lane 3 zero: a two-lane load and a one-lane load
/// joined in registers (a vector assembled in memory from single stores and read back whole
/// stalls the pipeline).
inline Lanes load3(const double* p) {
  typedef double Pair __attribute__((vector_size(16)));
  Pair low, high{p[2], 0.0};
  std::memcpy(&low, p, sizeof low);
  return __builtin_shufflevector(low, high, 0, 1, 2, 3);
}
inline Lanes lanes(const Vector3d& v) { return load3(v.data()); }
inline LaneMatrix lanes(const Matrix3d& M) {  // column-major: each column is three doubles in a row
  return {{load3(M.data()), load3(M.data() + 3), load3(M.data() + 6)}};
}
/// The unit vectors, e[k] = lane k one, the others zero.
inline constexpr Lanes unit[3] = {{1.0, 0.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}};

/// M x, x given by its three components.
inline Lanes times(const LaneMatrix& M, double x, double y, double z) { return M.c[0] * x + M.c[1] * y + M.c[2] * z; }
inline Lanes times(const LaneMatrix& M, const Vector3d& x) { return times(M, x.x(), x.y(), x.z()); }
/// M X
inline LaneMatrix times(const LaneMatrix& M, const Matrix3d& X) {
  return {{times(M, X(0, 0), X(1, 0), X(2, 0)), times(M, X(0, 1), X(1, 1), X(2, 1)),
           times(M, X(0, 2), X(1, 2), X(2, 2))}};
}
/// A M^T, M given by its columns: column k of the result is sum_j A.c[j] M(k, j).
inline LaneMatrix timesTransposed(const LaneMatrix& A, const LaneMatrix& M) {
  LaneMatrix out;
  for (int k = 0; k < 3; ++k) out.c[k] = A.c[0] * M.c[0][k] + A.c[1] * M.c[1][k] + A.c[2] * M.c[2][k];
  return out;
}

inline Lanes cross(const Lanes& a, const Lanes& b) {
  const Lanes a_yzx = __builtin_shufflevector(a, a, 1, 2, 0, 3), b_yzx = __builtin_shufflevector(b, b, 1, 2, 0, 3);
  const Lanes a_zxy = __builtin_shufflevector(a, a, 2, 0, 1, 3), b_zxy = __builtin_shufflevector(b, b, 2, 0, 1, 3);
  return a_yzx * b_zxy - a_zxy * b_yzx;
}

/// v[0] + v[1] + v[2]
inline double sum3(const Lanes& v) { return v[0] + v[1] + v[2]; }
/// The dot product of two 6-vectors given as their (top; bottom) halves.
inline double dot(const Lanes& a_top, const Lanes& a_bottom, const Lanes& b_top, const Lanes& b_bottom) {
  return sum3(a_top * b_top + a_bottom * b_bottom);
}

/// Stores lanes 0-2 (three doubles; lane 3 is not written).
inline void store3(const Lanes& v, double* out) {
  std::memcpy(out, &v, 2 * sizeof(double));
  out[2] = v[2];
}
inline void store(const Lanes& v, Vector3d& out) { store3(v, out.data()); }
inline void store(const LaneMatrix& M, Matrix3d& out) {
  for (int k = 0; k < 3; ++k) store3(M.c[k], out.data() + 3 * k);  // column-major
}

}  // namespace kdl_space::detail
