// Free-floating forward dynamics: base and joint accelerations from the state, joint torques and
// external wrenches, with the velocity-product terms (the paper's c* and the base's own) and an
// optional gravity. KDL has no floating-base forward dynamics: this is a recursive Newton-Euler
// pass over the KDL tree for the bias, and the composite-rigid-body inertia of
// FreeFloatingSolver for the mass matrix.
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/free_floating_solver.hpp"

namespace kdl_space {

/// Generalized acceleration of a free-floating system, world frame.
struct FloatingAcceleration {
  Vector6d base = Vector6d::Zero();  ///< (acceleration of the base frame's origin; angular acceleration)
  KDL::JntArray qddot;               ///< joint accelerations, model order
};

/// \brief Forward dynamics of a FloatingModel:
/// `[[M_a, A_m], [A_m^T, H]] [a_g; qddot] = [-c_0; tau - c_q]`, everything about the system's
/// CoM at this instant (a fixed point): a_g is the base's spatial acceleration there, c = (c_0;
/// c_q) the bias from a Newton-Euler pass with zero accelerations (velocity products, gravity,
/// external wrenches). Locked joints (brakes on) are held: their qddot is 0 and their torque is
/// whatever holds them. Workspaces are sized in the constructor.
class ForwardDynamicsSolver {
 public:
  explicit ForwardDynamicsSolver(std::shared_ptr<const FloatingModel> model);

  const FloatingModel& model() const { return kinematics_.model(); }
  /// Gravity acceleration (world frame); zero by default (orbit). For ground test beds.
  /// \return 0, or E_NOT_FINITE (and the gravity unchanged) for a NaN or infinite g.
  int setGravity(const Vector3d& g) {
    if (!g.allFinite()) return E_NOT_FINITE;
    gravity_ = g;
    return E_NOERROR;
  }
  const Vector3d& gravity() const { return gravity_; }
  /// Joints whose brakes are on (model order, size nj()). \return E_SIZE_MISMATCH or 0.
  int setLocked(const std::vector<bool>& locked);
  const std::vector<bool>& locked() const { return locked_; }

  /// \brief Accelerations from state, velocity, joint torques tau (model order) and external
  /// wrenches f_ext (one per body in model().bodies() order, world axes, moment about the body
  /// frame's origin; empty for none).
  /// \return 0, E_SIZE_MISMATCH (qdot, tau, acceleration.qddot, a non-empty f_ext of another
  /// size than bodies()), E_NOT_FINITE (an input, or accelerations that overflow) or
  /// E_NOT_POSITIVE_DEFINITE; `acceleration` is untouched on an error.
  int CartToJnt(const State& state, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);

  /// The kinematic solver at the state of the last CartToJnt (centroid terms, G*, momentum...).
  FreeFloatingSolver& kinematics() { return kinematics_; }
  /// Bias (c_0 at the CoM; c_q) of the last CartToJnt: the generalized force that gives zero
  /// acceleration. Size 6 + nj().
  const Eigen::VectorXd& bias() const { return c_; }

 private:
  FreeFloatingSolver kinematics_;
  Vector3d gravity_ = Vector3d::Zero();
  std::vector<bool> locked_;
  std::vector<Vector6d> V_, A_, F_;  ///< per body: twist, spatial acceleration, force, at r_g
  Eigen::VectorXd c_, rhs_;
  Eigen::MatrixXd M_;
  Eigen::LLT<Eigen::MatrixXd> M_llt_;
};

}  // namespace kdl_space
