// What forward_dynamics.cpp, simulation.cpp and simulation_result.cpp share: a joint or a link
// given by name or index, a set of locked joints, a run's samples and its result.
#pragma once

#include <chrono>
#include <memory>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "conversions.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space::python {

/// \brief Ctrl-C in a run that holds no GIL (Simulator::setCancelPoll, OperationOptions::cancelled):
/// about every 50 ms of the run it takes the GIL and lets Python handle a pending signal, so that
/// a KeyboardInterrupt (or what a handler raises) ends the run there, however rare its output
/// samples. By time rather than by steps: a step takes 1 us on a small arm, milliseconds on a
/// large one with the Rosenbrock method. Between: a counter, and the clock every 8th call.
class SignalPoll {
 public:
  bool operator()() {
    if (++calls_ % 8 != 0) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(50)) return false;
    last_ = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    return false;
  }

 private:
  unsigned calls_ = 0;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// \brief SignalPoll for a search that stops on `true` and keeps its best so far (planCapture's
/// PlanOptions::cancelled, whose optimiser would swallow an exception): a pending signal's error
/// (KeyboardInterrupt) stays set, and the caller raises it once the call returns, holding the GIL
/// (`if (poll.raised()) throw py::error_already_set();`). Copies share the flag.
class SignalFlag {
 public:
  bool operator()() {
    if (*raised_) return true;
    if (++calls_ % 8 != 0) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(50)) return false;
    last_ = now;
    py::gil_scoped_acquire gil;
    *raised_ = PyErr_CheckSignals() != 0;
    return *raised_;
  }
  bool raised() const { return *raised_; }

 private:
  std::shared_ptr<bool> raised_ = std::make_shared<bool>(false);
  unsigned calls_ = 0;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// \brief Refuses (ValueError) a run whose `rows` samples, each kept in memory, would exceed
/// `limit` (the keyword max_output_rows), saying what to change.
inline void checkOutputRows(const char* call, double rows, std::uint64_t limit, const std::string& step_name) {
  if (!(rows > static_cast<double>(limit))) return;
  std::ostringstream why;
  why << call << ": the run would keep up to ";
  if (rows < 1e18) why << static_cast<unsigned long long>(rows); else why << rows;
  why << " samples in memory, more than max_output_rows = " << limit << ": give a coarser " << step_name
      << ", a shorter duration, or raise max_output_rows";
  throw py::value_error(why.str());
}

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
  py::list warnings;  ///< {kind, element, message}: a sampled controller's gains (sampledGainWarnings)
  PyRun(const Samples& x, const PyState& final, const PyStats& st);
};

/// A joint by name (ModelError naming an unknown one) or index (IndexError out of range).
unsigned int jointArgument(const FloatingModel& model, py::handle obj, const char* name);
/// A link (body) by name or index, as jointArgument.
unsigned int bodyArgument(const FloatingModel& model, py::handle obj, const char* name);
/// None (no joint), joint names or indices, or nj booleans.
std::vector<bool> lockedJoints(const FloatingModel& model, py::handle obj);

/// The warnings of a run as a list of {kind, element, message}, each also issued as a Python
/// RuntimeWarning (on stderr unless the caller filters it; an error if warnings are errors).
py::list reportWarnings(const std::vector<Diagnostic>& warnings);

/// Integrator, JointRecord, SimulationStats, Stiffness, SimulationResult (simulation_result.cpp).
void bindSimulationResults(py::module_& m);

}  // namespace kdl_space::python
