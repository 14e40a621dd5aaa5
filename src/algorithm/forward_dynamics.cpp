#include "kdl_space/algorithm/forward_dynamics.hpp"

#include "algorithm/mimic_coupling.hpp"
#include "algorithm/set_up.hpp"
#include "detail/multiversion.hpp"
#include "spatial/symmetric6d.hpp"

namespace kdl_space {

// Featherstone, Rigid Body Dynamics Algorithms (2008): the articulated-body algorithm (ch. 7, sec.
// 7.3, Table 7.1) with a floating base (ch. 9), in the fixed-frame form (world axes,
// every quantity about one point p_b; twists (v; w), wrenches (f; n)). The velocity-product
// accelerations are accumulated outward (a_i, the acceleration of zero joint accelerations and a
// still base) and enter the bias forces p_i = I_i a_i + V_i x* I_i V_i - f_ext; the unknowns are
// then A_i - a_i, whose recursion has no velocity term (so the inward pass needs no I^A c).
struct ForwardDynamicsSolver::BodyData {
  // The topology, beside the numbers (every pass reads it; the model's per-body records are large)
  int parent = -1, joint = -1;     ///< as Body
  bool moving = false;             ///< a movable joint whose brakes are off
  bool leads = true;               ///< its joint's coordinate's own body (false: a mimic joint's)
  double armature = 0.0;           ///< of the free system (mimic_coupling.hpp): the coordinate's, on its own body
  double qdd = 0.0;                ///< last pass: the joint's acceleration, free system
  double mass = 0.0;               ///< [kg]
  detail::Symmetric6d IA;          ///< articulated inertia I^A
  Vector6d V = Vector6d::Zero();   ///< twist
  Vector6d a = Vector6d::Zero();   ///< outward: bias acceleration a_i; last pass: A_i - a_i
  Vector6d pA = Vector6d::Zero();  ///< articulated bias force p^A
  Vector6d U = Vector6d::Zero();   ///< I^A S
  double D_inv = 0.0;              ///< 1 / (S^T I^A S + armature)
  double u = 0.0;                  ///< tau - S^T p^A
};

namespace {

/// I x of a rigid body of mass m, CoM at c relative to the reference point, inertia I_c about
/// the CoM (world axes), without forming I: (m (x_v + x_w x c); I_c x_w + c x m (x_v + x_w x c)).
inline Vector6d rigidTimes(double m, const Vector3d& c, const Matrix3d& I_c, const Vector6d& x) {
  const Vector3d P = m * (x.head<3>() + x.tail<3>().cross(c));
  Vector6d r;
  r.head<3>() = P;
  r.tail<3>() = I_c * x.tail<3>() + c.cross(P);
  return r;
}

}  // namespace

ForwardDynamicsSolver::ForwardDynamicsSolver(std::shared_ptr<const FloatingModel> model) : model_(std::move(model)) {
  if (!model_) throw ModelError("ForwardDynamicsSolver: null model");
  const std::size_t nb = model_->bodies().size();
  locked_.assign(model_->nj(), false);
  own_ = Kinematics(*model_);
  data_.resize(nb);
  for (std::size_t i = 0; i < nb; ++i) {
    const Body& b = model_->bodies()[i];
    data_[i].parent = b.parent;
    data_[i].joint = b.joint;
    data_[i].moving = b.joint >= 0;
    data_[i].mass = b.mass;
  }
  // Mimic joints: every body's joint free in the recursion, the couplings imposed after it.
  coupling_.emplace_back(*model_);
  for (std::size_t i = 1; i < nb; ++i) {
    const int j = data_[i].joint;
    data_[i].leads = j < 0 || model_->jointBody()[j] == static_cast<int>(i);
    data_[i].armature = coupling_[0].armature(static_cast<int>(i));
  }
  qddot_.setZero(model_->nj());
}

ForwardDynamicsSolver::~ForwardDynamicsSolver() = default;
ForwardDynamicsSolver::ForwardDynamicsSolver(const ForwardDynamicsSolver&) = default;
ForwardDynamicsSolver& ForwardDynamicsSolver::operator=(const ForwardDynamicsSolver&) = default;

void ForwardDynamicsSolver::setGravity(const Vector3d& g) {
  detail::checkGravity(g, "ForwardDynamicsSolver");
  gravity_ = g;
}

void ForwardDynamicsSolver::setLocked(const std::vector<bool>& locked) {
  detail::checkLocked(*model_, locked, false, "ForwardDynamicsSolver");
  locked_ = locked;  // the same size: no allocation (the Simulator changes the brakes in a run)
  for (BodyData& b : data_) b.moving = b.joint >= 0 && !locked_[b.joint];
}

int ForwardDynamicsSolver::CartToJnt(const State& state, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                                     const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration) {
  if (const int rc = forwardKinematics(*model_, state, own_)) return rc;
  return CartToJnt(own_, velocity, tau, f_ext, acceleration);
}

KDL_SPACE_MULTIVERSION int ForwardDynamicsSolver::CartToJnt(const Kinematics& kin, const FloatingVelocity& velocity,
                                                            const KDL::JntArray& tau,
                                                            const std::vector<KDL::Wrench>& f_ext,
                                                            FloatingAcceleration& acceleration) {
  const std::size_t nb = data_.size();
  const unsigned int n = model_->nj();
  if (kin.model != model_.get() || kin.R.size() != nb || velocity.qdot.rows() != n || tau.rows() != n ||
      acceleration.qddot.rows() != n || (!f_ext.empty() && f_ext.size() != nb))
    return E_SIZE_MISMATCH;
  if (!kin.valid) return E_NOT_COMPUTED;
  if (!velocity.qdot.data.allFinite() || !tau.data.allFinite() || !allFinite(velocity.base_twist)) return E_NOT_FINITE;
  if (grounded_ && toEigen(velocity.base_twist) != Vector6d::Zero()) return E_BAD_ARGUMENT;
  for (const KDL::Wrench& f : f_ext)
    if (!allFinite(f.force) || !allFinite(f.torque)) return E_NOT_FINITE;
  const Vector3d& p_b = kin.p_b;  // the reference point of every spatial quantity
  const double* qdot = velocity.qdot.data.data();

  // 1. Outward: twists, bias accelerations, rigid-body inertias and bias forces (Table 7.1's
  // first loop; the base's twist is given, its bias acceleration is zero).
  for (std::size_t i = 0; i < nb; ++i) {
    BodyData& b = data_[i];
    if (b.parent < 0) {
      b.V = toEigen(velocity.base_twist);
      b.a.setZero();
    } else {
      const BodyData& parent = data_[b.parent];
      if (b.joint >= 0) {
        const Vector6d Sqd = kin.S[i] * qdot[b.joint];
        b.V = parent.V + Sqd;
        b.a = parent.a + crossMotion(parent.V, Sqd);  // c_i = V_parent x S qdot (= V_i x S qdot)
      } else {
        b.V = parent.V;
        b.a = parent.a;
      }
    }
    if (b.mass > 0.0 || !kin.I_com[i].isZero(0.0)) {  // else a frame: no inertia (issue 28: zero mass, inertia kept)
      const Vector3d c = kin.com[i] - p_b;
      const Matrix3d& I_c = kin.I_com[i];
      b.IA.setRigidBody(b.mass, c, I_c);
      const Vector6d h = rigidTimes(b.mass, c, I_c, b.V);  // momentum I V
      const Vector3d w = b.V.tail<3>();
      b.pA = rigidTimes(b.mass, c, I_c, b.a);
      b.pA.head<3>() += w.cross(h.head<3>());  // V x* I V
      b.pA.tail<3>() += w.cross(h.tail<3>()) + b.V.head<3>().cross(h.head<3>());
    } else {
      b.IA.setZero();
      b.pA.setZero();
    }
    if (!f_ext.empty()) {
      const Vector3d f = toEigen(f_ext[i].force);
      b.pA.head<3>() -= f;
      b.pA.tail<3>() -= toEigen(f_ext[i].torque) + (kin.p[i] - p_b).cross(f);  // moment moved to p_b
    }
  }

  // 2. Inward: articulated inertias and bias forces (Table 7.1's second loop, c = 0 here). A
  // fixed or locked joint passes its body's on whole.
  for (std::size_t i = nb; i-- > 1;) {
    BodyData& b = data_[i];
    BodyData& parent = data_[b.parent];
    if (!b.moving) {
      parent.IA += b.IA;
      parent.pA += b.pA;
      continue;
    }
    const Vector6d& S = kin.S[i];
    b.U = b.IA * S;
    const double D = S.dot(b.U) + b.armature;
    if (!(D > 0.0)) return E_NOT_POSITIVE_DEFINITE;
    b.D_inv = 1.0 / D;
    b.u = (b.leads ? tau(b.joint) : 0.0) - S.dot(b.pA);  // a mimic joint's torque is its leader's (T^T tau)
    parent.IA.addMinusRank1(b.IA, b.U, b.D_inv);
    parent.pA += b.pA + b.U * (b.u * b.D_inv);
  }

  // 3. Outward: the base's acceleration I^A_0 A_0 = -p^A_0 (the floating base, ch. 9; a grounded
  // base's is that of the frame, -g), then the joints'.
  Vector6d A0;
  if (grounded_) A0 << -gravity_, Vector3d::Zero();
  else if (!data_[0].IA.solve(-data_[0].pA, A0)) return E_NOT_POSITIVE_DEFINITE;
  data_[0].a = A0;
  for (std::size_t i = 1; i < nb; ++i) {
    BodyData& b = data_[i];
    const Vector6d& a_parent = data_[b.parent].a;
    if (b.moving) {
      const double qdd = (b.u - b.U.dot(a_parent)) * b.D_inv;
      b.qdd = qdd;
      if (b.leads) qddot_(b.joint) = qdd;
      b.a = a_parent + kin.S[i] * qdd;
    } else {
      if (b.joint >= 0) qddot_(b.joint) = 0.0;  // brakes on
      b.qdd = 0.0;
      b.a = a_parent;
    }
  }

  if (coupling_[0].rows() > 0) {
    if (const int rc = couple(kin, A0)) return rc;
  }

  // Gravity: the frame's acceleration -g undone; the base origin's classical acceleration.
  A0.head<3>() += gravity_;
  const Vector3d w = toEigen(velocity.base_twist.rot), v_b = toEigen(velocity.base_twist.vel);
  Vector6d base;
  base.head<3>() = A0.head<3>() + w.cross(v_b);
  base.tail<3>() = A0.tail<3>();
  if (!base.allFinite() || !qddot_.allFinite()) return E_NOT_FINITE;
  acceleration.base = base;
  acceleration.qddot.data = qddot_;
  return E_NOERROR;
}

}  // namespace kdl_space

namespace kdl_space {

// Mimic joints (algorithm/mimic_coupling.hpp): the free system's accelerations less the
// couplings' share, a = a_free - M^-1 C^T S^-1 C a_free, from k more passes at zero velocity on
// the articulated inertias of this state.
int ForwardDynamicsSolver::couple(const Kinematics& kin, Vector6d& A0) {
  detail::MimicCoupling& c = coupling_[0];
  const int rc = c.compute([&](int i) { return data_[i].parent; }, [&](int i) { return data_[i].moving; },
                           [&](int i) -> const Vector6d& { return kin.S[i]; },
                           [&](int i) -> const Vector6d& { return data_[i].U; },
                           [&](int i) { return data_[i].D_inv; },
                           [&](const auto& P0, auto A0) {  // 6 x k blocks
                             if (grounded_) {
                               A0.setZero();
                               return true;
                             }
                             for (Eigen::Index c = 0; c < P0.cols(); ++c) {
                               Vector6d a;
                               if (!data_[0].IA.solve(-Vector6d(P0.col(c)), a)) return false;
                               A0.col(c) = a;
                             }
                             return true;
                           });
  if (rc != E_NOERROR) return rc;
  c.solve([&](int i) { return data_[i].qdd; });
  A0 -= c.baseShare();
  const std::vector<int>& own = model_->jointBody();
  for (unsigned int j = 0; j < model_->nj(); ++j) qddot_(j) -= c.qddShare(own[j]);
  return E_NOERROR;
}

}  // namespace kdl_space
