// kdl_space.Simulator (simulation.hpp, actuation.hpp): the options as keyword arguments, joint and
// base controls, scheduled wrenches, and run(): the samples as NumPy arrays, with a Python
// controller called at a control rate (zero-order hold) or at every derivative evaluation.
//
// The zero-order hold is the library's (runSampled, simulation/sampled_control.hpp); here only the
// Python controller's call and its conversions.
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <thread>

#include "capture_types.hpp"
#include "conversions.hpp"
#include "kdl_space/simulation/sampled_control.hpp"
#include "simulation_types.hpp"

namespace kdl_space::python {
namespace {

Integrator integratorOf(py::handle obj) {
  if (!py::isinstance<py::str>(obj)) return py::cast<Integrator>(obj);
  try {
    return integratorFromName(py::cast<std::string>(obj));
  } catch (const InputError& e) {
    throw py::value_error(std::string("integrator: ") + e.what());  // a bad argument of this call
  }
}

const char* modeName(const JointControl& c) {
  switch (c.mode) {
    case JointControl::Mode::Free: return "free";
    case JointControl::Mode::Locked: return "locked";
    case JointControl::Mode::PD: return c.hold ? "hold" : "pd";
  }
  return "?";
}

const char* limitName(LimitMode m) { return m == LimitMode::Ignore ? "ignore" : m == LimitMode::Warn ? "warn" : "stop"; }

struct PySimulator {
  PySimulator(const Model& m, const SimulationOptions& o) : model(m), sim(std::make_unique<Simulator>(m.ptr, o)) {}
  PySimulator(const Model& m, std::unique_ptr<Simulator> s) : model(m), sim(std::move(s)) {}
  Model model;
  std::unique_ptr<Simulator> sim;
  std::mutex mutex;
  std::atomic<std::thread::id> runner{};  ///< the thread inside run(), whose controller must not call back

  void notFromController() const {
    if (runner.load() == std::this_thread::get_id())
      throw std::runtime_error("Simulator: called from its own controller during run() (one run at a time)");
  }
  template <class F>
  auto locked(F&& f) {
    notFromController();
    return withoutGil(mutex, std::forward<F>(f));
  }
  SimulationState stateOf(const PyState& s, const char* name) const {
    if (s.model->nj() != model.ptr->nj())
      throw py::value_error(std::string(name) + ": a state of another model (" + std::to_string(s.model->nj()) +
                            " joints, this one has " + std::to_string(model.ptr->nj()) + ")");
    SimulationState x;
    x.state = s.state;
    x.velocity = s.velocity;
    return x;
  }
};

[[noreturn]] void raiseRunError(int rc, const SimulationState& s, double t0, double t_end, py::object partial) {
  std::ostringstream what;
  what << "Simulator.run: " << strError(rc) << " at t = " << s.t << " s (the run was from " << t0 << " to " << t_end
       << " s)";
  const py::object type = py::module_::import("kdl_space._kdl_space").attr("ComputeError");
  py::object e = type(what.str());
  e.attr("code") = rc;
  e.attr("t") = s.t;
  e.attr("result") = partial;
  PyErr_SetObject(type.ptr(), e.ptr());
  throw py::error_already_set();
}

PyRun run(PySimulator& w, const PyState& start, double t_end, double output_dt, py::object controller,
          py::object control_rate, double t0, std::uint64_t max_output_rows, bool check_gains) {
  w.notFromController();
  const FloatingModel& model = *w.model.ptr;
  SimulationState s = w.stateOf(start, "state");
  s.t = t0;
  // Every sample is kept: its count (t0, every output_dt, t_end) is checked first (a span or a
  // step the run refuses with its code is left to it).
  if (std::isfinite(t_end) && std::isfinite(t0) && output_dt > 0.0 && t_end >= t0)
    checkOutputRows("Simulator.run", std::ceil((t_end - t0) / output_dt * (1.0 - 1e-12)) + 1.0, max_output_rows,
                    "output_dt");
  if (!controller.is_none() && !PyCallable_Check(controller.ptr()))
    throw py::type_error("controller: expected a callable controller(t, q, qdot, base_pose, base_twist) -> tau");
  if (controller.is_none() && !control_rate.is_none()) throw py::value_error("control_rate: given without a controller");
  double rate = 0.0;  // 0: the controller at every evaluation
  if (!control_rate.is_none()) {
    rate = py::cast<double>(control_rate);
    if (!(rate > 0.0) || !std::isfinite(rate))
      throw py::value_error("control_rate: expected a finite rate > 0 [Hz], got " + std::to_string(rate));
    try {
      controlGrid(output_dt, 1.0 / rate);
    } catch (const InputError& e) {
      throw py::value_error(e.what());  // a bad argument of this call
    }
  }
  // The library's zero-order hold (runSampled) around the Python controller.
  SampledController sampled;
  if (!controller.is_none())
    sampled = [&](const SimulationState& x, Eigen::VectorXd& tau) {
      py::gil_scoped_acquire gil;
      const py::object r = controller(x.t, toNumpyVec(x.state.q.data), toNumpyVec(x.velocity.qdot.data),
                                      frameToNumpy(x.state.world_T_base), toNumpy6(toEigen(x.velocity.base_twist)));
      tau = jointValues(model, r, "controller: tau").data;
      if (!tau.allFinite())
        throw py::value_error("controller: returned a torque that is not finite at t = " + std::to_string(x.t) + " s");
    };
  Samples samples;
  int sample_rc = E_NOERROR;
  const auto observer = [&](const SimulationState& x) {
    double T = std::nan("");
    Vector6d h = Vector6d::Constant(std::nan(""));
    if (const int rc = w.sim->energyAndMomentum(x, T, h)) sample_rc = sample_rc ? sample_rc : rc;
    samples.add(x, T, h);
    py::gil_scoped_acquire gil;  // Ctrl-C ends the run at the next output sample (a KeyboardInterrupt)
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  };
  int rc = E_NOERROR;
  std::vector<Diagnostic> gain_warnings;
  {
    py::gil_scoped_release nogil;
    std::lock_guard<std::mutex> lock(w.mutex);
    struct Guard {  // whoever runs: cleared when the run ends, however it ends
      PySimulator& w;
      ~Guard() {
        w.runner = std::thread::id();
        w.sim->setCancelPoll(nullptr);
      }
    } guard{w};
    w.runner = std::this_thread::get_id();
    w.sim->setCancelPoll(SignalPoll());  // and between the samples, however rare
    // A sampled controller's rate gains, probed at the start (2 calls a joint), before it runs.
    if (check_gains) rc = sampledGainWarnings(*w.sim, s, sampled, rate, gain_warnings);
    if (rc == E_NOERROR) rc = runSampled(*w.sim, s, t_end, output_dt, sampled, rate, observer);
  }
  PyRun result(samples, PyState{w.model.ptr, s.state, s.velocity}, PyStats{w.sim->stats(), model.jointNames()});
  result.warnings = reportWarnings(gain_warnings);
  if (rc || sample_rc) raiseRunError(rc ? rc : sample_rc, s, t0, t_end, py::cast(result));
  return result;
}

std::unique_ptr<PySimulator> makeSimulator(const Model& model, py::object integrator, double step, double rtol, double atol,
                                           double max_step, long max_steps, py::object gravity, bool grounded,
                                           bool effort_limits, bool joint_friction, double friction_velocity,
                                           double friction_rate) {
  SimulationOptions o;
  o.integrator = integratorOf(integrator);
  o.step = step, o.rtol = rtol, o.atol = atol, o.max_step = max_step, o.max_steps = max_steps;
  if (!gravity.is_none()) o.gravity = vec3(gravity, "gravity");
  o.grounded = grounded, o.effort_limits = effort_limits, o.joint_friction = joint_friction;
  o.friction_velocity = friction_velocity, o.friction_rate = friction_rate;
  return std::make_unique<PySimulator>(model, o);
}

/// The simulator as `kdl_space simulate` builds it from a scenario (makeSimulator, parsers/scenario/scenario.hpp),
/// for the scenario's robot or `model`, after checking that `model` has every joint and link the scenario's
/// simulation names (makeSimulator finds them by name and would be handed none).
std::unique_ptr<PySimulator> fromScenario(const ScenarioArg& ps, py::object model_obj) {
  const Scenario& sc = ps.get();
  const FloatingSystem& robot = sc.capture.robot;
  const Model model = model_obj.is_none() ? Model{robot.model, sc.robot_urdf} : py::cast<Model>(model_obj);
  const auto need = [&](unsigned int j) {
    if (model.ptr->jointIndex(robot.model->jointNames()[j]) < 0)
      throw py::value_error("model: has no joint '" + robot.model->jointNames()[j] + "' of the scenario's robot");
  };
  const SimulationSpec& spec = sc.simulation;
  // The joints and links in makeSimulator's order (braked, controlled, limited; the wrenches' links).
  for (unsigned int j = 0; j < robot.model->nj(); ++j)
    if (robot.response == Response::JointsLocked || (!robot.locked.empty() && robot.locked[j])) need(j);
  for (const auto& jc : spec.joints) need(jc.first);
  for (const auto& jl : spec.limits) need(jl.first);
  for (const ScheduledWrench& x : spec.wrenches)
    if (model.ptr->bodyIndex(robot.model->bodies()[x.body].name) < 0)
      throw py::value_error("model: has no link '" + robot.model->bodies()[x.body].name + "' of the scenario's robot");
  try {
    return std::make_unique<PySimulator>(model, makeSimulator(sc, model.ptr, false));  // the motion after the capture
  } catch (const Error& e) {
    e.rethrowWithContext(sc.file + ": ");
  }
}

template <class T>
T item(const py::dict& d, const char* key, T fallback) {
  return d.contains(key) ? py::cast<T>(d[key]) : fallback;
}

void checkKeys(const py::dict& d, const char* name, const std::vector<std::string>& keys) {
  for (auto kv : d) {
    const std::string k = py::cast<std::string>(kv.first);
    if (std::find(keys.begin(), keys.end(), k) == keys.end())
      throw py::value_error(std::string(name) + ": unknown key '" + k + "' (kp, kd, set_point, hold, " +
                            keys.back() + ")");
  }
}

void setBaseControl(PySimulator& w, py::object attitude, py::object position) {
  BaseControl c;
  if (!attitude.is_none()) {
    const py::dict d = attitude;
    checkKeys(d, "attitude", {"kp", "kd", "set_point", "hold", "torque_limit"});
    c.attitude.on = true;
    c.attitude.kp = item(d, "kp", 0.0), c.attitude.kd = item(d, "kd", 0.0), c.attitude.hold = item(d, "hold", false);
    if (d.contains("set_point")) {
      const Matrix3d R = mat3(d["set_point"], "attitude['set_point']");
      c.attitude.set_point = KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
    }
    if (d.contains("torque_limit")) c.attitude.torque_limit = vec3(d["torque_limit"], "attitude['torque_limit']");
  }
  if (!position.is_none()) {
    const py::dict d = position;
    checkKeys(d, "position", {"kp", "kd", "set_point", "hold", "force_limit"});
    c.position.on = true;
    c.position.kp = item(d, "kp", 0.0), c.position.kd = item(d, "kd", 0.0), c.position.hold = item(d, "hold", false);
    if (d.contains("set_point")) c.position.set_point = vec3(d["set_point"], "position['set_point']");
    if (d.contains("force_limit")) c.position.force_limit = vec3(d["force_limit"], "position['force_limit']");
  }
  w.locked([&] { w.sim->setBaseControl(c); });
}

void setJointControl(PySimulator& w, py::object joint, const std::string& mode, double kp, double kd, double set_point) {
  const unsigned int j = jointArgument(*w.model.ptr, joint, "joint");
  JointControl c;
  if (mode == "free") c.mode = JointControl::Mode::Free;
  else if (mode == "locked") c.mode = JointControl::Mode::Locked;
  else if (mode == "pd" || mode == "hold") c.mode = JointControl::Mode::PD, c.hold = mode == "hold";
  else throw py::value_error("mode: expected 'free', 'locked', 'pd' or 'hold', got '" + mode + "'");
  c.kp = kp, c.kd = kd, c.set_point = set_point;
  w.locked([&] { w.sim->setJointControl(j, c); });
}

void setLimitMode(PySimulator& w, py::object joint, const std::string& mode) {
  const unsigned int j = jointArgument(*w.model.ptr, joint, "joint");
  LimitMode l;
  if (mode == "ignore") l = LimitMode::Ignore;
  else if (mode == "warn") l = LimitMode::Warn;
  else if (mode == "stop") l = LimitMode::Stop;
  else throw py::value_error("mode: expected 'ignore', 'warn' or 'stop', got '" + mode + "'");
  w.locked([&] { w.sim->setLimitMode(j, l); });
}

}  // namespace

void bindSimulation(py::module_& m) {
  bindSimulationResults(m);
  const SimulationOptions d;
  py::class_<PySimulator>(m, "Simulator",
                          "Integrates the free-floating equations of motion (momentum kept exactly with no external "
                          "force): joint controls, limits, the base's control, scheduled wrenches and a Python "
                          "controller. One thread at a time per simulator.")
      .def(py::init(&makeSimulator), py::arg("model"), py::kw_only(), py::arg("integrator") = "dopri5",
           py::arg("step") = d.step, py::arg("rtol") = d.rtol, py::arg("atol") = d.atol, py::arg("max_step") = d.max_step,
           py::arg("max_steps") = d.max_steps, py::arg("gravity") = py::none(), py::arg("grounded") = d.grounded,
           py::arg("effort_limits") = d.effort_limits, py::arg("joint_friction") = d.joint_friction,
           py::arg("friction_velocity") = d.friction_velocity, py::arg("friction_rate") = d.friction_rate,
           "integrator: 'rk4' (fixed `step`), 'dopri5' or 'rosenbrock' (adaptive: rtol, atol, max_step; `step` the "
           "first trial) or an Integrator; max_steps: the run's budget; gravity (3,) world frame (None: orbit); "
           "grounded: the base held still; effort_limits: the controls' torques limited to the model's; "
           "joint_friction: the model's damping and Coulomb friction act (friction_velocity, friction_rate: its "
           "regularisation). ModelError for an option out of range.")
      .def_static("from_scenario", &fromScenario, py::arg("scenario"), py::arg("model") = py::none(),
                  "The simulator as `kdl_space simulate` builds it from a scenario's simulation section (options, "
                  "joint controls, limits, base control, wrenches, the robot's brakes) for `model` (None: the robot's; "
                  "after a capture: attach_target(scenario, result)). kdl_space.Error (ModelError or InputError) naming the file.")
      .def_property_readonly("model", [](const PySimulator& w) { return w.model; }, "The Model it integrates.")
      .def_property_readonly("joint_names", [](const PySimulator& w) { return w.model.ptr->jointNames(); })
      .def_property_readonly("options", [](const PySimulator& w) {
        const SimulationOptions& o = w.sim->options();
        py::dict r;
        r["integrator"] = toString(o.integrator), r["step"] = o.step, r["rtol"] = o.rtol, r["atol"] = o.atol;
        r["max_step"] = o.max_step, r["max_steps"] = o.max_steps, r["gravity"] = toNumpy(o.gravity, true);
        r["grounded"] = o.grounded, r["effort_limits"] = o.effort_limits, r["joint_friction"] = o.joint_friction;
        r["friction_velocity"] = o.friction_velocity, r["friction_rate"] = o.friction_rate;
        return r;
      }, "The options, as a dict of the constructor's keywords.")
      .def("set_joint_control", &setJointControl, py::arg("joint"), py::arg("mode"), py::kw_only(), py::arg("kp") = 0.0, py::arg("kd") = 0.0,
         py::arg("set_point") = 0.0,
         "Joint (name or index): 'free' (zero torque), 'locked' (brakes on), 'pd' (tau = kp (set_point - q) - kd "
         "qdot) or 'hold' (PD to the joint's position at the start of each run). ModelError for a negative gain.")
      .def_property_readonly("joint_controls", [](const PySimulator& w) {
        py::dict r;
        const auto& cs = w.sim->jointControls();
        for (std::size_t j = 0; j < cs.size(); ++j)
          r[py::str(w.model.ptr->jointNames()[j])] =
              py::dict(py::arg("mode") = modeName(cs[j]), py::arg("kp") = cs[j].kp, py::arg("kd") = cs[j].kd,
                       py::arg("set_point") = cs[j].set_point);
        return r;
      }, "Joint name -> {'mode', 'kp', 'kd', 'set_point'}.")
      .def("set_limit_mode", &setLimitMode, py::arg("joint"), py::arg("mode"),
         "What the joint's position limits do: 'ignore', 'warn' (recorded in stats; the default) or 'stop' (hard "
         "stops). ModelError for 'stop' on a joint without finite limits.")
      .def_property_readonly("limit_modes", [](const PySimulator& w) {
        py::dict r;
        const auto& ls = w.sim->limitModes();
        for (std::size_t j = 0; j < ls.size(); ++j) r[py::str(w.model.ptr->jointNames()[j])] = limitName(ls[j]);
        return r;
      }, "Joint name -> 'ignore', 'warn' or 'stop'.")
      .def("set_base_control", &setBaseControl, py::kw_only(), py::arg("attitude") = py::none(),
           py::arg("position") = py::none(),
           "The base's own control (None: off). attitude: {'kp', 'kd', 'set_point': world_R_base (3, 3), 'hold': "
           "the start's attitude, 'torque_limit': (3,) base axes}; position: {'kp', 'kd', 'set_point': (3,), "
           "'hold', 'force_limit': (3,)}. ModelError for a negative gain, a grounded base.")
      .def("add_wrench", [](PySimulator& w, py::object link, py::object wrench, py::object point, bool body_axes,
                            double start, double end) {
        ScheduledWrench x;
        x.body = bodyArgument(*w.model.ptr, link, "link");
        x.wrench = vec6(wrench, "wrench");
        if (!point.is_none()) x.point = vec3(point, "point");
        x.body_axes = body_axes, x.start = start, x.end = end;
        w.locked([&] { w.sim->addWrench(x); });
      }, py::arg("link"), py::arg("wrench"), py::kw_only(), py::arg("point") = py::none(), py::arg("body_axes") = false,
         py::arg("start") = 0.0, py::arg("end") = std::numeric_limits<double>::infinity(),
         "A wrench (f; n) (6,) on `link` (name or index) over [start, end) [s], the force at `point` (link frame, "
         "(3,)), world axes or the link's (body_axes). ModelError for a value not finite or end <= start.")
      .def("engage_brakes", [](PySimulator& w, const PyState& s) {
        SimulationState x = w.stateOf(s, "state");
        check(w.locked([&] { return w.sim->engageBrakes(x); }), "Simulator.engage_brakes");
        return PyState{w.model.ptr, x.state, x.velocity};
      }, py::arg("state"), "The state with the locked joints' rates stopped by an internal impulse (momentum kept).")
      .def("energy_and_momentum", [](PySimulator& w, const PyState& s) {
        const SimulationState x = w.stateOf(s, "state");
        double T = 0.0;
        Vector6d h;
        check(w.locked([&] { return w.sim->energyAndMomentum(x, T, h); }), "Simulator.energy_and_momentum");
        return py::make_tuple(T, toNumpy6(h));
      }, py::arg("state"), "(kinetic energy [J], momentum (P; L about the world origin) (6,)) of a state, in O(n).")
      .def("stiffness", [](PySimulator& w, const PyState& s) {
        const SimulationState x = w.stateOf(s, "state");
        Stiffness st;
        check(w.locked([&] { return w.sim->stiffness(x, st); }), "Simulator.stiffness");
        return PyStiffness{st, w.model.ptr->jointNames()};
      }, py::arg("state"), "The servos' fastest closed-loop rate at a state (Stiffness).")
      .def("apparent_inertia", [](PySimulator& w, const PyState& s, py::object joint) {
        const SimulationState x = w.stateOf(s, "state");
        const unsigned int j = jointArgument(*w.model.ptr, joint, "joint");
        double mass = 0.0;
        check(w.locked([&] { return w.sim->apparentInertia(x, j, mass); }), "Simulator.apparent_inertia");
        return mass;
      }, py::arg("state"), py::arg("joint"), "1 / (M^-1)_jj: the inertia the joint's torque meets at a state.")
      .def_property_readonly("friction_velocities", [](const PySimulator& w) {
        const std::vector<double>& v = w.sim->frictionVelocities();
        return toNumpyVec(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(v.size())));
      }, "Each joint's Coulomb regularisation v_s of the last run (nj,).")
      .def("run", &run, py::arg("state"), py::arg("t_end"), py::arg("output_dt"), py::kw_only(),
           py::arg("controller") = py::none(), py::arg("control_rate") = py::none(), py::arg("t0") = 0.0,
           py::arg("max_output_rows") = std::uint64_t{10'000'000}, py::arg("check_gains") = true,
           "Integrates from `state` at time t0 to t_end; samples at t0, every output_dt and t_end "
           "(SimulationResult). controller(t, q, qdot, base_pose (4, 4), base_twist (6,)) -> tau (nj,) (or a dict "
           "by joint name), added to the joint controls' torques: with control_rate [Hz], called at t0 + k / "
           "control_rate with the state there and held constant until the next (zero-order hold; output_dt and "
           "the period must be commensurate; check_gains: probed first, 2 calls a joint, kd / (rate m_j) > 1 warns "
           "in result.warnings and as RuntimeWarning); else called at every evaluation. The GIL is released "
           "while integrating; an exception in the controller ends the run and propagates; a nonzero return "
           "code raises ComputeError with .code, .t (how far the run got) and .result (the samples so far). "
           "Every sample is kept in memory: a run of more than max_output_rows samples is refused (ValueError) "
           "before it starts. Ctrl-C raises KeyboardInterrupt within about 0.1 s, between samples too.")
      .def("__repr__", [](const PySimulator& w) {
        std::ostringstream s;
        s << "<kdl_space.Simulator of " << w.model.source << ": " << w.model.ptr->nj() << " joints, "
          << toString(w.sim->options().integrator) << (w.sim->options().grounded ? ", grounded" : "") << ">";
        return s.str();
      });
}

}  // namespace kdl_space::python
