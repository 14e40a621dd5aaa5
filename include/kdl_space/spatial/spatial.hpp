// Pure 6-D algebra in the conventions of MATH.md: twist (v; w), wrench (f; n), world frame.
// Stateless, allocation-free free functions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <kdl/frames.hpp>

#include "kdl_space/export.hpp"

namespace kdl_space {

using Vector3d = Eigen::Vector3d;
using Matrix3d = Eigen::Matrix3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;
/// The one 6x6 alias KDL lacks (spatial inertias, G*, R_h).
using Matrix6d = Eigen::Matrix<double, 6, 6>;
/// 6 x n matrices indexed by joint (A_m, J, J*).
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// \brief Cross-product matrix: skew(r) x = r x x (the paper's r-hat, eq. 1).
KDL_SPACE_EXPORT Matrix3d skew(const Vector3d& r);

/// \brief Rigid transfer of a twist from point a to point a + r (eq. 5):
/// `[[E, -skew(r)], [0, E]]`. With r = r_gh it is the paper's R_h; its transpose maps a wrench
/// at a + r to the same wrench at a (eq. 8).
KDL_SPACE_EXPORT Matrix6d transfer(const Vector3d& r);

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

/// True when every number of the frame (vector, twist) is finite.
/// Spatial cross product of motions, V x U, (linear; angular) order (Featherstone's crm).
inline Vector6d crossMotion(const Vector6d& V, const Vector6d& U) {
  Vector6d r;
  const Vector3d w = V.tail<3>();
  r.head<3>() = w.cross(U.head<3>()) + V.head<3>().cross(U.tail<3>());
  r.tail<3>() = w.cross(U.tail<3>());
  return r;
}

/// Spatial cross product of a motion and a force, V x* F, (f; n) order (Featherstone's crf).
inline Vector6d crossForce(const Vector6d& V, const Vector6d& F) {
  Vector6d r;
  r.head<3>() = V.tail<3>().cross(F.head<3>());
  r.tail<3>() = V.tail<3>().cross(F.tail<3>()) + V.head<3>().cross(F.head<3>());
  return r;
}

KDL_SPACE_EXPORT bool allFinite(const KDL::Frame& f);
KDL_SPACE_EXPORT bool allFinite(const KDL::Vector& v);
KDL_SPACE_EXPORT bool allFinite(const KDL::Twist& t);

/// \brief Momentum (P; L) with its angular part about point a moved to point b = a + r:
/// L_b = L_a - r x P (e.g. about the world origin from about r_g: r = -r_g, L_O = L_g + r_g x P).
inline Vector6d shiftMomentum(const Vector6d& PL, const Vector3d& r) {
  Vector6d m = PL;
  m.tail<3>() -= r.cross(PL.head<3>());
  return m;
}

/// \brief Spatial inertia (6x6, (v; w) order) of a rigid body about a reference point, world
/// axes: mass m, CoM at c relative to the reference point, inertia I_c about the CoM.
/// Maps a twist at the reference point to the momentum (P; L about the reference point).
KDL_SPACE_EXPORT Matrix6d spatialInertia(double m, const Vector3d& c, const Matrix3d& I_c);

/// \brief Inverse inertia of a rigid body B at a point c: G_B = R_b M_b^-1 R_b^T (eq. 15-17; with the whole system locked, w, I_g and r_gh, it is eq. 20),
/// mass m, inertia I_com about the CoM (world axes), r_bc = p_c - p_b.
/// \return 0, E_NOT_FINITE (an input, or the result overflows), E_BAD_ARGUMENT (m <= 0) or
/// E_NOT_POSITIVE_DEFINITE (I_com). `G_B` untouched on an error.
KDL_SPACE_EXPORT int rigidBodyG(double m, const Matrix3d& I_com, const Vector3d& r_bc, Matrix6d& G_B);
/// The same, unchecked (m > 0 and I_com symmetric positive definite are the caller's).
KDL_SPACE_EXPORT Matrix6d rigidBodyG(double m, const Matrix3d& I_com, const Vector3d& r_bc);

/// \brief Centroid inertia M_a = diag(w E, I_g) (eq. 12).
KDL_SPACE_EXPORT Matrix6d centroidInertia(double w, const Matrix3d& I_g);

/// \brief Rank and conditioning of a symmetric positive semi-definite 6x6 matrix (e.g. the
/// grounded G, which is singular where J is).
struct SpectralFigures {
  int rank = 0;                  ///< eigenvalues above `tolerance * largest`
  double min_eigenvalue = 0.0;
  double max_eigenvalue = 0.0;
  double condition = 0.0;        ///< max/min eigenvalue; +inf when singular
};
KDL_SPACE_EXPORT SpectralFigures spectralFigures(const Matrix6d& G, double tolerance = 1e-12);

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
KDL_SPACE_EXPORT Matrix3d toEigen(const KDL::Rotation& R);
/// The rotation vector (axis times angle) of R, accurate at small angles: KDL's Rotation::GetRot
/// (and so KDL::diff) reads every angle below about 1e-6 rad as 0, too coarse for a 1e-9 rad
/// tolerance.
KDL_SPACE_EXPORT KDL::Vector rotationVector(const KDL::Rotation& R);
inline KDL::Vector toKDL(const Vector3d& v) { return KDL::Vector(v.x(), v.y(), v.z()); }
inline KDL::Twist toTwist(const Vector6d& t) {
  return KDL::Twist(KDL::Vector(t(0), t(1), t(2)), KDL::Vector(t(3), t(4), t(5)));
}
inline KDL::Wrench toWrench(const Vector6d& w) {
  return KDL::Wrench(KDL::Vector(w(0), w(1), w(2)), KDL::Vector(w(3), w(4), w(5)));
}

}  // namespace kdl_space
