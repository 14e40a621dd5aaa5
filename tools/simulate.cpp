#include "simulate.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <optional>
#include <sstream>

#include "approach_report.hpp"
#include "capture.hpp"
#include "kdl_space/joined_system.hpp"
#include "cli_common.hpp"
#include "csv_writer.hpp"
#include "detail/text.hpp"
#include "motion_report.hpp"
#include "plot_writer.hpp"
#include "scene_writer.hpp"

namespace kdl_space::cli {
namespace {

namespace fs = std::filesystem;

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
      const std::vector<std::string>& joints = r.sim.model().jointNames();
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

const char* integratorName(Integrator i) {
  return i == Integrator::RK4 ? "rk4" : i == Integrator::Rosenbrock ? "rosenbrock" : "dopri5";
}

/// A name of the robot's model resolved in `model` (the same model, or the robot with a payload).
unsigned int jointIn(const FloatingModel& model, const FloatingModel& robot, unsigned int j) {
  return static_cast<unsigned int>(model.jointIndex(robot.jointNames()[j]));
}

/// The simulator as the scenario says: the robot's mode holds through the motion (a grounded base
/// stays grounded, braked joints stay braked) unless the simulation section changes it. For the
/// approach (`approach`), the joints are left free for its velocity servo (the simulation
/// section's joint controls act after the capture).
std::unique_ptr<Simulator> makeSimulator(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                         bool approach = false) {
  const SimulationSpec& spec = sc.simulation;
  const FloatingSystem& robot = sc.capture.robot;
  SimulationOptions options = spec.options;
  options.grounded = spec.grounded.value_or(robot.response == Response::Grounded);
  auto sim = std::make_unique<Simulator>(model, options);
  JointControl locked;
  locked.mode = JointControl::Mode::Locked;
  for (unsigned int j = 0; j < robot.model->nj(); ++j)
    if (robot.response == Response::JointsLocked || (!robot.locked.empty() && robot.locked[j]))
      sim->setJointControl(jointIn(*model, *robot.model, j), locked);
  if (!approach)
    for (const auto& [joint, control] : spec.joints) sim->setJointControl(jointIn(*model, *robot.model, joint), control);
  for (const auto& [joint, mode] : spec.limits) sim->setLimitMode(jointIn(*model, *robot.model, joint), mode);
  sim->setBaseControl(spec.base_control);
  for (ScheduledWrench w : spec.wrenches) {
    w.body = static_cast<unsigned int>(model->bodyIndex(robot.model->bodies()[w.body].name));
    sim->addWrench(w);
  }
  return sim;
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
struct TargetMotion {
  SimulationState end;
  double dP = 0.0, dL = 0.0, T = 0.0;  ///< momentum drift over the run, kinetic energy after the impact
};
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

}  // namespace

CLI::App* addSimulate(CLI::App& app, SimulateOptions& o) {
  CLI::App* cmd = app.add_subcommand("simulate", "Solve the scenario's impact, then integrate the motion after it (or the robot's plain motion)");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON), as for capture")->required();
  cmd->add_option("--duration", o.duration, "Seconds to simulate after the impact (default: the scenario's, else 20)")
      ->check(positiveNumber());
  const CLI::Validator file_name(
      [](std::string& name) { return name.empty() ? std::string("the file name is empty") : std::string(); }, "");
  cmd->add_option("--csv", o.csv, "Write the time history as CSV (one row per output step)")
      ->type_name("FILE")->check(file_name);
  cmd->add_option("--plot", o.plot, "Draw base attitude, joint angles (and torques), momentum and energy balance (.svg or .png)")
      ->type_name("FILE")->check(file_name);
  cmd->add_option("--scene", o.scene, "Draw the scene in 3-D at the start, at the contact and at the end (.svg or .png)")
      ->type_name("FILE")->check(file_name);
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void runSimulate(const SimulateOptions& o, std::ostream& out) {
  // Everything that can be refused without simulating is refused first.
  if (!o.plot.empty()) plotTerminal(o.plot);
  if (!o.scene.empty()) sceneTerminal(o.scene, 3);
  const std::pair<const char*, std::string> outputs[] = {{"--csv", o.csv}, {"--plot", o.plot}, {"--scene", o.scene}};
  std::error_code ec;
  for (const auto& [option, path] : outputs) {
    if (path.empty()) continue;
    checkOutputFile(path, option);
    if (fs::equivalent(path, o.scenario, ec))
      throw UsageError(std::string(option) + " " + path + ": is the scenario file; it would be overwritten");
    for (const auto& [other, other_path] : outputs)
      if (other != option && path == other_path)
        throw UsageError(std::string(option) + " and " + other + " name the same file " + path);
  }
  if (!o.csv.empty() && !o.plot.empty() && fs::equivalent(o.csv, o.plot, ec))
    throw UsageError("--csv and --plot name the same file " + o.plot);
  for (const auto& [option, path] : outputs)
    if (!path.empty() && std::string(option) != "--csv" && std::system("command -v gnuplot >/dev/null 2>&1") != 0)
      throw InputError(std::string(option) + " " + path +
                       ": gnuplot is not installed (Debian package gnuplot-nox; tools/deps.sh installs it)");

  const Scenario sc = loadScenario(o.scenario);
  const SimulationSpec& spec = sc.simulation;
  const double duration = o.duration.value_or(spec.duration);
  {
    // A run that cannot fit its step budget is refused now, not after max_steps steps: every
    // step is at most max_step (dopri5) or step (rk4) long, and each output row ends a step.
    const bool rk4 = spec.options.integrator == Integrator::RK4;
    const double longest = std::min(rk4 ? spec.options.step : spec.options.max_step, spec.output_step);
    const double needed = std::ceil(duration / longest * (1.0 - 1e-12));
    if (needed > static_cast<double>(spec.options.max_steps)) {
      std::ostringstream why;
      why << std::setprecision(12) << sc.file << ": simulation: " << duration << " s in steps of at most " << longest << " s ("
          << (longest == spec.output_step ? "simulation.output_step" : rk4 ? "simulation.step" : "simulation.max_step")
          << ") needs " << needed << " steps, more than simulation.max_steps = " << spec.options.max_steps;
      throw InputError(why.str());
    }
  }
  CaptureProblem problem = sc.capture;  // with an approach: the states at the contact instant
  std::vector<Sample> approach_samples;
  std::optional<ApproachOutcome> approach;
  SimulationState s;
  s.state = problem.robot.state;
  s.velocity = problem.robot.velocity;
  std::optional<CsvWriter> csv;
  if (sc.approach) {
    approach = approachPhase(sc, problem, spec.output_step, approach_samples, s);
    if (!approach->record.reached) {
      // What happened is written out (the CSV, the plot) before the run is refused.
      if (!o.csv.empty()) {
        CsvWriter partial(o.csv, problem.robot.model->jointNames(), spec.base_control.on());
        for (const Sample& x : approach_samples) partial.write(x);
        partial.close();
        partial.file().commit();
      }
      if (!o.plot.empty()) {
        AtomicFile plot(o.plot, "--plot");
        writePlot(plot, approach_samples, problem.robot.model->jointNames(),
                  "kdl_space simulate " + fs::path(sc.file).filename().string() + ": the approach", true);
        plot.commit();
      }
      throw InputError(approachFailure(sc, *approach));
    }
  }
  std::optional<CaptureResult> capture;
  std::optional<JoinedSystem> joint;  // the target joined to the robot's tree
  std::shared_ptr<const FloatingModel> model = problem.robot.model;
  if (sc.impact) {
    capture = inScenario(sc, [&] { return solveCapture(problem); });
    joint = inScenario(sc, [&] {
      try {
        return joined(problem, *capture);
      } catch (const ModelError& e) {
        throw InputError(std::string("target: cannot join the captured target to the robot: ") + e.what());
      }
    });
    model = joint ? joint->model : inScenario(sc, [&] { return attachTarget(problem, *capture); });
  }
  const bool payload_attached = model != problem.robot.model;

  std::unique_ptr<Simulator> simulator = simulatorFor(sc, model, false);
  Simulator& sim = *simulator;
  const std::vector<std::string>& joints = model->jointNames();
  s.state = joint ? joint->state : problem.robot.state;
  s.velocity = joint ? joint->velocity : capture ? capture->robot.after : problem.robot.velocity;
  if (joint)  // the target keeps its own joints' modes: its brakes, the controls of target_joints
    if (const auto* target = std::get_if<FloatingSystem>(&problem.target)) {
      JointControl locked;
      locked.mode = JointControl::Mode::Locked;
      for (std::size_t j = 0; j < joint->target_joints.size(); ++j)
        if (target->response == Response::JointsLocked || (!target->locked.empty() && target->locked[j]))
          sim.setJointControl(static_cast<unsigned int>(joint->target_joints[j]), locked);
      for (auto [j, control] : spec.target_joints) {
        control.set_point *= joint->target_joint_sign[j];  // a reversed joint's coordinate is negated
        try {
          sim.setJointControl(static_cast<unsigned int>(joint->target_joints[j]), control);
        } catch (const ModelError& e) {
          throw InputError(sc.file + ": simulation.target_joints: " + e.what());
        }
      }
    }
  if (sim.options().grounded && toEigen(s.velocity.base_twist) != Vector6d::Zero()) {
    std::ostringstream why;
    why << sc.file << ": simulation: the base is grounded (held still), but its twist at the start of the motion is "
        << toEigen(s.velocity.base_twist).transpose().format(Eigen::IOFormat(6, Eigen::DontAlignCols, ", ", ", ", "", "", "[", "]"))
        << ": give robot.base.twist zero, or simulation.base: free";
    throw InputError(why.str());
  }
  for (unsigned int j = 0; j < model->nj(); ++j) {  // a hard stop holds a joint inside its limits only
    const JointProperties& p = model->jointProperties()[j];
    const double q = s.state.q(j);
    if (sim.limitModes()[j] == LimitMode::Stop && (q > p.upper || q < p.lower)) {
      std::ostringstream why;
      why << sc.file << ": simulation.limits: joint '" << joints[j] << "' starts at " << q << ", outside its limits ["
          << p.lower << ", " << p.upper << "] (a hard stop keeps it inside them): start it inside, or let its limits warn";
      throw InputError(why.str());
    }
  }
  if (const int rc = sim.engageBrakes(s)) throw InputError(sc.file + ": simulation: cannot engage the brakes: " + strError(rc));
  const SimulationState start = s;
  Stiffness stiffness;

  std::vector<Sample> samples;
  std::unique_ptr<AtomicFile> plot_file;
  if (!o.csv.empty()) csv.emplace(o.csv, joints, spec.base_control.on());
  if (model->nj() != problem.robot.model->nj())  // the target brought joints: NaN in the approach's rows
    for (Sample& x : approach_samples) {
      Eigen::VectorXd q = Eigen::VectorXd::Constant(model->nj(), NAN), qd = q, tau = q;
      for (unsigned int j = 0; j < problem.robot.model->nj(); ++j) {
        const unsigned int k = jointIn(*model, *problem.robot.model, j);
        q(k) = x.q(j), qd(k) = x.qd(j), tau(k) = x.tau(j);
      }
      x.q = q, x.qd = qd, x.tau = tau;
    }
  if (csv)
    for (const Sample& x : approach_samples) csv->write(x);
  int observer_rc = E_NOERROR;
  double chart_margin = 1.0;  // a ball joint's distance from its chart's singularity (1: at the centre)
  const auto observer = [&](const SimulationState& x) {
    Sample smp = sampleOf(sim, x, observer_rc);
    smp.phase = sc.impact ? "post" : "motion";
    if (joint && joint->grasp == GraspJoint::Spherical) chart_margin = std::min(chart_margin, sphericalChartMargin(*joint, x.state));
    if (csv) csv->write(smp);
    samples.push_back(std::move(smp));
  };
  const double t_capture = s.t;  // 0 without an approach
  const int rc = sim.run(s, t_capture + duration, spec.output_step, observer);
  const std::optional<TargetMotion> target_motion =
      rc || joint ? std::nullopt : separatedTarget(sc, problem, capture, t_capture, t_capture + duration);
  // The servos' stiffness at the start, with the friction's regularisation of the run.
  if (const int src = sim.stiffness(start, stiffness))
    throw InputError(sc.file + ": simulation: " + strError(src));
  const MotionRecord record{sim, samples, stiffness, spec.output_step, start.t, s.t};
  if (rc || observer_rc) {
    std::ostringstream why;
    why << sc.file << ": simulation failed at t = " << s.t << " s of " << duration << " s: "
        << simulationFailure(rc ? rc : observer_rc, spec, record, s);
    throw InputError(why.str());  // the temporaries are removed: no file is left
  }
  if (csv) csv->close();
  bool torques = false;  // a controller runs: something drives the joints
  for (const Sample& x : samples) torques = torques || x.tau.cwiseAbs().maxCoeff() > 0.0;
  if (!o.plot.empty()) {
    plot_file = std::make_unique<AtomicFile>(o.plot, "--plot");
    std::vector<Sample> all = approach_samples;
    all.insert(all.end(), samples.begin(), samples.end());
    writePlot(*plot_file, all, joints, "kdl_space simulate " + fs::path(sc.file).filename().string(), torques || approach,
              sc.impact && approach ? t_capture : std::numeric_limits<double>::quiet_NaN());
  }
  std::unique_ptr<AtomicFile> scene_file;
  if (!o.scene.empty()) {
    scene_file = std::make_unique<AtomicFile>(o.scene, "--scene");
    writeScene(*scene_file, sceneSnapshots(sc, problem, capture, joint.has_value(), model, s, t_capture,
                                            target_motion ? &target_motion->end : nullptr),
               "kdl_space simulate " + fs::path(sc.file).filename().string(), "--scene");
  }
  // Every output is complete: give them their names (a failed rename takes the others back).
  if (csv) csv->file().commit();
  try {
    if (plot_file) plot_file->commit();
    try {
      if (scene_file) scene_file->commit();
    } catch (const InputError&) {
      if (plot_file) plot_file->retract();
      throw;
    }
  } catch (const InputError&) {
    if (csv) csv->file().retract();
    throw;
  }

  // Drift of the invariants over the run (no external force unless gravity is set).
  const Sample& first = samples.front();
  double dP = 0.0, dL = 0.0, dT = 0.0;
  for (const Sample& x : samples) {
    dP = std::max(dP, (x.h.head<3>() - first.h.head<3>()).norm());
    dL = std::max(dL, (x.h.tail<3>() - first.h.tail<3>()).norm());
    dT = std::max(dT, std::abs(x.T - first.T));
  }
  const Sample& last = samples.back();
  std::vector<std::string> locked_joints;
  for (unsigned int j = 0; j < model->nj(); ++j)
    if (sim.jointControls()[j].mode == JointControl::Mode::Locked) locked_joints.push_back(joints[j]);
  if (o.json) {
    Json j;
    j["capture"] = capture ? captureJson(sc, *capture) : Json(nullptr);
    j["approach"] = approach ? approachJson(sc, *approach) : Json(nullptr);
    if (target_motion) {  // a free-floating target that separated: its own motion
      const SimulationState& e = target_motion->end;
      Eigen::Vector4d quat;
      e.state.world_T_base.M.GetQuaternion(quat(0), quat(1), quat(2), quat(3));
      j["target_motion"] = Json{{"final", Json{{"t", e.t},
                                               {"base_position", toJson(toEigen(e.state.world_T_base.p))},
                                               {"base_quaternion", toJson(quat)},
                                               {"base_twist", toJson(toEigen(e.velocity.base_twist))},
                                               {"q", toJson(e.state.q.data)},
                                               {"qdot", toJson(e.velocity.qdot.data)}}},
                                {"joint_names", std::get<FloatingSystem>(problem.target).model->jointNames()},
                                {"energy", target_motion->T},
                                {"max_linear_momentum_change", target_motion->dP},
                                {"max_angular_momentum_change", target_motion->dL}};
    } else {
      j["target_motion"] = nullptr;
    }
    Json final_state{{"t", last.t},
                     {"base_position", toJson(last.p)},
                     {"base_quaternion", toJson(last.quat)},
                     {"base_twist", toJson(last.twist)},
                     {"q", toJson(last.q)},
                     {"qdot", toJson(last.qd)}};
    const auto [balance_P, balance_L] = momentumBalance(samples);
    j["simulation"] = Json{{"duration", duration},
                           {"integrator", integratorName(spec.options.integrator)},
                           {"accepted_steps", sim.stats().accepted_steps},
                           {"rejected_steps", sim.stats().rejected_steps},
                           {"payload_attached", payload_attached},
                           {"target_joined", joint ? Json{{"grasp", joint->grasp == GraspJoint::Rigid ? "rigid" : "spherical"},
                                                          {"target_prefix", joint->target_prefix},
                                                          {"target_joint_signs", targetSigns(*joint, model)},
                                                          {"min_chart_margin", chart_margin}}
                                                   : Json(nullptr)},
                           {"joint_names", joints},
                           {"joints_treated_as_fixed", fixedJointsJson(*model)},
                           {"final", final_state},
                           {"max_linear_momentum_change", dP},
                           {"max_angular_momentum_change", dL},
                           {"max_energy_change", dT},
                           {"energy", first.T},
                           {"csv", o.csv.empty() ? Json(nullptr) : Json(o.csv)},
                           {"plot", o.plot.empty() ? Json(nullptr) : Json(o.plot)},
                           {"base", sim.options().grounded ? "grounded" : "free"},
                           {"locked_joints", locked_joints},
                           {"momentum_balance_error", sim.options().grounded
                                                          ? Json(nullptr)
                                                          : Json{{"linear", balance_P}, {"angular", balance_L}}},
                           {"limit_violations", limitViolationsJson(record)},
                           {"saturation", saturationJson(record)},
                           {"energy_split", energySplitJson(record)},
                           {"base_control", baseControlJson(record)},
                           {"stiffness", stiffnessJson(record)},
                           {"friction", frictionJson(record)}};
    out << j.dump(2) << "\n";
    return;
  }
  if (approach) printApproach(out, sc, *approach);
  if (capture) {
    printCaptureSummary(out, sc, *capture);
    const std::string& contact_link = problem.robot.model->bodies()[problem.robot.contact.body].name;
    out << "\nAfter the impact: "
        << (joint ? "the target joins the robot's tree at link '" + contact_link + "' by a " +
                        (joint->grasp == GraspJoint::Rigid ? "fixed joint" : "ball joint (grasp_rz, grasp_ry, grasp_rx)")
            : payload_attached ? "the target is attached to link '" + contact_link + "'"
            : target_motion    ? std::string("the target separates; both move on")
                               : std::string("the target separates; the robot alone"));
  } else {
    out << "Plain motion of " << sc.robot_urdf << " from its initial state (no impact)";
  }
  out << ", " << duration << " s with " << integratorName(spec.options.integrator) << " ("
      << sim.stats().accepted_steps << " steps, " << sim.stats().rejected_steps << " rejected)"
      << (sim.options().grounded ? ", base grounded" : "") << "\n";
  if (!locked_joints.empty()) out << "Braked joints: " << locked_joints.size() << " (" << detail::listNames(locked_joints) << ")\n";
  double roll, pitch, yaw;
  KDL::Rotation::Quaternion(last.quat(0), last.quat(1), last.quat(2), last.quat(3)).GetRPY(roll, pitch, yaw);
  out << "Final base position [m]: " << last.p.transpose() << "\n"
      << "Final base attitude (roll, pitch, yaw) [deg]: " << roll * 180 / M_PI << ", " << pitch * 180 / M_PI << ", "
      << yaw * 180 / M_PI << "\n"
      << "Final base twist (v; w): " << last.twist.transpose() << "\n";
  printMatrix(out, "Joints at the end", (Eigen::MatrixXd(joints.size(), 2) << last.q, last.qd).finished(), joints,
              {"position", "rate"});
  out << "Largest change over the run: linear momentum " << dP << " N s, angular momentum " << dL
      << " N m s, kinetic energy " << dT << " J (of " << first.T << " J)\n";
  printMotionReport(out, record);
  if (target_motion)
    out << "The target after the impact: base at " << toEigen(target_motion->end.state.world_T_base.p).transpose()
        << " m at t = " << target_motion->end.t << " s; its momentum changed by at most " << target_motion->dP
        << " N s, " << target_motion->dL << " N m s\n";
  if (joint && joint->grasp == GraspJoint::Spherical && chart_margin < 0.1)
    out << "Warning: the ball joint came within " << chart_margin
        << " of its chart's singularity (|cos grasp_ry|): its angles are ill-conditioned there\n";
  if (!o.csv.empty()) out << "CSV: " << o.csv << "\n";
  if (!o.plot.empty()) out << "Plot: " << o.plot << "\n";
}

}  // namespace kdl_space::cli
