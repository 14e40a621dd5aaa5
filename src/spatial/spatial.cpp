#include "kdl_space/spatial/spatial.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "spatial/symmetric6d.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

Matrix3d skew(const Vector3d& r) {
  Matrix3d S;
  S << 0.0, -r.z(), r.y(),  //
      r.z(), 0.0, -r.x(),   //
      -r.y(), r.x(), 0.0;
  return S;
}

Matrix6d transfer(const Vector3d& r) {
  Matrix6d R = Matrix6d::Identity();
  R.topRightCorner<3, 3>() = -skew(r);  // eq. 5
  return R;
}

Matrix6d spatialInertia(double m, const Vector3d& c, const Matrix3d& I_c) {
  detail::Symmetric6d M;  // one formula for the packed and the dense form
  M.setZero();
  M.addRigidBody(m, c, I_c);
  return M.toDense();
}

Matrix6d centroidInertia(double w, const Matrix3d& I_g) {
  Matrix6d M_a = Matrix6d::Zero();
  M_a.topLeftCorner<3, 3>() = w * Matrix3d::Identity();  // eq. 12
  M_a.bottomRightCorner<3, 3>() = I_g;
  return M_a;
}

SpectralFigures spectralFigures(const Matrix6d& G, double tolerance) {
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(G, Eigen::EigenvaluesOnly);
  const Vector6d& lambda = eig.eigenvalues();  // ascending
  SpectralFigures f;
  f.max_eigenvalue = lambda(5);
  f.min_eigenvalue = lambda(0);
  const double threshold = tolerance * std::max(std::abs(lambda(5)), std::numeric_limits<double>::min());
  for (int i = 0; i < 6; ++i) f.rank += lambda(i) > threshold ? 1 : 0;
  f.condition = f.rank == 6 ? lambda(5) / lambda(0) : std::numeric_limits<double>::infinity();
  return f;
}

bool allFinite(const KDL::Frame& f) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(f.p(i))) return false;
    for (int j = 0; j < 3; ++j)
      if (!std::isfinite(f.M(i, j))) return false;
  }
  return true;
}

bool allFinite(const KDL::Vector& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
bool allFinite(const KDL::Twist& t) { return allFinite(t.vel) && allFinite(t.rot); }

Matrix3d toEigen(const KDL::Rotation& R) {
  Matrix3d M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, j) = R(i, j);
  return M;
}

int rigidBodyG(double m, const Matrix3d& I_com, const Vector3d& r_bc, Matrix6d& G_B) {
  if (!std::isfinite(m) || !I_com.allFinite() || !r_bc.allFinite()) return E_NOT_FINITE;
  if (!(m > 0.0)) return E_BAD_ARGUMENT;
  if ((0.5 * (I_com + I_com.transpose())).llt().info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  const Matrix6d G = rigidBodyG(m, I_com, r_bc);
  if (!G.allFinite()) return E_NOT_FINITE;
  G_B = G;
  return E_NOERROR;
}

Matrix6d rigidBodyG(double m, const Matrix3d& I_com, const Vector3d& r_bc) {
  const Matrix6d R_b = transfer(r_bc);  // eq. 16: twist at the CoM -> twist at c
  Matrix6d M_inv_Rt = R_b.transpose();
  M_inv_Rt.topRows<3>() /= m;
  M_inv_Rt.bottomRows<3>() = I_com.llt().solve(M_inv_Rt.bottomRows<3>().eval());
  return R_b * M_inv_Rt;  // eq. 17: G_B = R_b M_b^-1 R_b^T
}

KDL::Vector rotationVector(const KDL::Rotation& R) {
  const KDL::Vector v(0.5 * (R(2, 1) - R(1, 2)), 0.5 * (R(0, 2) - R(2, 0)), 0.5 * (R(1, 0) - R(0, 1)));  // sin(a) axis
  const double c = 0.5 * (R(0, 0) + R(1, 1) + R(2, 2) - 1.0);                                        // cos(a)
  if (c < 0.0) return R.GetRot();  // beyond 90 degrees KDL's own is accurate (and handles 180)
  const double s = std::sqrt(KDL::dot(v, v));
  if (s == 0.0) return KDL::Vector::Zero();
  return v * (std::atan2(s, c) / s);
}

}  // namespace kdl_space
