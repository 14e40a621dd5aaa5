// What forward_dynamics.cpp, simulation.cpp and simulation_result.cpp share: a joint or a link
// given by name or index, a set of locked joints, a run's samples and its result.
#pragma once

#include <vector>

#include "conversions.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space::python {

struct PyStats {
  SimulationStats stats;
  std::vector<std::string> joint_names;
};

struct PyStiffness {
  Stiffness s;
  std::vector<std::string> joint_names;
};

/// The samples of a run, field by field, row after row.
struct Samples {
  long k = 0;
  std::vector<double> t, p, quat, twist, q, qdot, tau, base_wrench, work, impulse, h, T;
  void add(const SimulationState& s, double energy, const Vector6d& momentum) {
    const auto put = [](std::vector<double>& v, const auto& x) { v.insert(v.end(), x.data(), x.data() + x.size()); };
    ++k;
    t.push_back(s.t);
    put(p, toEigen(s.state.world_T_base.p));
    Eigen::Vector4d xyzw;
    s.state.world_T_base.M.GetQuaternion(xyzw(0), xyzw(1), xyzw(2), xyzw(3));
    put(quat, xyzw);
    put(twist, toEigen(s.velocity.base_twist));
    put(q, s.state.q.data);
    put(qdot, s.velocity.qdot.data);
    put(tau, s.tau.data);
    put(base_wrench, s.base_wrench);
    const EnergySplit& w = s.work;
    put(work, (Vector6d() << w.controller, w.friction, w.limits, w.base_control, w.wrenches, w.gravity).finished());
    put(impulse, s.impulse);
    put(h, momentum);
    T.push_back(energy);
  }
};

struct PyRun {
  std::vector<std::string> joint_names;
  py::array_t<double> t, base_position, base_quaternion, base_twist, q, qdot, tau, base_wrench, momentum, energy, impulse;
  py::dict work;
  PyState final_state;
  PyStats stats;
  PyRun(const Samples& x, const PyState& final, const PyStats& st);
};

/// A joint by name (ModelError naming an unknown one) or index (IndexError out of range).
unsigned int jointArgument(const FloatingModel& model, py::handle obj, const char* name);
/// A link (body) by name or index, as jointArgument.
unsigned int bodyArgument(const FloatingModel& model, py::handle obj, const char* name);
/// None (no joint), joint names or indices, or nj booleans.
std::vector<bool> lockedJoints(const FloatingModel& model, py::handle obj);

/// Integrator, JointRecord, SimulationStats, Stiffness, SimulationResult (simulation_result.cpp).
void bindSimulationResults(py::module_& m);

}  // namespace kdl_space::python
