// The composite-rigid-body route of free-floating forward dynamics: the tests' (and the
// benchmark's) second route beside the library's articulated-body algorithm. It is the dense
// route the library used before (docs/DYNAMICS.md, "The second route"): about the system's CoM
// r_g at this instant,
//   [[M_a, A_m], [A_m^T, H]] [a_g; qddot] = [-c_0; tau - c_q],
// M_a, A_m, H from FreeFloatingSolver (a composite-rigid-body pass, eq. 12 and the fixed-base
// H), c = (c_0; c_q) the bias of a recursive Newton-Euler pass with zero accelerations (velocity
// products, gravity as an acceleration -g of the frame, external wrenches), and the (6+n)^2
// system solved by a Cholesky factorisation; locked joints: rows and columns replaced by the
// identity, qddot = 0. It shares only FreeFloatingSolver (and through it forwardKinematics) with
// the articulated-body route.
//
// CrbSimulator: the Simulator's integration loop (same state, tableau, error norm and step
// control) on this route, as the library ran it before: per derivative, FreeFloatingSolver's
// compute and baseTwist for the base twist, then CrbForwardDynamics (which computes again).
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/forward_dynamics.hpp"
#include "kdl_space/free_floating_solver.hpp"
#include "kdl_space/simulation.hpp"

namespace kdl_space::test {

/// Dense forward dynamics; the same contract and codes as ForwardDynamicsSolver::CartToJnt(State).
class CrbForwardDynamics {
 public:
  explicit CrbForwardDynamics(std::shared_ptr<const FloatingModel> model);

  const FloatingModel& model() const { return kinematics_.model(); }
  int setGravity(const Vector3d& g);
  int setLocked(const std::vector<bool>& locked);
  int CartToJnt(const State& state, const FloatingVelocity& velocity, const KDL::JntArray& tau,
                const std::vector<KDL::Wrench>& f_ext, FloatingAcceleration& acceleration);
  /// The dense solver at the state of the last CartToJnt.
  FreeFloatingSolver& kinematics() { return kinematics_; }
  /// Bias (c_0 at the CoM; c_q) of the last CartToJnt. Size 6 + nj().
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

/// \brief Simulator::run's loop on the dense route (free, locked and PD joints; no callback, no
/// observer, no brakes): for the benchmark and for a cross-check of the Simulator.
class CrbSimulator {
 public:
  CrbSimulator(std::shared_ptr<const FloatingModel> model, SimulationOptions options = {});
  void setJointControl(unsigned int joint, const JointControl& control);
  /// Integrates s from s.t to t_end. \return 0 or an Error code, as Simulator::run.
  int run(SimulationState& s, double t_end);
  const SimulationStats& stats() const { return stats_; }

 private:
  using Vector = Eigen::VectorXd;
  int unpack(const Vector& x, double t, SimulationState& s);
  int derivative(double t, const Vector& x, Vector& dx);
  int stepRK4(double t, double h, Vector& x);
  int stepDP54(double t, double h, Vector& x, double& error);

  CrbForwardDynamics dynamics_;
  SimulationOptions options_;
  std::vector<JointControl> controls_;
  SimulationStats stats_;
  SimulationState scratch_;
  KDL::JntArray tau_;
  FloatingAcceleration acc_;
  std::vector<Vector> k_;
  Vector x_, x_tmp_, x_new_;
};

}  // namespace kdl_space::test
