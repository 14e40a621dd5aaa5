#include "kdl_space/spatial.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "detail/symmetric6d.hpp"

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

}  // namespace kdl_space
