#include "capture_operation.hpp"

#include <sstream>

#include "capture.hpp"
#include "detail/text.hpp"

namespace kdl_space::cli {

/// A name of the robot's model resolved in `model` (the same model, or the robot with a payload).
unsigned int jointIn(const FloatingModel& model, const FloatingModel& robot, unsigned int j) {
  return static_cast<unsigned int>(model.jointIndex(robot.jointNames()[j]));
}

/// One output row from a state of the run of `sim`.
Sample sampleOf(Simulator& sim, const SimulationState& x, int& rc) {
  Sample smp;
  smp.t = x.t;
  smp.p = toEigen(x.state.world_T_base.p);
  x.state.world_T_base.M.GetQuaternion(smp.quat(0), smp.quat(1), smp.quat(2), smp.quat(3));
  smp.twist = toEigen(x.velocity.base_twist);
  smp.q = x.state.q.data;
  smp.qd = x.velocity.qdot.data;
  smp.tau = x.tau.data;
  smp.base_wrench = x.base_wrench;
  smp.work << x.work.controller, x.work.friction, x.work.limits, x.work.base_control, x.work.wrenches, x.work.gravity;
  smp.impulse = x.impulse;
  if (const int e = sim.energyAndMomentum(x, smp.T, smp.h)) rc = e;
  return smp;
}

/// A simulator built from the scenario, or its refusal in the scenario's words.
std::unique_ptr<Simulator> simulatorFor(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                        bool approach) {
  try {
    return makeSimulator(sc, model, approach);
  } catch (const ModelError& e) {
    throw InputError(sc.file + ": " + e.what());
  }
}

/// The approach phase: from the robot's initial state until the hand holds the grasp point; the
/// samples (the last one: the contact instant) go to `samples`. `problem` gets the robot's and
/// the target's states at the contact instant.
ApproachOutcome approachPhase(const Scenario& sc, CaptureProblem& problem, double output_step,
                              std::vector<Sample>& samples, SimulationState& s) {
  const FloatingSystem& robot = sc.capture.robot;
  std::unique_ptr<Simulator> sim = simulatorFor(sc, robot.model, true);
  const auto controller = inScenario(sc, [&] {
    try {
      return std::make_unique<ApproachController>(robot.model, robot.contact, *sc.approach,
                                                  FreeRigidMotion(std::get<RigidTarget>(sc.capture.target)));
    } catch (const ModelError& e) {
      throw InputError(std::string("approach: ") + e.what());
    }
  });
  s.state = robot.state;
  s.velocity = robot.velocity;
  if (const int rc = sim->engageBrakes(s)) throw InputError(sc.file + ": approach: cannot engage the brakes: " + strError(rc));
  ApproachOutcome outcome;
  int observer_rc = E_NOERROR;
  const auto observer = [&](const SimulationState& x, const ApproachCommand& cmd) {
    Sample smp = sampleOf(*sim, x, observer_rc);
    smp.phase = "approach";
    smp.grasp_distance = cmd.error.head<3>().norm();
    samples.push_back(std::move(smp));
  };
  const int rc = runApproach(*sim, *controller, s, output_step, observer, outcome.record);
  if (rc || observer_rc) {
    std::ostringstream why;
    why << sc.file << ": the approach failed at t = " << s.t << " s: " << strError(rc ? rc : observer_rc);
    throw InputError(why.str());
  }
  if (const int e = controller->target(s.t, outcome.target_at_contact))
    throw InputError(sc.file + ": approach: the target's motion: " + strError(e));
  if (outcome.record.reached && !samples.empty()) samples.back().phase = "capture";
  problem.robot.state = s.state;
  problem.robot.velocity = s.velocity;
  problem.target = outcome.target_at_contact;
  return outcome;
}

namespace {
/// A rigid target as a free-floating system of one body (no joints), its frame at the CoM with
/// the inertia's axes of the target's frame: what a ball joint can join to the robot.
FloatingSystem oneBody(const RigidTarget& t, const Vector3d& contact_point, const Vector6d& twist_at_com) {
  const Matrix3d& I = t.inertia;
  FloatingSystem s;
  s.model = std::make_shared<const FloatingModel>(
      KDL::Tree("target"), KDL::RigidBodyInertia(t.mass, KDL::Vector::Zero(),
                                                 KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2))));
  s.state = State(*s.model);
  s.state.world_T_base = KDL::Frame(t.pose.M, t.pose * toKDL(t.com));
  s.velocity = FloatingVelocity(*s.model);
  s.velocity.base_twist = toTwist(twist_at_com);
  s.contact = Contact{0, s.state.world_T_base.Inverse() * toKDL(contact_point)};
  return s;
}

}  // namespace

/// After a capture that joins the target to the robot (a free-floating target captured rigidly
/// or translationally, a rigid target captured translationally): the joined system.
std::optional<JoinedSystem> joined(const CaptureProblem& problem, const CaptureResult& capture) {
  const ImpactKind kind = problem.law.kind;
  if (kind != ImpactKind::Capture && kind != ImpactKind::TranslationalCapture) return std::nullopt;
  const GraspJoint grasp = kind == ImpactKind::Capture ? GraspJoint::Rigid : GraspJoint::Spherical;
  if (const auto* target = std::get_if<FloatingSystem>(&problem.target))
    return joinAtGrasp(problem.robot, capture.robot.after, *target, capture.floating_target->after, grasp,
                       problem.touch_tolerance);
  if (grasp == GraspJoint::Rigid) return std::nullopt;  // the payload route (attachTarget)
  const RigidTarget& rigid = std::get<RigidTarget>(problem.target);
  FloatingSystem body = oneBody(rigid, capture.contact_point, capture.target_twist_before);
  FloatingVelocity after = body.velocity;
  after.base_twist = toTwist(capture.target_twist_after);
  return joinAtGrasp(problem.robot, capture.robot.after, body, after, grasp, problem.touch_tolerance);
}

/// The scene at the start, at the contact (the impact, at t_contact) and at the end of the run.
std::vector<SceneSnapshot> sceneSnapshots(const Scenario& sc, const CaptureProblem& at_contact,
                                          const std::optional<CaptureResult>& capture, bool joined,
                                          const std::shared_ptr<const FloatingModel>& model, const SimulationState& end,
                                          double t_contact, const SimulationState* target_end) {
  // The grasp point of an approach: fixed in the (rigid) target's frame.
  const auto grasp = [&](const CaptureTarget& target) -> std::optional<Vector3d> {
    const auto* rigid = std::get_if<RigidTarget>(&target);
    if (!sc.approach || !rigid) return std::nullopt;
    return toEigen(rigid->pose * sc.approach->grasp.p);
  };
  const auto at = [&](const CaptureProblem& problem, const char* label, double t) {
    Scenario then = sc;
    then.capture = problem;
    SceneSnapshot snap = impactSnapshot(then);
    if (!sc.impact) snap.target_body.reset();  // a plain motion: no target
    if (const std::optional<Vector3d> g = grasp(problem.target)) snap.grasp_point = g;
    snap.label = label;
    snap.t = t;
    return snap;
  };
  std::vector<SceneSnapshot> out;
  if (sc.approach || !sc.impact) out.push_back(at(sc.capture, "start", 0.0));
  if (sc.impact) out.push_back(at(at_contact, sc.approach ? "contact" : "impact", t_contact));
  SceneSnapshot last;
  last.label = "end";
  last.t = end.t;
  last.robot = model;  // the joined system, the robot with its payload, or the robot alone
  last.robot_state = end.state;
  last.robot_contact = joined ? Contact{-1, KDL::Vector::Zero()} : at_contact.robot.contact;
  if (capture && model == at_contact.robot.model) {  // the target separated: a rigid one tumbles on
    if (const auto* rigid = std::get_if<RigidTarget>(&at_contact.target)) {
      RigidTarget after = *rigid;
      after.twist = capture->target_twist_after;
      RigidTarget later;
      if (FreeRigidMotion(after).at(end.t - t_contact, later) == E_NOERROR) {
        last.target_body = later.toWorld();
        last.target_frame = later.pose;
      }
    }
  }
  if (const auto* floating = std::get_if<FloatingSystem>(&at_contact.target); floating && target_end) {
    last.target_robot = floating->model;  // separated after a point impact: where it went
    last.target_state = target_end->state;
  }
  out.push_back(last);
  return out;
}

/// A free-floating target that separates after a point impact moves on by itself: its motion
/// from the impact (its own modes: braked joints stay braked; gravity as the robot's), to t_end.
std::optional<TargetMotion> separatedTarget(const Scenario& sc, const CaptureProblem& problem,
                                            const std::optional<CaptureResult>& capture, double t0, double t_end) {
  const auto* target = std::get_if<FloatingSystem>(&problem.target);
  if (!target || !capture || !capture->floating_target) return std::nullopt;
  SimulationOptions options = sc.simulation.options;
  options.grounded = target->response == Response::Grounded;
  Simulator sim(target->model, options);
  JointControl locked;
  locked.mode = JointControl::Mode::Locked;
  for (unsigned int j = 0; j < target->model->nj(); ++j)
    if (target->response == Response::JointsLocked || (!target->locked.empty() && target->locked[j]))
      sim.setJointControl(j, locked);
  TargetMotion m;
  m.end.t = t0;
  m.end.state = target->state;
  m.end.velocity = capture->floating_target->after;
  if (options.grounded) m.end.velocity.base_twist = KDL::Twist::Zero();
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
  if (rc == E_NOERROR) rc = sim.run(m.end, t_end, sc.simulation.output_step, observer);
  if (rc || observer_rc)
    throw InputError(sc.file + ": the target's motion after the impact failed at t = " + detail::number(m.end.t) +
                     " s: " + strError(rc ? rc : observer_rc));
  return m;
}

/// The target's joints in the joined model, by their name there, and the sign of their coordinate
/// (-1: reversed by the re-rooting).
Json targetSigns(const JoinedSystem& joint, const std::shared_ptr<const FloatingModel>& model) {
  Json signs = Json::object();
  for (std::size_t j = 0; j < joint.target_joints.size(); ++j)
    signs[model->jointNames()[joint.target_joints[j]]] = joint.target_joint_sign[j];
  return signs;
}

}  // namespace kdl_space::cli
