// The packed symmetric 6x6 of the O(n) recursions (spatial, articulated inertias): an internal, not API.
#pragma once

#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space::detail {

/// \brief A symmetric 6x6 (spatial or articulated inertia, inverse inertia) stored as the 21
/// numbers of its lower triangle: half the arithmetic of a Matrix6d in the O(n) recursions.
struct Symmetric6d {
  double a[21];

  static constexpr int index(int r, int c) { return r >= c ? r * (r + 1) / 2 + c : c * (c + 1) / 2 + r; }
  double operator()(int r, int c) const { return a[index(r, c)]; }
  void setZero() { Eigen::Map<Eigen::Matrix<double, 21, 1>>(a).setZero(); }  // vector stores, not rep stos
  Symmetric6d& operator+=(const Symmetric6d& o) {
    for (int k = 0; k < 21; ++k) a[k] += o.a[k];
    return *this;
  }
  /// this * x (each stored number used twice off the diagonal): six independent dot products,
  /// each as three pairs summed (a shorter chain of dependent operations than six in a row)
  Vector6d operator*(const Vector6d& x) const {
    Vector6d y;
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r) {
      const double s01 = a[index(r, 0)] * x(0) + a[index(r, 1)] * x(1);
      const double s23 = a[index(r, 2)] * x(2) + a[index(r, 3)] * x(3);
      const double s45 = a[index(r, 4)] * x(4) + a[index(r, 5)] * x(5);
      y(r) = s01 + (s23 + s45);
    }
    return y;
  }
  /// this += B - alpha u u^T, in one pass (an articulated body's contribution to its parent)
  void addMinusRank1(const Symmetric6d& B, const Vector6d& u, double alpha) {
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r) {
      const double ur = alpha * u(r);
      const int row = r * (r + 1) / 2;
#pragma GCC unroll 6
      for (int c = 0; c <= r; ++c) a[row + c] += B.a[row + c] - ur * u(c);
    }
  }
  /// Adds the spatial inertia of a rigid body about the reference point, world axes: mass m,
  /// CoM at c relative to the point, inertia I_c about the CoM (as spatialInertia).
  void addRigidBody(double m, const Vector3d& c, const Matrix3d& I_c) {
    const double mx = m * c.x(), my = m * c.y(), mz = m * c.z();
    a[0] += m, a[2] += m, a[5] += m;                           // m E
    a[7] += -mz, a[8] += my;                                   // m skew(c), rows 3-5, columns 0-2
    a[10] += mz, a[12] += -mx;
    a[15] += -my, a[16] += mx;
    // I_c + m (|c|^2 E - c c^T)
    a[9] += I_c(0, 0) + my * c.y() + mz * c.z();
    a[13] += I_c(1, 0) - mx * c.y();
    a[14] += I_c(1, 1) + mx * c.x() + mz * c.z();
    a[18] += I_c(2, 0) - mx * c.z();
    a[19] += I_c(2, 1) - my * c.z();
    a[20] += I_c(2, 2) + mx * c.x() + my * c.y();
  }
  /// The spatial inertia of one rigid body (as addRigidBody), replacing the contents.
  void setRigidBody(double m, const Vector3d& c, const Matrix3d& I_c) {
    const double mx = m * c.x(), my = m * c.y(), mz = m * c.z();
    a[0] = m, a[1] = 0.0, a[2] = m, a[3] = 0.0, a[4] = 0.0, a[5] = m;  // m E
    a[6] = 0.0, a[7] = -mz, a[8] = my;                                 // m skew(c)
    a[10] = mz, a[11] = 0.0, a[12] = -mx;
    a[15] = -my, a[16] = mx, a[17] = 0.0;
    a[9] = I_c(0, 0) + my * c.y() + mz * c.z();                        // I_c + m (|c|^2 E - c c^T)
    a[13] = I_c(1, 0) - mx * c.y();
    a[14] = I_c(1, 1) + mx * c.x() + mz * c.z();
    a[18] = I_c(2, 0) - mx * c.z();
    a[19] = I_c(2, 1) - my * c.z();
    a[20] = I_c(2, 2) + mx * c.x() + my * c.y();
  }
  /// \brief The root-free Cholesky factors A = L D L^T (L unit lower triangular, only its
  /// strictly lower part written; d_inv = D^-1; no pivoting, as for any symmetric positive
  /// definite matrix). \return false when a pivot is not positive (not positive definite, NaN).
  bool factor(double (&L)[6][6], double (&d_inv)[6]) const {
    double LD[6][6];  // LD(i, k) = L(i, k) d_k
#pragma GCC unroll 6
    for (int j = 0; j < 6; ++j) {
      double d = a[index(j, j)];
      for (int k = 0; k < j; ++k) d -= L[j][k] * LD[j][k];
      if (!(d > 0.0)) return false;
      d_inv[j] = 1.0 / d;
      for (int i = j + 1; i < 6; ++i) {
        double s = a[index(i, j)];
        for (int k = 0; k < j; ++k) s -= L[i][k] * LD[j][k];
        LD[i][j] = s;
        L[i][j] = s * d_inv[j];
      }
    }
    return true;
  }
  /// \brief The inverse, from the root-free Cholesky factors A = L D L^T (L unit lower
  /// triangular; no pivoting, as for any symmetric positive definite matrix):
  /// A^-1 = X^T D^-1 X with X = L^-1. \return false, `inverse` unspecified, when a pivot is not
  /// positive: the matrix is not positive definite (or holds NaN).
  bool invert(Symmetric6d& inverse) const {
    double L[6][6], d_inv[6];
    if (!factor(L, d_inv)) return false;
    double X[6][6];  // X = L^-1, unit lower triangular: X(i, c) = -sum_{c <= k < i} L(i, k) X(k, c)
#pragma GCC unroll 6
    for (int c = 0; c < 6; ++c) {
      X[c][c] = 1.0;
      for (int i = c + 1; i < 6; ++i) {
        double s = -L[i][c];
        for (int k = c + 1; k < i; ++k) s -= L[i][k] * X[k][c];
        X[i][c] = s;
      }
    }
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r)  // (X^T D^-1 X)(r, c) = sum_{k >= r} X(k, r) X(k, c) / d_k, c <= r
      for (int c = 0; c <= r; ++c) {
        double s = 0.0;
        for (int k = r; k < 6; ++k) s += X[k][r] * d_inv[k] * X[k][c];
        inverse.a[index(r, c)] = s;
      }
    return true;
  }
  /// \brief x = this^-1 b by the same root-free Cholesky factors A = L D L^T, then forward and
  /// back substitution (no inverse formed). \return false, `x` unspecified, when a pivot is not
  /// positive.
  bool solve(const Vector6d& b, Vector6d& x) const {
    double L[6][6], d_inv[6], y[6];
    if (!factor(L, d_inv)) return false;
#pragma GCC unroll 6
    for (int i = 0; i < 6; ++i) {  // L y = b
      double s = b(i);
      for (int k = 0; k < i; ++k) s -= L[i][k] * y[k];
      y[i] = s;
    }
#pragma GCC unroll 6
    for (int i = 5; i >= 0; --i) {  // L^T x = D^-1 y
      double s = y[i] * d_inv[i];
      for (int k = i + 1; k < 6; ++k) s -= L[k][i] * x(k);
      x(i) = s;
    }
    return true;
  }
  Matrix6d toDense() const {
    Matrix6d M;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) M(r, c) = a[index(r, c)];
    return M;
  }
};

}  // namespace kdl_space::detail
