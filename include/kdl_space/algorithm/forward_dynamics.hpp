// Free-floating forward dynamics: base and joint accelerations from the state, joint torques and
// external wrenches, with the velocity-product terms (the paper's c* and the base's own) and an
// optional gravity, in O(n): Featherstone's articulated-body algorithm with a floating base
// (Rigid Body Dynamics Algorithms, 2008, ch. 7 and 9), reading the one forward-kinematics
// pass (kinematics.hpp). KDL has no floating-base forward dynamics. The composite-rigid-body
// route (M_full solved densely) is the tests' second route (docs/DYNAMICS.md).
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space {
namespace detail {
class MimicCoupling;  // src/algorithm/mimic_coupling.hpp: mimic joints as constraints
}

/// Generalized acceleration of a free-floating system, world frame.
struct FloatingAcceleration {
  Vector6d base = Vector6d::Zero();  ///< (acceleration of the base frame's origin; angular acceleration)
  KDL::JntArray qddot;               ///< joint accelerations, model order
};

/// \brief Forward dynamics of a FloatingModel by the articulated-body algorithm with a floating
/// base, every quantity in world axes about the base frame's origin p_b (a point fixed in the
/// world for the instant):
///  1. outward: body twists V_i = V_parent + S_i qdot_i, the bias accelerations of zero joint
///     accelerations a_i = a_parent + V_i x S_i qdot_i, and the bias forces
///     p_i = I_i a_i + V_i x* I_i V_i - f_ext,i;
///  2. inward: articulated inertias I^A_i = I_i + sum_children (I^A_c - U_c D_c^-1 U_c^T) and bias
///     forces p^A_i = p_i + sum_children (p^A_c + U_c D_c^-1 u_c), with U = I^A S,
///     D = S^T U + armature, u = tau - S^T p^A;
///  3. outward: the base's spatial acceleration A_0 = -(I^A_0)^-1 p^A_0, then
///     qddot_i = D_i^-1 (u_i - U_i^T A_parent), A_i = A_parent + S_i qddot_i;
/// gravity g as an acceleration -g of the frame (the base's is A_0 + (g; 0)); the base's classical
/// acceleration follows, p_b'' = A_0,v + w x v_b.
/// Locked joints (brakes on) are fixed joints in steps 2 and 3 (qddot = 0; their torque is
/// whatever holds them); a locked joint that still moves keeps its velocity product in step 1.
/// Mimic joints: every joint free in the recursion, then a = a_free - M^-1 C^T S^-1 C a_free from k
/// more passes on the same articulated inertias (src/algorithm/mimic_coupling.hpp; O(n k + k^3); its
/// being allocation-free is not yet proved by tests/alloc for such a model).
/// Workspaces are sized in the constructor; CartToJnt allocates nothing and never throws.
class KDL_SPACE_EXPORT ForwardDynamicsSolver {
 public:
  explicit ForwardDynamicsSolver(std::shared_ptr<const FloatingModel> model);
  ~ForwardDynamicsSolver();
  ForwardDynamicsSolver(const ForwardDynamicsSolver&);
  ForwardDynamicsSolver& operator=(const ForwardDynamicsSolver&);

  const FloatingModel& model() const { return *model_; }
  /// Gravity acceleration (world frame); zero by default (orbit). For ground test beds. A set-up
  /// call: \throws ModelError (naming the value; the gravity unchanged) for a NaN or infinite g.
  void setGravity(const Vector3d& g);
  const Vector3d& gravity() const { return gravity_; }
  /// Joints whose brakes are on (model order, size nj()). A set-up call: \throws ModelError
  /// (naming the model's joints; the locks unchanged) for another size. Allocation-free, so the
  /// Simulator changes the brakes with it during a run (always of the right size there).
  void setLocked(const std::vector<bool>& locked);
  const std::vector<bool>& locked() const { return locked_; }
  /// \brief A grounded base (held still, as on a test bed or a fixed-base arm): its acceleration
  /// is zero and the joints follow the fixed-base dynamics H qddot = tau - c (eq. 22's H). The
  /// base twist given to CartToJnt must then be zero (else E_BAD_ARGUMENT).
  void setGrounded(bool grounded) { grounded_ = grounded; }
  bool grounded() const { return grounded_; }

  /// \brief Accelerations at the state of `kin` (forwardKinematics of this model) from the
  /// velocity, joint torques tau (model order) and external wrenches f_ext (one per body in
  /// model().bodies() order, world axes, moment about the body frame's origin; empty for none).
  /// No reference to `kin` is kept.
  /// \return 0, E_SIZE_MISMATCH (kin of another model, qdot, tau, acceleration.qddot, a non-empty
  /// f_ext of another size than bodies()), E_NOT_COMPUTED (kin not valid), E_NOT_FINITE (an
  /// input, or accelerations that overflow), E_NOT_POSITIVE_DEFINITE (an articulated inertia
  /// that is not) or E_BAD_ARGUMENT (a grounded base given a twist); `acceleration` is untouched
  /// on an error.
  int CartToJnt(const Kinematics& kin, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);
  /// \brief The same from a state: forwardKinematics into the solver's own Kinematics, then the
  /// above. \return also E_SIZE_MISMATCH (state.q) and E_NOT_FINITE (a non-finite state).
  int CartToJnt(const State& state, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);

 private:
  /// Per body: its parent, joint and mass, and the articulated-body recursion's data (world
  /// axes, about p_b).
  struct BodyData;

  std::shared_ptr<const FloatingModel> model_;
  Vector3d gravity_ = Vector3d::Zero();
  std::vector<bool> locked_;
  bool grounded_ = false;
  Kinematics own_;                 ///< for CartToJnt(State) only
  std::vector<BodyData> data_;     ///< per body
  Eigen::VectorXd qddot_;          ///< joint accelerations before they are returned (n)
  /// Mimic joints as constraints on the recursion (src/algorithm/mimic_coupling.hpp; one element,
  /// with no rows for a model without mimic joints).
  std::vector<detail::MimicCoupling> coupling_;
  /// The couplings' share taken from qddot_ and the base's acceleration A0 (mimic joints).
  int couple(const Kinematics& kin, Vector6d& A0);
};

}  // namespace kdl_space
