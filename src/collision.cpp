#include "kdl_space/collision.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace kdl_space {

FloatingSide::FloatingSide(FreeFloatingSolver& solver, const Contact& h, const FloatingVelocity& before,
                           Response response, ExIITMethod method)
    : solver_(solver), h_(h), response_(response), before_(before), after_(before), dqdot_(solver.model().nj()) {
  if (before.qdot.rows() != solver.model().nj())
    throw ModelError("robot: " + std::to_string(before.qdot.rows()) + " joint rates for " +
                     std::to_string(solver.model().nj()) + " joints");
  Vector3d p_h;
  if (const int rc = solver_.contactPoint(h_, p_h)) throw ModelError(std::string("robot: ") + strError(rc));
  if (response_ == Response::FreeFloating && method == ExIITMethod::Recursive) {
    recursive_ = std::make_unique<RecursiveExIITSolver>(solver_.sharedModel());
    int rc = recursive_->compute(solver_.state());
    if (rc == E_NOERROR) rc = recursive_->G_star(h_, G_);
    if (rc) throw ModelError(std::string("robot: ") + strError(rc));
  } else if (const int rc = solver_.G(h_, response_, G_)) {
    throw ModelError(std::string("robot: ") + strError(rc));
  }
  if (response_ == Response::Grounded) {
    // The grounded base does not move, whatever twist was given.
    before_.base_twist = after_.base_twist = KDL::Twist::Zero();
  }
  solver_.momentum(before_.base_twist, before_.qdot, PL_before_);
  solver_.kineticEnergy(before_.base_twist, before_.qdot, T_before_);
  PL_after_ = PL_before_;
  T_after_ = T_before_;
  t_before_ = t_after_ = contactTwist(before_);
}

Vector6d FloatingSide::contactTwist(const FloatingVelocity& v) const {
  Vector6d PL;
  solver_.momentum(v.base_twist, v.qdot, PL);
  KDL::Twist t;
  solver_.handTwist(h_, v.qdot, PL, t);  // eq. 4
  return toEigen(t);
}

int FloatingSide::applyImpulse(const Vector6d& F) {
  if (recursive_) {
    Vector6d d_base;
    if (const int rc = recursive_->velocityJump(h_, F, d_base, dqdot_)) return rc;
    after_.qdot.data = before_.qdot.data + dqdot_.data;
    after_.base_twist = before_.base_twist + toTwist(d_base);
    solver_.momentum(after_.base_twist, after_.qdot, PL_after_);
    solver_.kineticEnergy(after_.base_twist, after_.qdot, T_after_);
    t_after_ = contactTwist(after_);
    return E_NOERROR;
  }
  Vector6d dPL;
  if (const int rc = solver_.velocityJump(h_, response_, F, dPL, dqdot_)) return rc;
  after_.qdot.data = before_.qdot.data + dqdot_.data;
  if (response_ != Response::Grounded) {
    PL_after_ = PL_before_ + dPL;
    solver_.baseTwist(PL_after_, after_.qdot, after_.base_twist);
  } else {
    solver_.momentum(after_.base_twist, after_.qdot, PL_after_);
  }
  solver_.kineticEnergy(after_.base_twist, after_.qdot, T_after_);
  t_after_ = contactTwist(after_);
  return E_NOERROR;
}

Vector6d FloatingSide::aboutOrigin(const Vector6d& PL_g) const {
  Vector6d m = PL_g;
  m.tail<3>() += solver_.r_g().cross(PL_g.head<3>());  // L_O = L_g + r_g x P
  return m;
}

Vector6d FloatingSide::centroidTwistBefore() const {
  Vector6d t = PL_before_;
  t.head<3>() /= solver_.w();
  t.tail<3>() = solver_.I_g().llt().solve(Vector3d(PL_before_.tail<3>()));
  return t;
}

Vector6d FloatingSide::centroidTwistAfter() const {
  Vector6d t = PL_after_;
  t.head<3>() /= solver_.w();
  t.tail<3>() = solver_.I_g().llt().solve(Vector3d(PL_after_.tail<3>()));
  return t;
}

RigidBodySide::RigidBodySide(const RigidBody& body, const Vector3d& contact_point)
    : body_(body), r_bc_(contact_point - body.com) {
  if (!(body.mass > 0.0) || !std::isfinite(body.mass)) throw ModelError("target: mass must be a finite value > 0");
  if (!body.I_com.allFinite() || !body.com.allFinite() || !body.twist.allFinite() || !contact_point.allFinite())
    throw ModelError("target: inertia, CoM, twist and contact point must be finite");
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(0.5 * (body.I_com + body.I_com.transpose()),
                                                    Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()(0) > 0.0) || (body.I_com - body.I_com.transpose()).norm() > 1e-12 * body.I_com.norm())
    throw ModelError("target: inertia must be symmetric positive definite");
  G_ = rigidBodyG(body.mass, body.I_com, r_bc_);
  t_before_ = transfer(r_bc_) * body.twist;
  twist_after_ = body.twist;
}

Vector6d RigidBodySide::contactTwistAfter() const { return transfer(r_bc_) * twist_after_; }

int RigidBodySide::applyImpulse(const Vector6d& F) {
  if (!F.allFinite()) return E_NOT_FINITE;
  const Vector6d at_com = transfer(r_bc_).transpose() * F;  // wrench moved to the CoM (eq. 8)
  twist_after_.head<3>() = body_.twist.head<3>() + at_com.head<3>() / body_.mass;
  twist_after_.tail<3>() = body_.twist.tail<3>() + body_.I_com.llt().solve(Vector3d(at_com.tail<3>()));
  return E_NOERROR;
}

Vector6d RigidBodySide::momentum(const Vector6d& twist) const {
  Vector6d m;
  m.head<3>() = body_.mass * twist.head<3>();
  m.tail<3>() = body_.I_com * twist.tail<3>() + body_.com.cross(m.head<3>());
  return m;
}

double RigidBodySide::energy(const Vector6d& twist) const {
  return 0.5 * body_.mass * twist.head<3>().squaredNorm() + 0.5 * twist.tail<3>().dot(body_.I_com * twist.tail<3>());
}

Impulse collide(ImpactSide& A, ImpactSide& B, const ImpactLaw& law) {
  const Impulse impulse = solveImpact(A.G(), B.G(), A.contactTwistBefore(), B.contactTwistBefore(), law);
  if (const int rc = A.applyImpulse(impulse.F)) throw ModelError(std::string("robot: ") + strError(rc));
  if (const int rc = B.applyImpulse(-impulse.F)) throw ModelError(std::string("target: ") + strError(rc));
  return impulse;
}

}  // namespace kdl_space
