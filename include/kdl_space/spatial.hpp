// Pure 6-D algebra in the conventions of MATH.md: twist (v; w), wrench (f; n), world frame.
// Stateless, allocation-free free functions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <kdl/frames.hpp>

namespace kdl_space {

using Vector3d = Eigen::Vector3d;
using Matrix3d = Eigen::Matrix3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;
/// The one 6x6 alias KDL lacks (spatial inertias, G*, R_h).
using Matrix6d = Eigen::Matrix<double, 6, 6>;
/// 6 x n matrices indexed by joint (A_m, J, J*).
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// \brief Cross-product matrix: skew(r) x = r x x (the paper's r-hat, eq. 1).
Matrix3d skew(const Vector3d& r);

/// \brief Rigid transfer of a twist from point a to point a + r (eq. 5):
/// `[[E, -skew(r)], [0, E]]`. With r = r_gh it is the paper's R_h; its transpose maps a wrench
/// at a + r to the same wrench at a (eq. 8).
Matrix6d transfer(const Vector3d& r);

/// \brief The same rigid twist with its reference point moved by r (from the old point to the
/// new one): v' = v + w x r. (transfer(r) t, without the 6x6 product.)
inline Vector6d shiftTwist(const Vector6d& t, const Vector3d& r) {
  Vector6d s = t;
  s.head<3>() += t.tail<3>().cross(r);
  return s;
}

/// Averages a square matrix with its transpose in place: a symmetric result exactly symmetric.
template <typename Derived>
void symmetrize(Eigen::MatrixBase<Derived>& A) {
  for (Eigen::Index i = 0; i < A.rows(); ++i)
    for (Eigen::Index j = i + 1; j < A.cols(); ++j) A(i, j) = A(j, i) = 0.5 * (A(i, j) + A(j, i));
}

/// True when every number of the frame is finite.
bool allFinite(const KDL::Frame& f);

/// \brief Spatial inertia (6x6, (v; w) order) of a rigid body about a reference point, world
/// axes: mass m, CoM at c relative to the reference point, inertia I_c about the CoM.
/// Maps a twist at the reference point to the momentum (P; L about the reference point).
Matrix6d spatialInertia(double m, const Vector3d& c, const Matrix3d& I_c);

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
  /// \brief The inverse, from the root-free Cholesky factors A = L D L^T (L unit lower
  /// triangular; no pivoting, as for any symmetric positive definite matrix):
  /// A^-1 = X^T D^-1 X with X = L^-1. \return false, `inverse` unspecified, when a pivot is not
  /// positive: the matrix is not positive definite (or holds NaN).
  bool invert(Symmetric6d& inverse) const {
    double L[6][6], LD[6][6], d_inv[6];  // LD(i, k) = L(i, k) d_k
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
  Matrix6d toDense() const {
    Matrix6d M;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) M(r, c) = a[index(r, c)];
    return M;
  }
};

/// \brief Centroid inertia M_a = diag(w E, I_g) (eq. 12).
Matrix6d centroidInertia(double w, const Matrix3d& I_g);

/// \brief Rank and conditioning of a symmetric positive semi-definite 6x6 matrix (e.g. the
/// grounded G, which is singular where J is).
struct SpectralFigures {
  int rank = 0;                  ///< eigenvalues above `tolerance * largest`
  double min_eigenvalue = 0.0;
  double max_eigenvalue = 0.0;
  double condition = 0.0;        ///< max/min eigenvalue; +inf when singular
};
SpectralFigures spectralFigures(const Matrix6d& G, double tolerance = 1e-12);

/// Conversions between KDL and Eigen, same component order.
inline Vector3d toEigen(const KDL::Vector& v) { return Vector3d(v.x(), v.y(), v.z()); }
inline Vector6d toEigen(const KDL::Twist& t) {
  Vector6d r;
  r << t.vel.x(), t.vel.y(), t.vel.z(), t.rot.x(), t.rot.y(), t.rot.z();
  return r;
}
inline Vector6d toEigen(const KDL::Wrench& w) {
  Vector6d r;
  r << w.force.x(), w.force.y(), w.force.z(), w.torque.x(), w.torque.y(), w.torque.z();
  return r;
}
Matrix3d toEigen(const KDL::Rotation& R);
inline KDL::Vector toKDL(const Vector3d& v) { return KDL::Vector(v.x(), v.y(), v.z()); }
inline KDL::Twist toTwist(const Vector6d& t) {
  return KDL::Twist(KDL::Vector(t(0), t(1), t(2)), KDL::Vector(t(3), t(4), t(5)));
}
inline KDL::Wrench toWrench(const Vector6d& w) {
  return KDL::Wrench(KDL::Vector(w(0), w(1), w(2)), KDL::Vector(w(3), w(4), w(5)));
}

}  // namespace kdl_space
