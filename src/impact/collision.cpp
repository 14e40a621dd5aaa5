#include "kdl_space/impact/collision.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "multibody/mimic_route.hpp"
#include "spatial/message_text.hpp"
#include "multibody/model_rules.hpp"

namespace kdl_space {

namespace {
[[noreturn]] void refuse(const std::string& what) { throw ModelError("FloatingSide: " + what); }
[[noreturn]] void refuse(const std::string& what, int rc) { refuse(what + ": " + strError(rc)); }

std::shared_ptr<const FloatingModel> checkedModel(std::shared_ptr<const FloatingModel> model) {
  if (!model) refuse("null model");
  return model;
}

/// The kinematics of `state`, or a ModelError naming the state.
Kinematics kinematicsAt(const FloatingModel* model, const State& state) {
  if (!model) refuse("null model");
  Kinematics kin(*model);
  if (const int rc = forwardKinematics(*model, state, kin)) refuse("the state", rc);
  return kin;
}
}  // namespace

FloatingSide::FloatingSide(const FloatingSystem& s, ExIITMethod method)
    : FloatingSide(s.model, s.state, s.contact, s.velocity, s.response, method, s.locked) {}

FloatingSide::~FloatingSide() = default;

FloatingSide::FloatingSide(std::shared_ptr<const FloatingModel> model, const State& state, const Contact& h,
                           const FloatingVelocity& before, Response response, ExIITMethod method,
                           std::vector<bool> locked)
    : FloatingSide(model, kinematicsAt(model.get(), state), h, before, response, method, std::move(locked)) {}

FloatingSide::FloatingSide(std::shared_ptr<const FloatingModel> model, Kinematics kin, const Contact& h,
                           const FloatingVelocity& before, Response response, ExIITMethod method,
                           std::vector<bool> locked)
    : model_(checkedModel(std::move(model))),
      kin_(std::move(kin)),
      momentum_(model_),
      h_(h),
      response_(response),
      locked_(std::move(locked)),
      before_(before),
      after_(before),
      dqdot_(model_->nj()),
      trial_(before) {
  const unsigned int n = model_->nj();
  if (before.qdot.rows() != n)
    refuse(std::to_string(before.qdot.rows()) + " joint rates given for the model's " + std::to_string(n) + " joints");
  if (!before.qdot.data.allFinite() || !allFinite(before.base_twist))
    refuse("the base twist or a joint rate is NaN or infinite");
  if (locked_.empty()) locked_.assign(n, false);
  if (locked_.size() != n)
    refuse(std::to_string(locked_.size()) + " joint brakes given for the model's " + std::to_string(n) + " joints");
  for (unsigned int j = 0; j < n; ++j)
    if (locked_[j] && before.qdot(j) != 0.0)
      refuse("joint " + detail::quoted(model_->jointNames()[j]) + " is braked but its rate before the impact is " +
             detail::number(before.qdot(j)) + ", not 0 (a braked joint does not move)");
  if (response_ != Response::FreeFloating && response_ != Response::Grounded && response_ != Response::JointsLocked)
    refuse("the response is not one of FreeFloating, Grounded, JointsLocked");
  if (method != ExIITMethod::Recursive && method != ExIITMethod::Dense)
    refuse("the method is not one of Recursive, Dense");
  if (const int rc = contactCode(true, h_, model_->bodies().size())) refuse("contact point", rc);
  if (kin_.model != model_.get() || kin_.R.size() != model_->bodies().size()) refuse("the kinematics", E_SIZE_MISMATCH);
  if (!kin_.valid) refuse("the kinematics", E_NOT_COMPUTED);
  if (response_ == Response::JointsLocked) {
    // eq. 20: no recursion
  } else if (method == ExIITMethod::Recursive &&
             detail::mimicGStarTakesRecursion(model_->nj(), model_->mimic().size())) {
    // Mimic joints: the recursion with the couplings as constraints (O(n k + k^3)) where it was
    // measured faster for G* than the dense route, i.e. few of them (4 k <= n: two grippers on a
    // long body); else the dense route (a hand, k growing with n: docs/benchmarks.md, "Mimic joints").
    recursive_ = std::make_unique<RecursiveExIITSolver>(model_);
    recursive_->setLocked(locked_);  // sizes checked above
  } else {
    dense_ = std::make_unique<FreeFloatingSolver>(model_);
    dense_->setLocked(locked_);
  }
  const char* stage = "";
  if (const int rc = prepare(stage)) refuse(stage, rc);
}

int FloatingSide::reset(const State& state, const FloatingVelocity& before) {
  ready_ = false;
  if (before.qdot.rows() != model_->nj()) return E_SIZE_MISMATCH;
  if (!before.qdot.data.allFinite() || !allFinite(before.base_twist)) return E_NOT_FINITE;
  for (unsigned int j = 0; j < model_->nj(); ++j)
    if (locked_[j] && before.qdot(j) != 0.0) return E_BAD_ARGUMENT;  // a braked joint does not move
  if (const int rc = forwardKinematics(*model_, state, kin_)) return rc;
  before_.base_twist = before.base_twist;
  before_.qdot.data = before.qdot.data;  // sizes checked: no allocation
  const char* stage = "";
  return prepare(stage);
}

int FloatingSide::prepare(const char*& stage) {
  ready_ = false;
  // The grounded base does not move, whatever twist was given.
  if (response_ == Response::Grounded) before_.base_twist = KDL::Twist::Zero();
  after_.base_twist = trial_.base_twist = before_.base_twist;
  after_.qdot.data = trial_.qdot.data = before_.qdot.data;
  stage = "the state before the impact";
  if (const int rc = momentum_.compute(kin_, before_)) return rc;
  stage = response_ == Response::Grounded       ? "grounded G at the contact point"
          : response_ == Response::FreeFloating ? "G* at the contact point"
                                                : "G at the contact point";
  int rc = E_NOERROR;
  if (response_ == Response::JointsLocked) {
    rc = momentum_.G_locked(h_, G_);  // eq. 20
  } else if (recursive_) {
    rc = recursive_->compute(kin_);
    if (rc == E_NOERROR) rc = recursive_->G(h_, response_, G_);
  } else {
    rc = dense_->compute(kin_);
    if (rc == E_NOERROR) rc = dense_->G(h_, response_, G_);
  }
  if (rc) return rc;
  stage = "the state before the impact";
  if ((rc = momentum_.contactTwist(h_, t_before_))) return rc;
  I_g_llt_.compute(momentum_.I_g());
  if (I_g_llt_.info() != Eigen::Success) return E_NOT_POSITIVE_DEFINITE;
  r_gh_ = kin_.point(h_) - momentum_.r_g();
  h_before_ = h_after_ = momentum_.momentum();
  T_before_ = T_after_ = momentum_.kineticEnergy();
  v_g_before_ = v_g_after_ = momentum_.centroidTwist();
  t_after_ = t_before_;
  ready_ = true;
  return E_NOERROR;
}

int FloatingSide::applyImpulse(const Vector6d& F) {
  if (!ready_) return E_NOT_COMPUTED;
  if (!F.allFinite()) return E_NOT_FINITE;
  // Everything after the impulse goes to trial_ and locals first: the state after changes only
  // when all of it is good.
  trial_.qdot.data = before_.qdot.data;
  const Vector6d F_at_origin = shiftMomentum(F, -kin_.point(h_));  // (f; n + p_h x f)
  if (response_ == Response::JointsLocked) {
    // One rigid body: the momentum changes by the impulse (eq. 21), the joints stay still.
    if (const int rc = momentum_.baseTwist(kin_, h_before_ + F_at_origin, trial_.qdot, trial_.base_twist)) return rc;
  } else {
    const int rc = recursive_ ? recursive_->velocityJump(h_, response_, F, d_base_, dqdot_)
                              : dense_->velocityJump(h_, response_, F, d_base_, dqdot_);
    if (rc) return rc;
    trial_.qdot.data += dqdot_.data;
    if (response_ == Response::Grounded) {
      trial_.base_twist = before_.base_twist;  // zero: the ground holds the base
    } else if (recursive_) {
      trial_.base_twist = before_.base_twist + toTwist(d_base_);
    } else {
      // The dense route gives the jump of (P_g; L_g) (eq. 8): the base twist from the momentum.
      Vector6d PL_g;
      if (const int rc = dense_->momentum(before_.base_twist, before_.qdot, PL_g)) return rc;
      if (const int rc = dense_->baseTwist(PL_g + d_base_, trial_.qdot, trial_.base_twist)) return rc;
    }
  }
  // What the impulse does to the whole side. Free-floating, without another pass over the
  // bodies: the contact twist jumps by G* F (eq. 18), the impulse does the work
  // F^T (t_before + t_after) / 2 and the momentum jumps by it (eq. 8). A grounded base (the
  // ground takes a share of the momentum) and braked joints that keep their rates (not a passive
  // response: the energy is not the impulse's work) are measured from the velocities after.
  Vector6d t_h, h_O, v_g;
  double T = 0.0;
  if (response_ != Response::FreeFloating) {
    if (const int rc = momentum_.compute(kin_, trial_)) return rc;
    if (const int rc = momentum_.contactTwist(h_, t_h)) return rc;
    T = momentum_.kineticEnergy();
    h_O = momentum_.momentum();
    v_g = momentum_.centroidTwist();
  } else {
    t_h = t_before_ + G_ * F;
    T = T_before_ + 0.5 * F.dot(t_before_ + t_h);
    h_O = h_before_ + F_at_origin;
    v_g = v_g_before_;
    v_g.head<3>() += F.head<3>() / model_->totalMass();                                  // eq. 12
    v_g.tail<3>() += I_g_llt_.solve(Vector3d(F.tail<3>() + r_gh_.cross(Vector3d(F.head<3>()))));  // R_h^T F
  }
  if (!t_h.allFinite() || !std::isfinite(T) || !h_O.allFinite() || !v_g.allFinite()) return E_NOT_FINITE;
  after_.base_twist = trial_.base_twist;
  after_.qdot.data = trial_.qdot.data;
  h_after_ = h_O;
  T_after_ = T;
  t_after_ = t_h;
  v_g_after_ = v_g;
  return E_NOERROR;
}

RigidBodySide::RigidBodySide(const RigidBody& body, const Vector3d& contact_point)
    : body_(body), r_bc_(contact_point - body.com) {
  if (!(body.mass > 0.0) || !std::isfinite(body.mass)) throw ModelError("target: mass must be a finite value > 0");
  if (!body.I_com.allFinite() || !body.com.allFinite() || !body.twist.allFinite() || !contact_point.allFinite())
    throw ModelError("target: inertia, CoM, twist and contact point must be finite");
  const rules::InertiaVerdict verdict = rules::judgeInertia(body.I_com);
  if (!verdict.symmetric || verdict.kind == rules::InertiaVerdict::NotPositiveDefinite)
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
  Vector6d m;  // (P; L about the CoM), then L about the origin: L_O = L_c + c x P
  m << body_.mass * twist.head<3>(), body_.I_com * twist.tail<3>();
  return shiftMomentum(m, -body_.com);
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
