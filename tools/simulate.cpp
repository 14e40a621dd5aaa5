#include "simulate.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "capture.hpp"
#include "cli_common.hpp"

namespace kdl_space::cli {
namespace {

namespace fs = std::filesystem;

/// A scratch file removed when it goes out of scope (gnuplot's data, script and log).
class ScratchFile {
 public:
  explicit ScratchFile(std::string path) : path_(std::move(path)) {}
  ~ScratchFile() { std::remove(path_.c_str()); }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The model moving after the impact: the robot with the target merged into the contact link
/// after a rigid capture, the robot alone after a point impact (the target separates).
std::shared_ptr<const FloatingModel> modelAfter(const Scenario& sc, const CaptureRun& run) {
  switch (sc.law.kind) {
    case ImpactKind::PointImpact:
    case ImpactKind::FrictionalImpact:
      return sc.robot.model;
    case ImpactKind::TranslationalCapture:
      throw InputError(sc.file + ": law.type: simulate does not model a translational capture (the target would "
                       "turn freely about the contact point, a spherical joint); `capture` solves its impact");
    case ImpactKind::Capture:
      break;
  }
  if (!sc.rigid_target)
    throw InputError(sc.file + ": target.urdf: simulate does not join two free-floating systems into one after a "
                     "capture yet; `capture` solves the impact");
  // The target's inertia in the contact link's frame at the capture instant.
  const RigidBody& b = *sc.rigid_target;
  const KDL::Frame& world_T_link = run.robot_solver->bodyPose(sc.robot.contact.body);
  const Matrix3d R = toEigen(world_T_link.M);
  const Matrix3d I = R.transpose() * b.I_com * R;
  const KDL::Vector com = world_T_link.Inverse() * toKDL(b.com);
  try {
    return std::make_shared<const FloatingModel>(sc.robot.model->withPayload(
        sc.robot.contact_link,
        KDL::RigidBodyInertia(b.mass, com, KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)))));
  } catch (const ModelError& e) {
    throw InputError(sc.file + ": target: cannot attach the captured target to link '" + sc.robot.contact_link +
                     "': " + e.what());
  }
}

/// One output row.
struct Sample {
  double t;
  Vector3d p;
  Eigen::Vector4d quat;  // x y z w
  Vector6d twist;
  Eigen::VectorXd q, qd;
  Vector6d h;
  double T;
};

void writeCsvHeader(std::ostream& os, const std::vector<std::string>& joints) {
  os << "t,base_x,base_y,base_z,base_qx,base_qy,base_qz,base_qw,base_vx,base_vy,base_vz,base_wx,base_wy,base_wz";
  for (const auto& j : joints) os << ",q_" << j;
  for (const auto& j : joints) os << ",qdot_" << j;
  os << ",P_x,P_y,P_z,L_x,L_y,L_z,kinetic_energy\n";
}

void writeCsvRow(std::ostream& os, const Sample& s) {
  os << s.t;
  for (int i = 0; i < 3; ++i) os << ',' << s.p(i);
  for (int i = 0; i < 4; ++i) os << ',' << s.quat(i);
  for (int i = 0; i < 6; ++i) os << ',' << s.twist(i);
  for (Eigen::Index i = 0; i < s.q.size(); ++i) os << ',' << s.q(i);
  for (Eigen::Index i = 0; i < s.qd.size(); ++i) os << ',' << s.qd(i);
  for (int i = 0; i < 6; ++i) os << ',' << s.h(i);
  os << ',' << s.T << '\n';
}

std::string quotedPath(const std::string& p) {
  std::string q = "'";
  for (char c : p) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

/// A label for gnuplot's enhanced text: '_' and '^' printed as themselves.
std::string label(const std::string& text) {
  std::string escaped;
  for (char c : text) escaped += (c == '_' || c == '^' || c == '{' || c == '}' || c == '@' || c == '&')
                                     ? std::string("\\") + c
                                     : std::string(1, c);
  return quotedPath(escaped);
}

/// The gnuplot terminal for a plot file name; throws UsageError for another extension.
std::string plotTerminal(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".svg") return "svg size 1000,1100 dynamic font 'sans,11'";
  if (ext == ".png") return "pngcairo size 1000,1100 font 'sans,10'";
  throw UsageError("--plot " + path + ": the file name must end in .svg or .png");
}

/// Base attitude, joint angles, momentum and energy error over time, drawn by gnuplot into
/// out.tmp() (the caller commits it).
void writePlot(const AtomicFile& out, const std::vector<Sample>& samples, const std::vector<std::string>& joints,
               const std::string& title) {
  const std::string& path = out.path();
  const std::string terminal = plotTerminal(path);
  const ScratchFile data(out.tmp() + ".dat"), script(out.tmp() + ".gp"), log(out.tmp() + ".log");
  {
    std::ofstream d(data.path());
    d << std::setprecision(12);
    const Sample& s0 = samples.front();
    const double h_scale = std::max(s0.h.norm(), 1e-300);
    for (const Sample& s : samples) {
      double roll, pitch, yaw;
      KDL::Rotation::Quaternion(s.quat(0), s.quat(1), s.quat(2), s.quat(3)).GetRPY(roll, pitch, yaw);
      const double dh = (s.h - s0.h).norm(), dT = std::abs(s.T - s0.T);
      d << s.t << ' ' << roll * 180 / M_PI << ' ' << pitch * 180 / M_PI << ' ' << yaw * 180 / M_PI;
      for (Eigen::Index j = 0; j < s.q.size(); ++j) d << ' ' << s.q(j);
      // Relative errors (absolute when the initial value is zero), floored for the log axis.
      d << ' ' << std::max(s0.h.norm() > 0 ? dh / h_scale : dh, 1e-17) << ' '
        << std::max(s0.T > 0 ? dT / s0.T : dT, 1e-17) << '\n';
    }
    d.close();
    if (!d) throw InputError("--plot " + path + ": cannot write the plot's data next to it");
  }
  {
    std::ofstream g(script.path());
    g << "set terminal " << terminal << "\nset output " << quotedPath(out.tmp()) << "\n"
      << "set multiplot layout 3,1 title " << label(title) << "\n"
      << "set grid\nset key outside right\nset xlabel 'time [s]'\n"
      << "set ylabel 'base attitude [deg]'\n"
      << "plot " << quotedPath(data.path()) << " using 1:2 with lines title 'roll', '' using 1:3 with lines title 'pitch', "
      << "'' using 1:4 with lines title 'yaw'\n"
      << "set ylabel 'joint position [rad or m]'\nplot ";
    for (std::size_t j = 0; j < joints.size(); ++j)
      g << (j ? ", " : "") << (j ? "''" : quotedPath(data.path())) << " using 1:" << 5 + j << " with lines title "
        << label(joints[j]);
    if (joints.empty()) g << "0 title 'no joints'";
    const std::size_t c = 5 + joints.size();
    g << "\nset ylabel 'change since t = 0 (relative)'\nset logscale y\nset format y '10^{%L}'\n"
      << "plot " << quotedPath(data.path()) << " using 1:" << c << " with lines title 'momentum |h - h_0|', '' using 1:"
      << c + 1 << " with lines title 'kinetic energy |T - T_0|'\n"
      << "unset multiplot\n";
    g.close();
    if (!g) throw InputError("--plot " + path + ": cannot write the plot's script next to it");
  }
  const int rc =
      std::system(("gnuplot " + quotedPath(script.path()) + " >" + quotedPath(log.path()) + " 2>&1").c_str());
  std::ifstream l(log.path());
  std::stringstream why;
  why << l.rdbuf();
  std::error_code ec;
  if (rc != 0 || !fs::is_regular_file(out.tmp(), ec) || fs::file_size(out.tmp(), ec) == 0)
    throw InputError("--plot " + path + ": gnuplot failed" + (why.str().empty() ? std::string() : ": " + why.str()));
}

/// Why a simulation stopped, in the scenario's terms.
std::string simulationFailure(int rc, const SimulationSpec& spec) {
  switch (rc) {
    case E_MAX_STEPS:
      return "the step budget simulation.max_steps = " + std::to_string(spec.options.max_steps) +
             " is spent (an unstable controller? raise max_steps, or loosen rtol and atol)";
    case E_STEP_UNDERFLOW:
      return std::string(strError(rc)) + " (loosen simulation.rtol and atol)";
    case E_NOT_FINITE:
      return "the motion blew up to NaN or infinite values (unstable PD gains, or too large an rk4 step?)";
    default:
      return strError(rc);
  }
}

const char* integratorName(Integrator i) { return i == Integrator::RK4 ? "rk4" : "dopri5"; }

}  // namespace

CLI::App* addSimulate(CLI::App& app, SimulateOptions& o) {
  CLI::App* cmd = app.add_subcommand("simulate", "Solve the scenario's impact, then integrate the motion after it");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON), as for capture")->required();
  cmd->add_option("--duration", o.duration, "Seconds to simulate after the impact (default: the scenario's, else 20)")
      ->check(positiveNumber());
  const CLI::Validator file_name(
      [](std::string& name) { return name.empty() ? std::string("the file name is empty") : std::string(); }, "");
  cmd->add_option("--csv", o.csv, "Write the time history as CSV (one row per output step)")
      ->type_name("FILE")->check(file_name);
  cmd->add_option("--plot", o.plot, "Draw base attitude, joint angles and momentum/energy drift (.svg or .png)")
      ->type_name("FILE")->check(file_name);
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void runSimulate(const SimulateOptions& o, std::ostream& out) {
  // Everything that can be refused without simulating is refused first.
  if (!o.plot.empty()) plotTerminal(o.plot);
  if (!o.csv.empty()) checkOutputFile(o.csv, "--csv");
  if (!o.plot.empty()) checkOutputFile(o.plot, "--plot");
  std::error_code ec;
  if (!o.csv.empty() && !o.plot.empty() && (o.csv == o.plot || fs::equivalent(o.csv, o.plot, ec)))
    throw UsageError("--csv and --plot name the same file " + o.plot);
  for (const auto& [option, path] : {std::pair{"--csv", o.csv}, std::pair{"--plot", o.plot}})
    if (!path.empty() && fs::equivalent(path, o.scenario, ec))
      throw UsageError(std::string(option) + " " + path + ": is the scenario file; it would be overwritten");
  if (!o.plot.empty() && std::system("command -v gnuplot >/dev/null 2>&1") != 0)
    throw InputError("--plot " + o.plot + ": gnuplot is not installed (Debian package gnuplot-nox; tools/deps.sh installs it)");

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
  const CaptureRun capture = solveCapture(sc);
  const std::shared_ptr<const FloatingModel> model = modelAfter(sc, capture);

  std::unique_ptr<Simulator> simulator;
  try {
    simulator = std::make_unique<Simulator>(model, spec.options);
    for (const auto& [joint, control] : spec.joints) simulator->setJointControl(joint, control);
  } catch (const ModelError& e) {
    throw InputError(sc.file + ": " + e.what());
  }
  Simulator& sim = *simulator;
  SimulationState s;
  s.state = sc.robot.state;
  s.velocity = capture.robot->after();
  if (const int rc = sim.engageBrakes(s)) throw InputError(sc.file + ": simulation: cannot engage the brakes: " + strError(rc));

  const std::vector<std::string>& joints = model->jointNames();
  std::vector<Sample> samples;
  std::unique_ptr<AtomicFile> csv_file, plot_file;
  std::ofstream csv;
  if (!o.csv.empty()) {
    csv_file = std::make_unique<AtomicFile>(o.csv, "--csv");
    csv.open(csv_file->tmp());
    if (!csv) throw InputError("--csv " + o.csv + ": cannot write in its folder");
    csv << std::setprecision(17);
    writeCsvHeader(csv, joints);
  }
  int observer_rc = E_NOERROR;
  const auto observer = [&](const SimulationState& x) {
    Sample smp;
    smp.t = x.t;
    smp.p = toEigen(x.state.world_T_base.p);
    x.state.world_T_base.M.GetQuaternion(smp.quat(0), smp.quat(1), smp.quat(2), smp.quat(3));
    smp.twist = toEigen(x.velocity.base_twist);
    smp.q = x.state.q.data;
    smp.qd = x.velocity.qdot.data;
    if (const int rc = sim.energyAndMomentum(x, smp.T, smp.h)) observer_rc = rc;
    if (csv.is_open()) writeCsvRow(csv, smp);
    samples.push_back(std::move(smp));
  };
  const int rc = sim.run(s, duration, spec.output_step, observer);
  if (rc || observer_rc) {
    std::ostringstream why;
    why << sc.file << ": simulation failed at t = " << s.t << " s of " << duration << " s: "
        << simulationFailure(rc ? rc : observer_rc, spec);
    throw InputError(why.str());  // the temporaries are removed: no file is left
  }
  if (csv.is_open()) {
    csv.close();
    if (!csv) throw InputError("--csv " + o.csv + ": write failed (disk full?)");
  }
  if (!o.plot.empty()) {
    plot_file = std::make_unique<AtomicFile>(o.plot, "--plot");
    writePlot(*plot_file, samples, joints, "kdl_space simulate " + fs::path(sc.file).filename().string());
  }
  // Every output is complete: give them their names (a failed rename takes the other back).
  if (csv_file) csv_file->commit();
  if (plot_file) {
    try {
      plot_file->commit();
    } catch (const InputError&) {
      if (csv_file) csv_file->retract();
      throw;
    }
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
  if (o.json) {
    Json j;
    j["capture"] = captureJson(sc, capture);
    Json final_state{{"t", last.t},
                     {"base_position", toJson(last.p)},
                     {"base_quaternion", toJson(last.quat)},
                     {"base_twist", toJson(last.twist)},
                     {"q", toJson(last.q)},
                     {"qdot", toJson(last.qd)}};
    j["simulation"] = Json{{"duration", duration},
                           {"integrator", integratorName(spec.options.integrator)},
                           {"accepted_steps", sim.stats().accepted_steps},
                           {"rejected_steps", sim.stats().rejected_steps},
                           {"payload_attached", model != sc.robot.model},
                           {"joint_names", joints},
                           {"final", final_state},
                           {"max_linear_momentum_change", dP},
                           {"max_angular_momentum_change", dL},
                           {"max_energy_change", dT},
                           {"energy", first.T},
                           {"csv", o.csv.empty() ? Json(nullptr) : Json(o.csv)},
                           {"plot", o.plot.empty() ? Json(nullptr) : Json(o.plot)}};
    out << j.dump(2) << "\n";
    return;
  }
  printCaptureSummary(out, sc, capture);
  out << "\nAfter the impact: " << (model != sc.robot.model ? "the target is attached to link '" + sc.robot.contact_link + "'"
                                                              : std::string("the target separates; the robot alone"))
      << ", " << duration << " s with " << integratorName(spec.options.integrator) << " ("
      << sim.stats().accepted_steps << " steps, " << sim.stats().rejected_steps << " rejected)\n";
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
  if (!o.csv.empty()) out << "CSV: " << o.csv << "\n";
  if (!o.plot.empty()) out << "Plot: " << o.plot << "\n";
}

}  // namespace kdl_space::cli
