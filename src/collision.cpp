#include "kdl_space/collision.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

namespace kdl_space {

namespace {
bool finite(const KDL::Vector& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

[[noreturn]] void refuse(const std::string& what) { throw ModelError("FloatingSide: " + what); }
[[noreturn]] void refuse(const std::string& what, int rc) { refuse(what + ": " + strError(rc)); }
}  // namespace

FloatingSide::FloatingSide(FreeFloatingSolver& solver, const Contact& h, const FloatingVelocity& before,
                           Response response, ExIITMethod method)
    : solver_(solver), h_(h), response_(response), before_(before), after_(before), dqdot_(solver.model().nj()),
      trial_(before) {
  const unsigned int n = solver.model().nj();
  if (before.qdot.rows() != n)
    refuse(std::to_string(before.qdot.rows()) + " joint rates given for the model's " + std::to_string(n) + " joints");
  if (!before.qdot.data.allFinite() || !finite(before.base_twist.vel) || !finite(before.base_twist.rot))
    refuse("the base twist or a joint rate is NaN or infinite");
  if (response_ != Response::FreeFloating && response_ != Response::Grounded && response_ != Response::JointsLocked)
    refuse("the response is not one of FreeFloating, Grounded, JointsLocked");
  Vector3d p_h;
  if (const int rc = solver_.contactPoint(h_, p_h)) refuse("contact point", rc);
  r_g_ = solver_.r_g();
  if (response_ == Response::FreeFloating && method == ExIITMethod::Recursive) {
    recursive_ = std::make_unique<RecursiveExIITSolver>(solver_.sharedModel());
    int rc = recursive_->compute(solver_.state());
    if (rc == E_NOERROR) rc = recursive_->G_star(h_, G_);
    if (rc == E_NOERROR && !G_.allFinite()) rc = E_NOT_FINITE;
    if (rc) refuse("G* at the contact point", rc);
  } else if (const int rc = solver_.G(h_, response_, G_)) {
    refuse(response_ == Response::Grounded ? "grounded G at the contact point" : "G at the contact point", rc);
  }
  if (response_ == Response::Grounded) {
    // The grounded base does not move, whatever twist was given.
    before_.base_twist = after_.base_twist = trial_.base_twist = KDL::Twist::Zero();
  }
  int rc = solver_.momentum(before_.base_twist, before_.qdot, PL_before_);
  if (rc == E_NOERROR) rc = solver_.kineticEnergy(before_.base_twist, before_.qdot, T_before_);
  if (rc == E_NOERROR) rc = contactAndCentroidTwists(before_, PL_before_, t_before_, v_g_before_);
  if (rc) refuse("the state before the impact", rc);
  PL_after_ = PL_before_;
  T_after_ = T_before_;
  t_after_ = t_before_;
  v_g_after_ = v_g_before_;
}

int FloatingSide::contactAndCentroidTwists(const FloatingVelocity& v, const Vector6d& PL_g, Vector6d& t_h,
                                           Vector6d& v_g) const {
  KDL::Twist t;
  if (const int rc = solver_.handTwist(h_, v.qdot, PL_g, t)) return rc;  // eq. 4
  // (v_g; w_g) = M_a^-1 (P_g; L_g), M_a = diag(w E, I_g) (eq. 12)
  const Eigen::LLT<Matrix3d> I_g_llt(solver_.I_g());
  if (I_g_llt.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  Vector6d c;
  c.head<3>() = PL_g.head<3>() / solver_.w();
  c.tail<3>() = I_g_llt.solve(Vector3d(PL_g.tail<3>()));
  if (!c.allFinite()) return E_NOT_FINITE;
  t_h = toEigen(t);
  v_g = c;
  return E_NOERROR;
}

int FloatingSide::applyImpulse(const Vector6d& F) {
  if (!F.allFinite()) return E_NOT_FINITE;
  // Everything after the impulse goes to trial_ and locals first: the state after changes only
  // when all of it is good.
  Vector6d PL, t_h, v_g;
  double T = 0.0;
  if (recursive_) {
    Vector6d d_base;
    if (const int rc = recursive_->velocityJump(h_, F, d_base, dqdot_)) return rc;
    trial_.qdot.data = before_.qdot.data + dqdot_.data;
    trial_.base_twist = before_.base_twist + toTwist(d_base);
    if (const int rc = solver_.momentum(trial_.base_twist, trial_.qdot, PL)) return rc;
  } else {
    Vector6d dPL;
    if (const int rc = solver_.velocityJump(h_, response_, F, dPL, dqdot_)) return rc;
    trial_.qdot.data = before_.qdot.data + dqdot_.data;
    if (response_ != Response::Grounded) {
      PL = PL_before_ + dPL;
      if (const int rc = solver_.baseTwist(PL, trial_.qdot, trial_.base_twist)) return rc;
    } else {
      trial_.base_twist = before_.base_twist;  // zero: the ground holds the base
      if (const int rc = solver_.momentum(trial_.base_twist, trial_.qdot, PL)) return rc;
    }
  }
  if (const int rc = solver_.kineticEnergy(trial_.base_twist, trial_.qdot, T)) return rc;
  if (const int rc = contactAndCentroidTwists(trial_, PL, t_h, v_g)) return rc;
  after_.base_twist = trial_.base_twist;
  after_.qdot.data = trial_.qdot.data;
  PL_after_ = PL;
  T_after_ = T;
  t_after_ = t_h;
  v_g_after_ = v_g;
  return E_NOERROR;
}

Vector6d FloatingSide::aboutOrigin(const Vector6d& PL_g) const {
  Vector6d m = PL_g;
  m.tail<3>() += r_g_.cross(PL_g.head<3>());  // L_O = L_g + r_g x P
  return m;
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
  if (const int rc = rigidBodyG(body.mass, body.I_com, r_bc_, G_))
    throw ModelError(std::string("target: inverse inertia at the contact point: ") + strError(rc));
  t_before_ = transfer(r_bc_) * body.twist;
  twist_after_ = body.twist;
}

Vector6d RigidBodySide::contactTwistAfter() const { return transfer(r_bc_) * twist_after_; }

int RigidBodySide::applyImpulse(const Vector6d& F) {
  if (!F.allFinite()) return E_NOT_FINITE;
  const Vector6d at_com = transfer(r_bc_).transpose() * F;  // wrench moved to the CoM (eq. 8)
  Vector6d twist;
  twist.head<3>() = body_.twist.head<3>() + at_com.head<3>() / body_.mass;
  twist.tail<3>() = body_.twist.tail<3>() + body_.I_com.llt().solve(Vector3d(at_com.tail<3>()));
  if (!twist.allFinite()) return E_NOT_FINITE;
  twist_after_ = twist;
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

int collide(ImpactSide& A, ImpactSide& B, const ImpactLaw& law, Impulse& impulse, ImpactFault* fault) {
  const auto failed = [fault](ImpactFault where, int rc) {
    if (fault) *fault = where;
    return rc;
  };
  Impulse result;
  if (const int rc = solveImpact(A.G(), B.G(), A.contactTwistBefore(), B.contactTwistBefore(), law, result))
    return failed(ImpactFault::Law, rc);
  if (const int rc = A.applyImpulse(result.F)) return failed(ImpactFault::SideA, rc);
  if (const int rc = B.applyImpulse(-result.F)) {
    A.applyImpulse(Vector6d::Zero());  // A back to its state before
    return failed(ImpactFault::SideB, rc);
  }
  impulse = result;
  return failed(ImpactFault::None, E_NOERROR);
}

}  // namespace kdl_space
