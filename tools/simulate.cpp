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
#include "capture_operation.hpp"
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
      if (other != option && !other_path.empty() && (path == other_path || fs::equivalent(path, other_path, ec)))
        throw UsageError(std::string(option) + " and " + other + " name the same file " + path);
  }
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
