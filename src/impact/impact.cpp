#include "kdl_space/impact/impact.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "impact/impact_friction.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

Impulse solveImpact(const Matrix6d& G_A, const Matrix6d& G_B, const Vector6d& t_A, const Vector6d& t_B,
                    const ImpactLaw& law) {
  Impulse out;
  const Matrix6d G = G_A + G_B;  // relative twist jump per impulse: d(t_A - t_B) = G F
  const Matrix3d W = G.topLeftCorner<3, 3>();
  const Vector3d u = t_A.head<3>() - t_B.head<3>();  // relative linear velocity of A w.r.t. B
  const Vector3d n = law.normal.normalized();  // unit to round-off whatever the caller gave
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
  // P: force impulse on B (A gets -P); afterwards the relative velocity is u' = u - W P.
  const double e = law.restitution;
  Vector3d P;
  if (law.kind == ImpactKind::PointImpact || law.friction == 0.0) {
    P = (1.0 + e) * u_n / n.dot(W * n) * n;  // Newton: n^T u' = -e u_n
  } else {
    const friction::SlipProcess sp = friction::solveSlipProcess(W, n, law.friction, e, u);
    P = sp.P;
    out.sticking = sp.sticking;
    out.max_dissipation_completion = sp.completed_by_max_dissipation;
  }
  out.F.head<3>() = -P;
  return out;
}

int solveImpact(const Matrix6d& G_A, const Matrix6d& G_B, const Vector6d& t_A, const Vector6d& t_B,
                const ImpactLaw& law, Impulse& impulse) {
  if (!G_A.allFinite() || !G_B.allFinite() || !t_A.allFinite() || !t_B.allFinite()) return E_NOT_FINITE;
  const Matrix6d G = G_A + G_B;
  if (!G.allFinite()) return E_NOT_FINITE;
  const Matrix3d W = G.topLeftCorner<3, 3>();
  switch (law.kind) {
    case ImpactKind::Capture:
      if (G.llt().info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
      break;
    case ImpactKind::TranslationalCapture:
      if (W.llt().info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
      break;
    case ImpactKind::PointImpact:
    case ImpactKind::FrictionalImpact: {
      const bool friction = law.kind == ImpactKind::FrictionalImpact;
      if (!law.normal.allFinite() || !std::isfinite(law.restitution) || (friction && !std::isfinite(law.friction)))
        return E_NOT_FINITE;
      if (!(law.normal.norm() > 0.0) || law.restitution < 0.0 || law.restitution > 1.0 || (friction && law.friction < 0.0))
        return E_BAD_ARGUMENT;
      const Vector3d n = law.normal.normalized();
      if (!(n.dot(W * n) > 0.0)) return E_NOT_POSITIVE_DEFINITE;
      if (friction && law.friction > 0.0 && W.llt().info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
      break;
    }
    default:
      return E_BAD_ARGUMENT;  // not one of the enumerators
  }
  const Impulse result = solveImpact(G_A, G_B, t_A, t_B, law);
  if (!result.F.allFinite()) return E_NOT_FINITE;
  impulse = result;
  return E_NOERROR;
}

int virtualMass(const Matrix6d& G, const Vector3d& n, double& m) {
  if (!G.allFinite() || !n.allFinite()) return E_NOT_FINITE;
  if (!(n.norm() > 0.0)) return E_BAD_ARGUMENT;
  const Vector3d u = n.normalized();
  const double inverse = u.dot(G.topLeftCorner<3, 3>() * u);
  if (!(inverse > 0.0)) return E_NOT_POSITIVE_DEFINITE;
  const double mass = 1.0 / inverse;
  if (!std::isfinite(mass)) return E_NOT_FINITE;
  m = mass;
  return E_NOERROR;
}

double virtualMass(const Matrix6d& G, const Vector3d& n) { return 1.0 / n.dot(G.topLeftCorner<3, 3>() * n); }

}  // namespace kdl_space
