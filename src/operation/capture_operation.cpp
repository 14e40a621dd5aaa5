#include "kdl_space/operation/capture_operation.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "kdl_space/simulation/integrator.hpp"
#include "operation/phases.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {

/// A run that cannot fit its step budget is refused before it starts, not after max_steps steps:
/// every step is at most max_step (dopri5) or step (rk4) long, and each output row ends a step.
void checkStepBudget(const Scenario& sc, double duration, double output_step) {
  const SimulationSpec& spec = sc.simulation;
  const StepEstimate e = fewestSteps(spec, duration, output_step);
  if (e.steps > static_cast<double>(spec.options.max_steps)) {
    std::ostringstream why;
    why << std::setprecision(12) << sc.file << ": simulation: " << duration << " s in steps of at most " << e.longest
        << " s (simulation." << e.limited_by << ") needs " << e.steps << " steps, more than simulation.max_steps = "
        << spec.options.max_steps;
    throw InputError(why.str());
  }
}

/// An approach whose servo is too stiff for an explicit integrator is refused before it starts
/// (it would spend the step budget first: 51 s for servo_bandwidth 1e9): the closed-loop rate of a
/// joint's velocity servo is the bandwidth, and an explicit Runge-Kutta step must stay below about
/// 3 / rate (its stability interval on the negative real axis: 2.8 for RK4, 3.3 for DOPRI5).
void checkApproachStiffness(const Scenario& sc) {
  const SimulationSpec& spec = sc.simulation;
  if (!sc.approach || spec.options.integrator == Integrator::Rosenbrock) return;
  const double steps = sc.approach->max_duration * sc.approach->servo_bandwidth / 3.0;
  if (!(steps > static_cast<double>(spec.options.max_steps))) return;
  std::ostringstream why;
  why << std::setprecision(6) << sc.file << ": approach.servo_bandwidth: " << sc.approach->servo_bandwidth
      << " 1/s needs explicit steps below about " << 3.0 / sc.approach->servo_bandwidth << " s, so "
      << steps << " steps for approach.max_duration = " << sc.approach->max_duration
      << " s, more than simulation.max_steps = " << spec.options.max_steps
      << ": lower the bandwidth (a joint servo's is 10 to 100 1/s), or use simulation.integrator: rosenbrock";
  throw InputError(why.str());
}

/// Why a simulation stopped, in the scenario's terms: what grew, when, and what to try. `s` is
/// the last accepted state.
std::string simulationFailure(int rc, const SimulationSpec& spec, const MotionRecord& r, const SimulationState& s) {
  const std::string advice = stiffnessAdvice(r);
  switch (rc) {
    case E_MAX_STEPS:
      return "the step budget simulation.max_steps = " + std::to_string(spec.options.max_steps) +
             " is spent (an unstable controller? raise max_steps, or loosen rtol and atol)" +
             (advice.empty() ? std::string() : "; " + advice);
    case E_STEP_UNDERFLOW:
      return std::string(strError(rc)) + " (loosen simulation.rtol and atol)" +
             (advice.empty() ? std::string() : "; " + advice);
    case E_NOT_FINITE: {
      std::ostringstream why;
      why << std::setprecision(3) << "the motion blew up to NaN or infinite values (unstable PD gains, or too large an "
          << "rk4 step?)";
      const std::vector<std::string>& joints = r.model->jointNames();
      Eigen::Index j = 0;
      if (s.velocity.qdot.rows() > 0 && s.velocity.qdot.data.allFinite()) {
        const double fastest = s.velocity.qdot.data.cwiseAbs().maxCoeff(&j);
        why << ": by t = " << s.t << " s joint '" << joints[j] << "' moved at " << fastest
            << " rad/s (or m/s), the base at " << toEigen(s.velocity.base_twist.rot).norm() << " rad/s";
      }
      const Stiffness& st = r.stiffness;
      if (st.fastest_joint >= 0)
        why << "; the servo of joint '" << joints[st.fastest_joint] << "' (closed-loop rate " << st.fastest_rate
            << " 1/s) needs explicit steps below " << st.explicit_step
            << " s: lower simulation.step or the gains, or use integrator: rosenbrock";
      return why.str();
    }
    default:
      return strError(rc);
  }
}

/// Samples of the system `from` in the joints of the system after the capture, by name: a target
/// that joined brought joints (NaN in the approach's rows); one that bounced off took its own.
void samplesIn(const FloatingModel& model, const FloatingModel& from, std::vector<MotionSample>& samples) {
  if (&model == &from) return;
  for (MotionSample& x : samples) {
    Eigen::VectorXd q = Eigen::VectorXd::Constant(model.nj(), NAN), qd = q, tau = q;
    for (unsigned int j = 0; j < from.nj(); ++j) {
      const int k = model.jointIndex(from.jointNames()[j]);
      if (k >= 0) q(k) = x.q(j), qd(k) = x.qd(j), tau(k) = x.tau(j);
    }
    x.q = q, x.qd = qd, x.tau = tau;
  }
}

/// The joint modes of the system after the capture: the target keeps its own joints' (its
/// brakes, the controls of simulation.target_joints); with hold_servos the PD joints hold.
void setModesAfter(const Scenario& sc, const CaptureProblem& problem, const OperationResult& r, bool hold_servos,
                   Simulator& sim) {
  // A compliant grasp: locked at its deflection, or (law.lock: never) its springs and dampers on.
  const bool springs = sc.compliant && sc.compliant->lock == GraspLock::Never;
  if (r.joined && r.joined->grasp == GraspJoint::Compliant)
    for (int k = 0; k < 6; ++k)
      sim.setJointControl(static_cast<unsigned int>(r.joined->grasp_joints[static_cast<std::size_t>(k)]),
                          springs ? sc.compliant->jointSpring(k) : JointControl{JointControl::Mode::Locked});
  if (r.joined)
    if (const auto* target = std::get_if<FloatingSystem>(&problem.target)) {
      const JoinedSystem& joint = *r.joined;
      JointControl locked;
      locked.mode = JointControl::Mode::Locked;
      for (std::size_t j = 0; j < joint.target_joints.size(); ++j)
        if (target->response == Response::JointsLocked || (!target->locked.empty() && target->locked[j]))
          sim.setJointControl(static_cast<unsigned int>(joint.target_joints[j]), locked);
      for (auto [j, control] : sc.simulation.target_joints) {
        control.set_point *= joint.target_joint_sign[j];  // a reversed joint's coordinate is negated
        try {
          sim.setJointControl(static_cast<unsigned int>(joint.target_joints[j]), control);
        } catch (const Error& e) {
          e.rethrowWithContext(sc.file + ": simulation.target_joints: ");
        }
      }
    }
  if (hold_servos)
    for (unsigned int j = 0; j < r.model->nj(); ++j) {
      JointControl c = sim.jointControls()[j];
      if (c.mode != JointControl::Mode::PD) continue;
      if (r.joined && std::find(r.joined->grasp_joints.begin(), r.joined->grasp_joints.end(), static_cast<int>(j)) !=
                          r.joined->grasp_joints.end())
        continue;  // a compliant grasp's springs hold zero deflection, not where the motion starts
      c.hold = true;
      sim.setJointControl(j, c);
    }
}

/// What the start of the motion must satisfy: a grounded base at rest, joints inside their hard
/// stops; then the brakes engage.
void checkStart(const Scenario& sc, Simulator& sim, SimulationState& s) {
  const FloatingModel& model = sim.model();
  if (sim.options().grounded && toEigen(s.velocity.base_twist) != Vector6d::Zero()) {
    std::ostringstream why;
    why << sc.file << ": simulation: the base is grounded (held still), but its twist at the start of the motion is "
        << toEigen(s.velocity.base_twist).transpose().format(Eigen::IOFormat(6, Eigen::DontAlignCols, ", ", ", ", "", "", "[", "]"))
        << ": give robot.base.twist zero, or simulation.base: free";
    throw InputError(why.str());
  }
  for (unsigned int j = 0; j < model.nj(); ++j) {  // a hard stop holds a joint inside its limits only
    const JointProperties& p = model.jointProperties()[j];
    const double q = s.state.q(j);
    if (sim.limitModes()[j] == LimitMode::Stop && (q > p.upper || q < p.lower)) {
      std::ostringstream why;
      why << sc.file << ": simulation.limits: joint '" << model.jointNames()[j] << "' starts at " << q
          << ", outside its limits [" << p.lower << ", " << p.upper
          << "] (a hard stop keeps it inside them): start it inside, or let its limits warn";
      throw InputError(why.str());
    }
  }
  if (const int rc = sim.engageBrakes(s)) throw InputError(sc.file + ": simulation: cannot engage the brakes: " + strError(rc));
}

}  // namespace

void runMotionAfterCapture(const Scenario& sc, const CaptureProblem& problem, const std::optional<CaptureResult>& capture,
                           double t_capture, const OperationOptions& o, OperationResult& r) {
  using operation::inScenario;
  r.duration = o.duration.value_or(sc.simulation.duration);
  r.output_step = o.output_step.value_or(sc.simulation.output_step);
  r.at_contact = problem;
  r.capture = capture;
  r.t_capture = t_capture;
  r.model = problem.robot.model;
  if (capture) {
    r.joined = inScenario(sc, [&] {
      try {
        return joinedAfterCapture(problem, *capture);
      } catch (const Error& e) {
        e.rethrowWithContext("target: cannot join the captured target to the robot: ");
      }
    });
    r.model = r.joined ? r.joined->model : inScenario(sc, [&] { return attachTarget(problem, *capture); });
  }
  r.payload_attached = r.model != problem.robot.model;
  SimulationState s;
  s.t = t_capture;
  s.state = r.joined ? r.joined->state : problem.robot.state;
  s.velocity = r.joined ? r.joined->velocity : capture ? capture->robot.after : problem.robot.velocity;
  s.wheel_momentum = operation::wheelsAtContact(sc, r);
  // A free-floating target that separated after a point impact moves on by itself.
  std::optional<FloatingSystem> separated;
  if (const auto* target = std::get_if<FloatingSystem>(&problem.target))
    if (!r.joined && capture && capture->floating_target) {
      separated = *target;
      separated->velocity = capture->floating_target->after;
    }
  operation::runMotion(sc, problem, s, separated, o, r);
}

namespace operation {

/// The warning `grasp_overload` when the grasp's peak load (the compliant contact's, or the held
/// target's in the motion) passed law.max_grasp_wrench.
void graspOverloadWarning(const Scenario& sc, OperationResult& r) {
  GraspPeak peak = r.record.grasp;
  if (r.compliant) {  // the contact's peaks come before the motion's
    peak.force = std::max(r.compliant->peak_force, peak.held() ? peak.force : 0.0);
    peak.moment = std::max(r.compliant->peak_moment, std::isnan(peak.moment) ? 0.0 : peak.moment);
  }
  if (!peak.held()) return;
  std::ostringstream why;
  why << std::setprecision(6);
  if (peak.force > sc.max_grasp_force)
    why << "the grasp carried " << peak.force << " N, more than law.max_grasp_wrench.force " << sc.max_grasp_force << " N";
  if (peak.moment > sc.max_grasp_moment)
    why << (why.tellp() > 0 ? ", and " : "the grasp carried ") << peak.moment
        << " N m, more than law.max_grasp_wrench.moment " << sc.max_grasp_moment << " N m";
  if (why.tellp() > 0)
    r.warnings.push_back(Diagnostic{"law.max_grasp_wrench",
                                    why.str() + " (simulation.grasp_load says when): a softer or slower law after the "
                                                "capture (simulation.after_capture), or a stronger grasp",
                                    "grasp_overload"});
}

}  // namespace operation

std::optional<HeldTarget> heldTarget(const OperationResult& r) {
  if (!r.capture || !r.payload_attached || !r.model) return std::nullopt;  // nothing held after a point impact
  const CaptureProblem& problem = r.at_contact;
  const FloatingModel& robot = *problem.robot.model;
  const std::string& link = robot.bodies()[problem.robot.contact.body].name;
  HeldTarget held;
  held.bodies.assign(r.model->bodies().size(), false);
  held.contact.offset = problem.robot.contact.offset;
  for (std::size_t i = 0; i < r.model->bodies().size(); ++i) {
    const std::string& name = r.model->bodies()[i].name;
    if (name == link) held.contact.body = static_cast<int>(i);
    held.bodies[i] = robot.bodyIndex(name) < 0;  // joinAtGrasp keeps the robot's names, makes the target's unique
  }
  if (!r.joined) {  // a rigid target merged into the hand (attachTarget)
    const LinkPayload p = payloadInLink(std::get<RigidTarget>(problem.target), r.capture->contact_body_pose);
    held.payload_body = held.contact.body;
    held.payload_mass = p.mass;
    held.payload_com = p.com;
    held.payload_I_com = p.I_com;
  }
  return held;
}

namespace operation {

void runMotion(const Scenario& sc, const CaptureProblem& problem, SimulationState s,
               const std::optional<FloatingSystem>& separated, const OperationOptions& o, OperationResult& r) {
  samplesIn(*r.model, *problem.robot.model, r.approach_samples);
  if (r.compliant) samplesIn(*r.model, *r.compliant->joined.model, r.contact_samples);
  const double t_start = s.t;
  r.record = MotionRecord{};
  r.record.model = r.model;
  r.record.output_step = r.output_step;
  r.record.t_start = r.record.t_reached = t_start;
  r.record.detumble.threshold = sc.simulation.detumble_rate;
  if (o.observer) {
    for (const MotionSample& x : r.approach_samples) o.observer(r, x);
    for (const MotionSample& x : r.contact_samples) o.observer(r, x);
  }
  if (!o.motion) return;

  std::unique_ptr<Simulator> simulator = operation::simulatorFor(sc, r.model, false);
  Simulator& sim = *simulator;
  sim.setCancelPoll(o.cancelled);
  setModesAfter(sc, problem, r, o.hold_servos, sim);
  checkStart(sc, sim, s);
  const SimulationState start = s;
  // A sampled controller's rate gains against what its hold keeps stable, before it runs.
  if (o.check_sampled_gains)
    if (const int grc = sampledGainWarnings(sim, s, o.controller, o.control_rate, r.warnings))
      throw OperationError(sc.file + ": the controller's gains could not be checked at the start of the motion: " +
                               strError(grc),
                           grc, std::make_shared<const OperationResult>(r));
  if (sim.baseControl().on()) r.base_control_phases.push_back("after");
  int observer_rc = E_NOERROR;
  const Phase phase = sc.impact ? Phase::Post : Phase::Motion;
  const bool spherical = r.joined && r.joined->grasp == GraspJoint::Spherical;
  const std::optional<HeldTarget> held = heldTarget(r);
  Kinematics kin(*r.model);
  FloatingAcceleration acc;
  std::vector<KDL::Wrench> f_ext;
  const auto observer = [&](const SimulationState& x) {
    MotionSample smp;
    if (const int rc = sampleOf(sim, x, phase, smp)) observer_rc = rc;
    if (held) {  // the load the grasp carries (eq. of motion of the held bodies)
      int rc = sim.accelerations(x, kin, acc, f_ext);
      if (rc == E_NOERROR) rc = graspWrench(*r.model, *held, kin, x.velocity, acc, f_ext, sim.options().gravity, smp.grasp_wrench);
      if (rc) observer_rc = rc;
    }
    if (spherical) r.min_chart_margin = std::min(r.min_chart_margin, sphericalChartMargin(*r.joined, x.state));
    r.record.add(smp);
    if (o.observer) o.observer(r, smp);
    if (o.keep_samples) r.samples.push_back(std::move(smp));
  };
  const int rc = runSampled(sim, s, t_start + r.duration, r.output_step, o.controller, o.control_rate, observer);
  r.end = s;
  r.record.takeFrom(sim);
  r.record.t_reached = s.t;
  // The servos' stiffness at the start, with the friction's regularisation of the run.
  if (const int src = sim.stiffness(start, r.record.stiffness))
    throw OperationError(sc.file + ": simulation: " + strError(src), src, std::make_shared<const OperationResult>(r));
  if (r.record.stats.wheel_saturation_time > 0.0)
    r.warnings.push_back(Diagnostic{"robot.base_actuators.wheels",
                                    "the reaction wheels were at their torque limit or momentum capacity for " +
                                        detail::number(r.record.stats.wheel_saturation_time) + " s from t = " +
                                        detail::number(r.record.stats.wheel_saturation_first_time) +
                                        " s: the bus's attitude was not held as the law asked (larger wheels, "
                                        "softer gains, or thrusters to unload them)",
                                    "wheel_saturated"});
  graspOverloadWarning(sc, r);
  if (const std::string advice = stiffnessAdvice(r.record); !advice.empty())  // a warning, by the joint's name
    r.warnings.push_back(Diagnostic{r.model->jointNames()[r.record.stiffness.fastest_joint],
                                    advice + " (its gains come from simulation.joints, where a pattern such as \"*\" "
                                             "gives every joint it matches the same gains)",
                                    "stiff"});
  if (rc == E_CANCELLED) {
    std::ostringstream why;
    why << std::setprecision(6) << sc.file << ": the simulation was cancelled at t = " << s.t << " s of "
        << t_start + r.duration << " s";
    throw OperationError(why.str(), rc, std::make_shared<const OperationResult>(r));
  }
  if (rc || observer_rc) {
    std::ostringstream why;
    why << sc.file << ": simulation failed at t = " << s.t << " s of " << r.duration << " s: "
        << simulationFailure(rc ? rc : observer_rc, sc.simulation, r.record, s);
    for (const Diagnostic& d : r.warnings)  // what was seen before it ran: the likely cause
      if (d.kind == "sampled_gain_unstable") why << "; " << d.message;
    throw OperationError(why.str(), rc ? rc : observer_rc, std::make_shared<const OperationResult>(r));
  }
  if (separated)
    r.target_motion = operation::separatedTarget(sc, *separated, t_start, t_start + r.duration, r.output_step, o.cancelled);
}

}  // namespace operation

bool holdsTarget(const Scenario& sc) {
  const ImpactKind k = sc.capture.law.kind;
  return sc.impact && (sc.compliant || k == ImpactKind::Capture || k == ImpactKind::TranslationalCapture);
}

double estimatedOutputRows(const Scenario& sc, const OperationOptions& o) {
  const double output_step = o.output_step.value_or(sc.simulation.output_step);
  // Simulator::run's samples: the start, every multiple of the step after it, and the end.
  const auto rows = [&](double duration) { return std::ceil(duration / output_step * (1.0 - 1e-12)) + 1.0; };
  double n = 0.0;
  if (sc.approach && o.approach) n += rows(sc.approach->max_duration);
  if (o.motion) n += rows(o.duration.value_or(sc.simulation.duration));
  return n;
}

namespace {

/// The capture at the contact instant r.t_capture (a compliant law's contact, or the impulsive
/// law's), then the system after it and its motion.
void captureAndMotion(const Scenario& sc, const CaptureProblem& at_contact, const OperationOptions& o, OperationResult& r) {
  std::optional<CaptureResult> capture;
  if (sc.impact) capture = operation::inScenario(sc, [&] { return solveCapture(at_contact); });
  if (sc.compliant) operation::compliantCapture(sc, at_contact, capture, o, r);  // its limit beside it
  else runMotionAfterCapture(sc, at_contact, capture, r.t_capture, o, r);
}

}  // namespace

OperationResult runCaptureOperation(const Scenario& sc, const OperationOptions& o) {
  using operation::inScenario;
  OperationResult r;
  r.duration = o.duration.value_or(sc.simulation.duration);
  r.output_step = o.output_step.value_or(sc.simulation.output_step);
  if (o.motion) checkStepBudget(sc, r.duration, r.output_step);
  if (o.approach) checkApproachStiffness(sc);
  r.at_contact = sc.capture;
  SimulationState s;
  s.wheel_momentum = sc.base_actuators.wheel_momentum;
  if (sc.approach && o.approach) {
    if (sc.simulation.base_control.on() && sc.simulation.base_control.in_approach)
      r.base_control_phases.push_back("approach");
    operation::approach(sc, r.output_step, o.cancelled, r, s);
  }
  const CaptureProblem at_contact = r.at_contact;
  captureAndMotion(sc, at_contact, o, r);
  return r;
}

OperationResult runOperationFrom(const Scenario& sc, const CaptureProblem& at_contact, const OperationOptions& o) {
  OperationResult r;
  r.duration = o.duration.value_or(sc.simulation.duration);
  r.output_step = o.output_step.value_or(sc.simulation.output_step);
  if (o.motion) checkStepBudget(sc, r.duration, r.output_step);
  r.at_contact = at_contact;
  captureAndMotion(sc, at_contact, o, r);
  return r;
}

}  // namespace kdl_space
