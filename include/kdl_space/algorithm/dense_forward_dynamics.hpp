// Free-floating forward dynamics by the composite-rigid-body route: the dense (6+n)^2 system of
// the paper's quantities. The route for models whose joints are coupled (mimic joints), which
// the articulated-body recursion (forward_dynamics.hpp) cannot carry; the tests' second route
// for every model.
#pragma once

#include <Eigen/Cholesky>
#include <memory>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"

namespace kdl_space {

/// \brief About the system's CoM r_g at this instant,
///   [[M_a, A_m], [A_m^T, H]] [a_g; qddot] = [-c_0; tau - c_q]   (eq. 2, 12 and the fixed-base H),
/// M_a, A_m, H from FreeFloatingSolver (coupled coordinates: J T, T^T H T), c = (c_0; c_q) the
/// bias of a recursive Newton-Euler pass with zero accelerations (velocity products, gravity as
/// an acceleration -g of the frame, external wrenches), solved by a Cholesky factorisation.
/// Locked joints: their rows and columns replaced by the identity, qddot = 0. The same contract
/// and codes as ForwardDynamicsSolver; O(n^2) to build, O(n^3) to solve. Allocation-free after
/// construction; never throws from CartToJnt.
class KDL_SPACE_EXPORT DenseForwardDynamicsSolver {
 public:
  explicit DenseForwardDynamicsSolver(std::shared_ptr<const FloatingModel> model);

  const FloatingModel& model() const { return solver_.model(); }
  /// As ForwardDynamicsSolver::setGravity and setLocked: set-up calls, \throws ModelError.
  void setGravity(const Vector3d& g);
  void setLocked(const std::vector<bool>& locked);
  /// A grounded base: the base rows and columns replaced by the identity, its acceleration zero
  /// (as ForwardDynamicsSolver::setGrounded).
  void setGrounded(bool grounded) { grounded_ = grounded; }
  int CartToJnt(const Kinematics& kin, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);
  int CartToJnt(const State& state, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);
  /// The dense solver at the state of the last CartToJnt.
  FreeFloatingSolver& kinematics() { return solver_; }
  /// Bias (c_0 at the CoM; c_q) of the last CartToJnt. Size 6 + nj().
  const Eigen::VectorXd& bias() const { return c_; }

 private:
  int solve(const Vector3d& p_b, const FloatingVelocity& velocity, const KDL::JntArray& tau,
            const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);

  FreeFloatingSolver solver_;
  Vector3d gravity_ = Vector3d::Zero();
  std::vector<bool> locked_;
  bool grounded_ = false;
  std::vector<Vector6d> V_, A_, F_;  ///< per body: twist, spatial acceleration, force, at r_g
  Eigen::VectorXd c_, rhs_;
  Eigen::MatrixXd M_;
  Eigen::LLT<Eigen::MatrixXd> M_llt_;
};

/// The class's name before it was the Python module's (DenseForwardDynamicsSolver), kept for one
/// release. Deprecated: use DenseForwardDynamicsSolver.
using DenseForwardDynamics [[deprecated("use DenseForwardDynamicsSolver")]] = DenseForwardDynamicsSolver;

}  // namespace kdl_space
