#include "operation/phases.hpp"

#include <iomanip>
#include <map>
#include <sstream>

#include "spatial/message_text.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/impact/rigid_body_system.hpp"
#include "kdl_space/operation/overlap_check.hpp"

namespace kdl_space::operation {

Eigen::VectorXd wheelsAtContact(const Scenario& sc, const OperationResult& r) {
  return r.wheel_momentum_at_contact.size() > 0 ? r.wheel_momentum_at_contact : sc.base_actuators.wheel_momentum;
}

std::unique_ptr<Simulator> simulatorFor(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                        bool approach) {
  try {
    return makeSimulator(sc, model, approach);
  } catch (const Error& e) {
    e.rethrowWithContext(sc.file + ": ");
  }
}

namespace {

/// Why an approach never reached its grasp point (closest distance and when).
std::string approachFailure(const Scenario& sc, const ApproachRecord& r) {
  std::ostringstream why;
  why << std::setprecision(6) << sc.file << ": approach: the hand never reached the grasp point in "
      << sc.approach->max_duration << " s (approach.max_duration): " << r.cause << "; closest " << r.closest_distance
      << " m at t = " << r.closest_time << " s, " << r.final_distance << " m at the end (tolerance "
      << sc.approach->position_tolerance << " m); control with the " << toString(r.base) << " Jacobian";
  return why.str();
}

/// The overlaps an approach goes through, one per link and obstacle (ApproachOutcome::overlaps).
class OverlapsSeen {
 public:
  explicit OverlapsSeen(const Scenario& sc) : geometry_(linkGeometry(*sc.capture.robot.model, robotVisuals(sc))) {
    // The link that carries the hand closes on the target by design: its depth at the capture is
    // the capture's check (overlapWarnings' allowance there), not the approach's.
    const FloatingModel& model = *sc.capture.robot.model;
    const std::vector<bool> hand = contactBodies(model, sc.capture.robot.contact.body);
    for (std::size_t i = 0; i < hand.size(); ++i) {
      const int parent = model.bodies()[i].parent;
      if (hand[i] && parent >= 0 && !hand[static_cast<std::size_t>(parent)]) wrist_ = model.bodies()[static_cast<std::size_t>(parent)].name;
    }
  }
  /// The robot at `robot` and the target at `target` (a problem at the sample's instant), at t.
  void look(const CaptureProblem& at, double t) {
    std::vector<Diagnostic> found = overlapWarnings(at, geometry_, "approach");
    for (Diagnostic& d : busOverlapWarnings(*at.robot.model, at.robot.state, geometry_, "approach")) found.push_back(std::move(d));
    for (const Diagnostic& d : found) {
      std::string link, target;
      double depth = 0.0;
      for (const auto& [key, value] : d.details) {
        if (key == "link") link = std::get<std::string>(value);
        if (key == "target") target = std::get<std::string>(value);
        if (key == "depth") depth = std::get<double>(value);
      }
      if (link == wrist_ && target != "bus") continue;
      Seen& seen = seen_[link + "\n" + target];
      if (seen.link.empty()) seen = Seen{link, target, t, depth, t};
      if (depth > seen.deepest) seen.deepest = depth, seen.at = t;
    }
  }
  std::vector<Diagnostic> warnings() const {
    std::vector<Diagnostic> out;
    for (const auto& [key, s] : seen_) {
      Diagnostic d{s.link,
                   "during the approach: link '" + s.link + "' went inside " +
                       (s.target == "bus" ? std::string("its own bus's box") : "the " + s.target + "'s box of inertia") +
                       " from t = " + detail::number(s.from) + " s, " + detail::number(s.deepest) + " m deep at t = " +
                       detail::number(s.at) + " s: another start, a pre-grasp pose (approach.pre_grasp) or a "
                       "longer standoff keeps the arm clear",
                   "overlap", Severity::Warning};
      d.details = {{"link", s.link}, {"target", s.target}, {"depth", s.deepest}, {"moment", std::string("approach")},
                   {"from", s.from}, {"deepest_at", s.at}};
      out.push_back(std::move(d));
    }
    return out;
  }

 private:
  struct Seen {
    std::string link, target;
    double from = 0.0, deepest = 0.0, at = 0.0;
  };
  LinkGeometry geometry_;
  std::string wrist_;
  std::map<std::string, Seen> seen_;
};

}  // namespace

// --- The approach of a free-floating robot target (issue 28) -----------------------------------

std::unique_ptr<Simulator> targetSimulator(const Scenario& sc, const FloatingSystem& target) {
  SimulationOptions options = sc.simulation.options;
  options.grounded = target.response == Response::Grounded;
  auto sim = std::make_unique<Simulator>(target.model, options);
  JointControl locked;
  locked.mode = JointControl::Mode::Locked;
  for (unsigned int j = 0; j < target.model->nj(); ++j)
    if (target.response == Response::JointsLocked || (!target.locked.empty() && target.locked[j]))
      sim->setJointControl(j, locked);
  for (const auto& [j, control] : sc.simulation.target_joints) {  // its own servos act before the contact too
    try {
      sim->setJointControl(j, control);
    } catch (const Error& e) {
      e.rethrowWithContext("simulation.target_joints: ");
    }
  }
  return sim;
}

std::shared_ptr<FloatingApproachTarget> approachTarget(const Scenario& sc, const FloatingSystem& target,
                                                       const std::function<bool()>& cancelled) {
  std::unique_ptr<Simulator> sim = targetSimulator(sc, target);
  sim->setCancelPoll(cancelled);
  SimulationState start;
  start.state = target.state;
  start.velocity = target.velocity;
  if (sim->options().grounded && toEigen(start.velocity.base_twist) != Vector6d::Zero())
    throw InputError("the target's base is grounded (held still), but target.base.twist is not zero");
  return std::make_shared<FloatingApproachTarget>(std::move(sim), std::move(start), target.contact.body);
}

// -------------------------------------------------------------------------------------------------

void approach(const Scenario& sc, double output_step, const std::function<bool()>& cancelled, OperationResult& result,
              SimulationState& s) {
  const FloatingSystem& robot = sc.capture.robot;
  std::unique_ptr<Simulator> sim = simulatorFor(sc, robot.model, true);
  sim->setCancelPoll(cancelled);
  std::shared_ptr<FloatingApproachTarget> floating_target;  // a robot target, integrated beside the servicer
  const auto controller = inScenario(sc, [&] {
    try {
      if (const auto* target = std::get_if<FloatingSystem>(&sc.capture.target)) {
        floating_target = approachTarget(sc, *target, cancelled);
        return std::make_unique<ApproachController>(robot.model, robot.contact, *sc.approach, floating_target);
      }
      return std::make_unique<ApproachController>(robot.model, robot.contact, *sc.approach,
                                                  FreeRigidMotion(std::get<RigidTarget>(sc.capture.target)));
    } catch (const Error& e) {
      e.rethrowWithContext("approach: ");
    }
  });
  s.state = robot.state;
  s.velocity = robot.velocity;
  s.wheel_momentum = sc.base_actuators.wheel_momentum;
  ApproachOutcome outcome;
  outcome.start_warnings = approachStartWarnings(sc);
  if (const int rc = sim->engageBrakes(s)) throw InputError(sc.file + ": approach: cannot engage the brakes: " + strError(rc));
  std::vector<MotionSample>& samples = result.approach_samples;
  int observer_rc = E_NOERROR;
  OverlapsSeen overlaps(sc);
  CaptureProblem at = sc.capture;
  const auto observer = [&](const SimulationState& x, const ApproachCommand& cmd) {
    at.robot.state = x.state;  // the arm and the target at the sample, against each other and the bus
    if (auto* rigid = std::get_if<RigidTarget>(&at.target)) {
      if (controller->target(x.t, *rigid) == E_NOERROR) overlaps.look(at, x.t);
    } else if (SimulationState target; floating_target && floating_target->state(x.t, target) == E_NOERROR) {
      std::get<FloatingSystem>(at.target).state = target.state;
      overlaps.look(at, x.t);
    }
    MotionSample smp;
    if (const int rc = sampleOf(*sim, x, Phase::Approach, smp)) observer_rc = rc;
    smp.grasp_distance = cmd.error.head<3>().norm();
    samples.push_back(std::move(smp));
  };
  const int rc = runApproach(*sim, *controller, s, output_step, observer, outcome.record);
  outcome.overlaps = overlaps.warnings();
  result.approach = outcome;  // what it did so far, also when it failed
  if (rc || observer_rc) {
    std::ostringstream why;
    if (rc == E_CANCELLED)
      why << std::setprecision(6) << sc.file << ": the approach was cancelled at t = " << s.t << " s of at most "
          << sc.approach->max_duration << " s";
    else
      why << sc.file << ": the approach failed at t = " << s.t << " s: " << strError(rc ? rc : observer_rc);
    throw OperationError(why.str(), rc ? rc : observer_rc, std::make_shared<const OperationResult>(result));
  }
  if (floating_target) {
    FloatingSystem target = std::get<FloatingSystem>(sc.capture.target);
    SimulationState x;
    if (const int e = floating_target->state(s.t, x))
      throw OperationError(sc.file + ": approach: the target's motion failed at t = " + detail::number(s.t) +
                               " s: " + strError(e),
                           e, std::make_shared<const OperationResult>(result));
    target.state = x.state;
    target.velocity = x.velocity;
    result.at_contact.target = std::move(target);
  } else if (const int e = controller->target(s.t, outcome.target_at_contact)) {
    throw InputError(sc.file + ": approach: the target's motion: " + strError(e));
  } else {
    result.at_contact.target = outcome.target_at_contact;
  }
  if (outcome.record.reached && !samples.empty()) samples.back().phase = Phase::Capture;
  result.at_contact.robot.state = s.state;
  result.at_contact.robot.velocity = s.velocity;
  result.wheel_momentum_at_contact = s.wheel_momentum;
  result.approach = outcome;
  result.t_capture = s.t;
  if (!outcome.record.reached)  // what happened is the caller's to show (the CSV, the plot) with the refusal
    throw OperationError(approachFailure(sc, outcome.record), E_NOERROR, std::make_shared<const OperationResult>(result));
}

TargetMotion separatedTarget(const Scenario& sc, const FloatingSystem& target, double t0, double t_end,
                             double output_step, const std::function<bool()>& cancelled) {
  std::unique_ptr<Simulator> simulator = inScenario(sc, [&] { return targetSimulator(sc, target); });
  Simulator& sim = *simulator;
  sim.setCancelPoll(cancelled);
  TargetMotion m;
  m.end.t = t0;
  m.end.state = target.state;
  m.end.velocity = target.velocity;
  if (sim.options().grounded) m.end.velocity.base_twist = KDL::Twist::Zero();
  Vector6d h0 = Vector6d::Zero();
  int observer_rc = E_NOERROR;
  const auto observer = [&](const SimulationState& x) {
    double T;
    Vector6d h;
    if (const int rc = sim.energyAndMomentum(x, T, h)) observer_rc = rc;
    if (x.t == t0) h0 = h, m.T = T;
    m.dP = std::max(m.dP, (h.head<3>() - h0.head<3>()).norm());
    m.dL = std::max(m.dL, (h.tail<3>() - h0.tail<3>()).norm());
  };
  int rc = sim.engageBrakes(m.end);
  if (rc == E_NOERROR) rc = sim.run(m.end, t_end, output_step, observer);
  if (rc || observer_rc)
    throw OperationError(sc.file + ": the target's motion after the impact " +
                             (rc == E_CANCELLED ? "was cancelled" : "failed") + " at t = " + detail::number(m.end.t) +
                             " s" + (rc == E_CANCELLED ? "" : std::string(": ") + strError(rc ? rc : observer_rc)),
                         rc ? rc : observer_rc, nullptr);
  return m;
}

}  // namespace kdl_space::operation

namespace kdl_space {

std::vector<Diagnostic> approachStartWarnings(const Scenario& sc) {
  if (!sc.approach) return {};
  const FloatingSystem& robot = sc.capture.robot;
  Conditioning c;
  std::vector<Diagnostic> warnings;
  // A state the solver refuses fails the approach itself; the limit warnings stand alone then.
  checkConfiguration(robot.model, robot.state, robot.contact, c, warnings);
  for (Diagnostic& d : overlapWarnings(sc, sc.capture, "start")) warnings.push_back(std::move(d));
  for (Diagnostic& d : warnings) d.message = "at the start of the approach: " + d.message;
  return warnings;
}

std::optional<JoinedSystem> joinedAfterCapture(const CaptureProblem& problem, const CaptureResult& capture) {
  const ImpactKind kind = problem.law.kind;
  if (kind != ImpactKind::Capture && kind != ImpactKind::TranslationalCapture) return std::nullopt;
  const GraspJoint grasp = kind == ImpactKind::Capture ? GraspJoint::Rigid : GraspJoint::Spherical;
  if (const auto* target = std::get_if<FloatingSystem>(&problem.target))
    return joinAtGrasp(problem.robot, capture.robot.after, *target, capture.floating_target->after, grasp,
                       problem.touch_tolerance);
  if (grasp == GraspJoint::Rigid) return std::nullopt;  // the payload route (attachTarget)
  const RigidTarget& rigid = std::get<RigidTarget>(problem.target);
  FloatingSystem body = rigidBodySystem(rigid, capture.contact_point, capture.target_twist_before);
  FloatingVelocity after = body.velocity;
  after.base_twist = toTwist(capture.target_twist_after);
  return joinAtGrasp(problem.robot, capture.robot.after, body, after, grasp, problem.touch_tolerance);
}

}  // namespace kdl_space
