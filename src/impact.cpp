#include "kdl_space/impact.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace kdl_space {

Impulse solveImpact(const Matrix6d& G_A, const Matrix6d& G_B, const Vector6d& t_A, const Vector6d& t_B,
                    const ImpactLaw& law) {
  Impulse out;
  const Matrix6d G = G_A + G_B;  // relative twist jump per impulse: d(t_A - t_B) = G F
  const Matrix3d W = G.topLeftCorner<3, 3>();
  const Vector3d u = t_A.head<3>() - t_B.head<3>();  // relative linear velocity of A w.r.t. B
  const Vector3d& n = law.normal;
  switch (law.kind) {
    case ImpactKind::Capture:
      out.F = G.llt().solve(t_B - t_A);  // eq. 24
      return out;
    case ImpactKind::TranslationalCapture:
      out.F.head<3>() = W.llt().solve(-u);
      return out;
    case ImpactKind::PointImpact:
    case ImpactKind::FrictionalImpact:
      break;
  }
  const double u_n = n.dot(u);
  if (u_n <= 0.0) {
    out.separating = true;
    return out;
  }
  // P: force impulse on B (A gets -P); afterwards u' = u - W P and n^T u' = -e u_n.
  const double e = law.restitution;
  Vector3d P = (1.0 + e) * u_n / n.dot(W * n) * n;  // frictionless
  if (law.kind == ImpactKind::FrictionalImpact && law.friction > 0.0) {
    const Eigen::LLT<Matrix3d> W_llt(W);
    const Vector3d P_stick = W_llt.solve(u + e * u_n * n);  // u' = -e u_n n: slip stopped
    const double P_n = n.dot(P_stick);
    if ((P_stick - P_n * n).norm() <= law.friction * P_n) {
      P = P_stick;
      out.sticking = true;
    } else {
      const Vector3d u_t = u - u_n * n;
      const double slip = u_t.norm();
      // With no initial slip the sticking impulse would have been in the cone unless the
      // coupling W drives slip: then slide along the direction the frictionless impulse drives.
      const Vector3d s = slip > 0.0 ? Vector3d(u_t / slip) : [&] {
        const Vector3d drive = -(W * n - n.dot(W * n) * n);
        return drive.norm() > 0.0 ? Vector3d(drive.normalized()) : Vector3d::Zero();
      }();
      const Vector3d d = n + law.friction * s;  // friction on B along the slip, on A against it
      P = (1.0 + e) * u_n / n.dot(W * d) * d;
    }
  }
  out.F.head<3>() = -P;
  return out;
}

double virtualMass(const Matrix6d& G, const Vector3d& n) { return 1.0 / n.dot(G.topLeftCorner<3, 3>() * n); }

Matrix6d rigidBodyG(double m, const Matrix3d& I_com, const Vector3d& r_bc) {
  const Matrix6d R_b = transfer(r_bc);  // eq. 16: twist at the CoM -> twist at c
  Matrix6d M_inv_Rt = R_b.transpose();
  M_inv_Rt.topRows<3>() /= m;
  M_inv_Rt.bottomRows<3>() = I_com.llt().solve(M_inv_Rt.bottomRows<3>().eval());
  return R_b * M_inv_Rt;  // eq. 17: G_B = R_b M_b^-1 R_b^T
}

}  // namespace kdl_space
