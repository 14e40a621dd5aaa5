// The composite-rigid-body route of free-floating forward dynamics, the tests' (and the
// benchmark's) second route beside the library's articulated-body algorithm: the library's
// DenseForwardDynamicsSolver (include/kdl_space/algorithm/dense_forward_dynamics.hpp; the route the simulation
// takes for coupled joints), which shares only FreeFloatingSolver (and through it
// forwardKinematics) with the articulated-body route.
//
// CrbSimulator: the Simulator's integration loop (same state, tableau, error norm and step
// control) on this route, as the library ran it before: per derivative, FreeFloatingSolver's
// compute and baseTwist for the base twist, then the dense forward dynamics (which computes again).
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space::test {

/// The dense route, the library's (DenseForwardDynamicsSolver): the tests' second route beside the
/// articulated-body algorithm.
using CrbForwardDynamics = DenseForwardDynamicsSolver;

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
