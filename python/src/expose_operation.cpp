// kdl_space.run_operation: the capture operation of a scenario (runCaptureOperation: approach,
// capture, the system after it, its motion) as one call; the result is the dict that
// `kdl_space simulate --json` prints (the same writer: tools/operation_report), plus the samples
// as NumPy arrays, with an optional controller at a control rate and an observer per sample.
#include <algorithm>
#include <cmath>
#include <exception>

#include "kdl_space/report/capture_report.hpp"
#include "capture_types.hpp"
#include "conversions.hpp"
#include "json_objects.hpp"
#include "expose_html.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/report/operation_report.hpp"
#include "simulation_types.hpp"

namespace kdl_space::python {
namespace {

/// The samples (the approach's, a compliant contact's, then the motion's), column by column.
py::dict samplesDict(const OperationResult& r) {
  std::vector<const MotionSample*> rows;
  for (const MotionSample& x : r.approach_samples) rows.push_back(&x);
  for (const MotionSample& x : r.contact_samples) rows.push_back(&x);
  for (const MotionSample& x : r.samples) rows.push_back(&x);
  const Eigen::Index k = static_cast<Eigen::Index>(rows.size()), n = r.model->nj();
  Eigen::MatrixXd t(k, 1), p(k, 3), quat(k, 4), twist(k, 6), q(k, n), qd(k, n), tau(k, n), h(k, 6), T(k, 1),
      wrench(k, 6), work(k, 6), impulse(k, 6), distance(k, 1), contact(k, 6), grasp(k, 6);
  Eigen::Index m = 0;  // reaction wheels: a sample's count (a compliant contact's rows carry none: NaN)
  for (const MotionSample* x : rows) m = std::max(m, x->wheel_momentum.size());
  Eigen::MatrixXd wheel_h = Eigen::MatrixXd::Constant(k, m, std::nan("")), wheel_u = wheel_h;
  py::list phase;
  for (Eigen::Index i = 0; i < k; ++i) {
    const MotionSample& x = *rows[static_cast<std::size_t>(i)];
    t(i) = x.t, T(i) = x.T, distance(i) = x.grasp_distance;
    p.row(i) = x.p.transpose(), quat.row(i) = x.quat.transpose(), twist.row(i) = x.twist.transpose();
    q.row(i) = x.q.transpose(), qd.row(i) = x.qd.transpose(), tau.row(i) = x.tau.transpose();
    h.row(i) = x.h.transpose(), wrench.row(i) = x.base_wrench.transpose(), work.row(i) = x.work.transpose();
    impulse.row(i) = x.impulse.transpose(), contact.row(i) = x.contact_wrench.transpose();
    grasp.row(i) = x.grasp_wrench.transpose();
    if (x.wheel_momentum.size() == m) wheel_h.row(i) = x.wheel_momentum.transpose();
    if (x.wheel_torque.size() == m) wheel_u.row(i) = x.wheel_torque.transpose();
    phase.append(toString(x.phase));
  }
  py::dict d;
  d["joint_names"] = r.model->jointNames();
  d["t"] = toNumpy(t, true);
  d["phase"] = phase;
  d["base_position"] = toNumpy(p);
  d["base_quaternion"] = toNumpy(quat);
  d["base_twist"] = toNumpy(twist);
  d["q"] = toNumpy(q);
  d["qdot"] = toNumpy(qd);
  d["tau"] = toNumpy(tau);
  d["momentum"] = toNumpy(h);
  d["energy"] = toNumpy(T, true);
  d["base_wrench"] = toNumpy(wrench);
  d["work"] = toNumpy(work);
  d["impulse"] = toNumpy(impulse);
  d["grasp_distance"] = toNumpy(distance, true);
  d["contact_wrench"] = toNumpy(contact);
  d["wheel_momentum"] = toNumpy(wheel_h);
  d["wheel_torque"] = toNumpy(wheel_u);
  d["grasp_wrench"] = toNumpy(grasp);
  return d;
}

py::object runOperation(const ScenarioArg& ps, py::object duration, py::object output_step, bool approach, bool motion,
                      py::object observer, py::object controller, py::object control_rate,
                      std::uint64_t max_output_rows, bool check_gains) {
  const Scenario& sc = ps.get();
  OperationOptions o;
  if (!duration.is_none()) {
    o.duration = argumentAs<double>(duration, "duration", "a number of seconds");
    if (!(*o.duration > 0.0) || !std::isfinite(*o.duration))
      throw py::value_error("duration: expected a finite duration > 0 s, got " + std::to_string(*o.duration));
  }
  if (!output_step.is_none()) {
    o.output_step = argumentAs<double>(output_step, "output_step", "a number of seconds");
    if (!(*o.output_step > 0.0) || !std::isfinite(*o.output_step))
      throw py::value_error("output_step: expected a finite step > 0 s, got " + std::to_string(*o.output_step));
  }
  o.approach = approach, o.motion = motion;
  o.check_sampled_gains = check_gains;
  // Every sample is kept (the result's arrays): their count is checked before the run.
  checkOutputRows("run_operation", estimatedOutputRows(sc, o), max_output_rows, "output_step (simulation.output_step)");
  o.cancelled = SignalPoll();  // Ctrl-C between the samples too
  if (!controller.is_none() && !PyCallable_Check(controller.ptr()))
    throw py::type_error("controller: expected a callable controller(t, q, qdot, base_pose, base_twist) -> tau");
  if (!observer.is_none() && !PyCallable_Check(observer.ptr()))
    throw py::type_error("observer: expected a callable observer(t, phase, q, qdot)");
  if (controller.is_none() && !control_rate.is_none()) throw py::value_error("control_rate: given without a controller");
  if (!control_rate.is_none()) {
    o.control_rate = argumentAs<double>(control_rate, "control_rate", "a rate in Hz");
    if (!(o.control_rate > 0.0) || !std::isfinite(o.control_rate))
      throw py::value_error("control_rate: expected a finite rate > 0 [Hz], got " + std::to_string(o.control_rate));
  }
  if (!controller.is_none())
    o.controller = [&](const SimulationState& x, Eigen::VectorXd& tau) {
      py::gil_scoped_acquire gil;
      const py::object r = controller(x.t, toNumpyVec(x.state.q.data), toNumpyVec(x.velocity.qdot.data),
                                      frameToNumpy(x.state.world_T_base), toNumpy6(toEigen(x.velocity.base_twist)));
      if (r.is_none()) throw py::value_error("controller: tau: expected an array of the joint torques, got None");
      tau = fromNumpy(r, "controller: tau", static_cast<Eigen::Index>(tau.size()));
      if (!tau.allFinite())
        throw py::value_error("controller: returned a torque that is not finite at t = " + std::to_string(x.t) + " s");
    };
  // Every sample: the observer if any, and Ctrl-C (a KeyboardInterrupt ends the run there).
  o.observer = [&](const OperationResult&, const MotionSample& x) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!observer.is_none()) observer(x.t, toString(x.phase), toNumpyVec(x.q), toNumpyVec(x.qd));
  };
  OperationResult r;
  std::exception_ptr failed;
  std::shared_ptr<const OperationResult> partial;
  {
    py::gil_scoped_release nogil;
    try {
      r = runCaptureOperation(sc, o);
    } catch (const OperationError& e) {
      failed = std::current_exception(), partial = e.partial();
    }
  }
  if (failed) {  // what the motion saw before it failed (a sampled controller's gains) warns too
    if (partial) reportWarnings(partial->warnings);
    std::rethrow_exception(failed);
  }
  const py::dict d = toPython(report::operationJson(sc, r));
  reportWarnings(r.warnings);  // the motion's warnings (also in d["warnings"]) as RuntimeWarnings
  d["samples"] = samplesDict(r);
  return operationResultOf(d, std::make_shared<const Scenario>(sc), std::move(r));  // a dict with to_html
}

/// The scenario's compliant law (or a stiff gripper's defaults), each keyword overriding it.
CompliantGrasp graspOf(const Scenario& sc, py::object stiffness, py::object damping, py::object damping_time,
                       py::object catch_tolerance, py::object max_duration, py::object normal, py::object lock) {
  CompliantGrasp g = sc.compliant.value_or(CompliantGrasp{});
  if (!stiffness.is_none()) g.stiffness = vec6(stiffness, "stiffness");
  if (!damping.is_none() && !damping_time.is_none())
    throw py::value_error("damping, damping_time: give one (D per axis, or D = damping_time * stiffness)");
  if (!damping.is_none()) g.damping = vec6(damping, "damping");
  if (!damping_time.is_none()) g.damping_time = argumentAs<double>(damping_time, "damping_time", "a number of seconds"), g.damping.reset();
  if (!catch_tolerance.is_none()) g.catch_tolerance = argumentAs<double>(catch_tolerance, "catch_tolerance", "a number");
  if (!max_duration.is_none()) g.max_duration = argumentAs<double>(max_duration, "max_duration", "a number of seconds");
  if (!normal.is_none()) {
    const Vector3d n = vec3(normal, "normal");
    if (!(n.norm() > 1e-12)) throw py::value_error("normal: has zero length");
    g.normal = n.normalized();
  }
  if (!lock.is_none()) {
    const std::string rule = argumentAs<std::string>(lock, "lock", "never, tolerance or spring_maximum");
    if (rule == "never") g.lock = GraspLock::Never;
    else if (rule == "tolerance") g.lock = GraspLock::Tolerance;
    else if (rule == "spring_maximum") g.lock = GraspLock::SpringMaximum;
    else throw py::value_error("lock: '" + rule + "' is not one of never, tolerance, spring_maximum");
  }
  return g;
}

py::object solveCompliant(const ScenarioArg& ps, py::object stiffness, py::object damping, py::object damping_time,
                          py::object catch_tolerance, py::object max_duration, py::object normal, py::object lock) {
  const Scenario& sc = ps.get();
  if (!sc.impact) throw py::value_error("scenario: a plain motion has no target to capture");
  const CompliantGrasp g = graspOf(sc, stiffness, damping, damping_time, catch_tolerance, max_duration, normal, lock);
  CompliantCaptureResult c;
  {
    py::gil_scoped_release nogil;
    CompliantRun run;
    run.options = sc.simulation.options;
    run.cancelled = SignalPoll();
    try {
      c = solveCompliantCapture(sc.capture, g, run);
    } catch (const Error& e) {
      e.rethrowWithContext(sc.file + ": ");
    }
  }
  return toPython(report::compliantJson(c));
}

}  // namespace

void bindOperation(py::module_& m) {
  m.def("solve_compliant_capture", &solveCompliant, py::arg("scenario"), py::kw_only(), py::arg("stiffness") = py::none(),
        py::arg("damping") = py::none(), py::arg("damping_time") = py::none(), py::arg("catch_tolerance") = py::none(),
        py::arg("max_duration") = py::none(), py::arg("normal") = py::none(), py::arg("lock") = py::none(),
        "The compliant capture of the scenario's target at the scenario's states (docs/COMPLIANT.md): the two "
        "systems joined at the grasp by a spring-damper, the contact integrated until the relative motion has died "
        "out (or it is caught, or opens). The "
        "law is the scenario's `law: {type: compliant, ...}` (or a stiff gripper's defaults), each keyword "
        "overriding it: stiffness and damping per axis (x, y, z [N/m, N s/m]; about x, y, z [N m/rad, N m s/rad]) "
        "of the robot's contact link, damping_time (D = damping_time * stiffness) [s], catch_tolerance, "
        "max_duration [s], normal (a one-sided contact), lock (never, the default: the grasp stays "
        "compliant; tolerance or spring_maximum: when the grasp locks). Returns the dict of `kdl_space capture --json`'s 'compliant' (end, duration, peak_force, impulse, "
        "lock_share, each side's velocities after, energies, history); "
        "solve_capture(scenario) is its impulsive limit. InputError for a parameter out of range.");
  m.def("run_operation", &runOperation, py::arg("scenario"), py::kw_only(), py::arg("duration") = py::none(),
        py::arg("output_step") = py::none(), py::arg("approach") = true, py::arg("motion") = true,
        py::arg("observer") = py::none(), py::arg("controller") = py::none(), py::arg("control_rate") = py::none(),
        py::arg("max_output_rows") = std::uint64_t{10'000'000}, py::arg("check_gains") = true,
        "The scenario's capture operation as `kdl_space simulate` runs it: the approach (if any), the capture at "
        "the contact instant, the system after it and `duration` s of its motion (None: the scenario's). Returns "
        "the dict `kdl_space simulate --json` prints (keys capture, compliant, approach, target_motion, simulation) "
        "with 'samples': the approach's, a compliant contact's (phase 'contact') and the motion's samples as NumPy "
        "arrays (t, phase, base_position, base_quaternion, base_twist, q, qdot, tau, momentum, energy, base_wrench, "
        "work, impulse, grasp_distance, contact_wrench: the compliant contact's (f; n) on the robot, NaN outside it; "
        "wheel_momentum, wheel_torque: (k, wheels) of robot.base_actuators' reaction wheels, NaN where none ran; "
        "grasp_wrench: the load the grasp carries, (f; n about the robot's contact point) the target exerts on the "
        "robot, in the contact and while the captured target is held, NaN where nothing is held; "
        "joint_names); an OperationResult (a dict) whose to_html(path) writes the run's 3-D page. `controller(t, q, qdot, base_pose, base_twist) -> tau` adds its torques in the motion "
        "after the capture, at `control_rate` Hz (zero-order hold) or at every evaluation (None); "
        "`observer(t, phase, q, qdot)` sees every sample. With control_rate and check_gains the controller is "
        "first probed at the start of the motion (2 calls a joint, its rate perturbed): a rate gain kd above "
        "control_rate x the joint's apparent inertia gets a warning (kind 'sampled_gain_unstable'), as a servo that "
        "forces tiny steps does ('stiff'), in 'warnings' and as a RuntimeWarning; 'base_control' says in which "
        "phases the scenario's base control acts ('phases') and acted ('acted_in'). InputError naming the scenario's file for what cannot "
        "be run or failed. The samples are kept in memory: a run that could give more than max_output_rows "
        "(approach.max_duration and duration over the output step) is refused (ValueError) before it starts. "
        "Ctrl-C raises KeyboardInterrupt within about 0.1 s.");
}

}  // namespace kdl_space::python
