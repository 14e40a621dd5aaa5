#include "capture.hpp"

#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli_common.hpp"
#include "kdl_space/report/html_writer.hpp"
#include "inspect.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/operation/overlap_check.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::cli {
namespace {

const char* lawName(ImpactKind k) {
  switch (k) {
    case ImpactKind::Capture: return "capture (rigid 6-D grasp, eq. 24-25)";
    case ImpactKind::PointImpact: return "point impact, frictionless, Newton restitution";
    case ImpactKind::FrictionalImpact: return "point impact, Newton restitution and Coulomb friction";
    case ImpactKind::TranslationalCapture: return "translational capture (linear velocities equal, rotation free)";
  }
  return "";
}

std::string row(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s << std::setprecision(6) << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v(i);
  return s.str() + "]";
}

}  // namespace

CLI::App* addCapture(CLI::App& app, CaptureOptions& o) {
  CLI::App* cmd = app.add_subcommand("capture", "Solve the impact or capture of a scenario (YAML or JSON)");
  cmd->add_option("SCENARIO", o.scenario, "Scenario file (YAML or JSON)")->required();
  const CLI::Validator file_name(
      [](std::string& name) { return name.empty() ? std::string("the file name is empty") : std::string(); }, "");
  cmd->add_option("--scene", o.scene, "Draw the robot, the target and the contact point at the impact in 3-D (.svg or .png)")
      ->type_name("FILE")->check(file_name);
  cmd->add_option("--html", o.html,
                  "Write the impact as an interactive 3-D page (one self-contained HTML file: the robot's URDF visuals "
                  "at the impact, the target, the contact point, the grasp frame, the impulse as an arrow; before and after)")
      ->type_name("FILE")->check(file_name);
  addMeshPathOption(cmd, o.mesh_path);
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  return cmd;
}

void printWarnings(std::ostream& out, const std::vector<Diagnostic>& warnings) {
  for (const Diagnostic& d : warnings)
    out << "Warning: " << (d.element.empty() ? "" : d.element + ": ") << d.message << "\n";
}

void warnOnStderr(const std::vector<Diagnostic>& warnings) {
  for (const Diagnostic& d : warnings)
    std::cerr << "kdl_space: warning: " << (d.element.empty() ? "" : d.element + ": ") << d.message << "\n";
}

void printCaptureSummary(std::ostream& out, const Scenario& sc, const CaptureResult& r) {
  const CaptureProblem& p = sc.capture;
  const ImpactLaw& law = p.law;
  const FloatingSideResult& robot = r.robot;
  const double T0 = r.energy_before, T1 = r.energy_after;
  const std::vector<std::string>& joints = p.robot.model->jointNames();
  out << "Scenario " << sc.file << "\n";
  out << "Law: " << lawName(law.kind);
  if (law.kind == ImpactKind::PointImpact || law.kind == ImpactKind::FrictionalImpact)
    out << ", e = " << law.restitution << ", normal " << row(law.normal)
        << (law.kind == ImpactKind::FrictionalImpact ? ", mu = " + std::to_string(law.friction) : "");
  out << "\n";
  if (r.impulse.separating) out << "The bodies are already separating along the normal: no impulse.\n";
  if (law.kind == ImpactKind::FrictionalImpact && !r.impulse.separating)
    out << (r.impulse.sticking ? "Contact sticks at the end of the impact.\n" : "Contact slides at the end of the impact.\n");
  out << "Contact point " << row(r.contact_point) << " m on link '"
      << p.robot.model->bodies()[p.robot.contact.body].name << "'";
  if (const std::optional<Vector3d> in_target = pointInTargetFrame(p, r.contact_point))
    out << ", " << row(*in_target) << " m in the target's frame";
  out << "\n";
  if (sc.grasp_solution)
    out << "Grasp (robot.place: grasp): the contact frame holds robot.grasp.target_frame to "
        << sc.grasp_solution->position_residual << " m, " << sc.grasp_solution->orientation_residual << " rad ("
        << sc.grasp_solution->iterations << " iterations, " << sc.grasp_solution->attempts
        << (sc.grasp_solution->attempts == 1 ? " start)\n" : " starts)\n");
  const std::vector<std::string> braked = lockedNames(p.robot);
  if (!braked.empty()) {
    out << "Braked joints (locked at the impact, rates stay 0):";
    for (std::size_t k = 0; k < braked.size(); ++k) out << (k ? ", '" : " '") << braked[k] << "'";
    out << "\n";
  }
  out << "Impulse on the robot (f; n) [N s; N m s]: " << row(r.impulse.F) << "\n";
  out << "Robot contact twist (v; w): before " << row(robot.contact_twist_before) << "\n"
      << "                            after  " << row(robot.contact_twist_after) << "\n";
  out << "Target twist at its CoM:    before " << row(r.target_twist_before) << "\n"
      << "                            after  " << row(r.target_twist_after) << "\n";
  out << "Base twist:                 before " << row(toEigen(robot.before.base_twist)) << "\n"
      << "                            after  " << row(toEigen(robot.after.base_twist)) << "\n"
      << "                            jump   "
      << row(toEigen(robot.after.base_twist) - toEigen(robot.before.base_twist)) << "\n";
  printMatrix(out, "Joint rates [rad/s or m/s]",
              (Eigen::MatrixXd(joints.size(), 3) << robot.before.qdot.data, robot.after.qdot.data,
               robot.after.qdot.data - robot.before.qdot.data).finished(),
              joints, {"before", "after", "jump"});
  out << "Momentum (P; L about the world origin): before " << row(r.momentum_before) << "\n"
      << "                                        after  " << row(r.momentum_after) << "\n";
  out << "Kinetic energy: before " << T0 << " J, after " << T1 << " J, lost " << T0 - T1 << " J ("
      << (T0 > 0 ? 100.0 * (T0 - T1) / T0 : 0.0) << " %)\n";
  if (p.has_normal) {
    out << "Virtual mass of the robot along the normal: ";
    if (r.virtual_mass)
      out << *r.virtual_mass << " kg\n";
    else
      out << "infinite (the robot cannot move its contact point along the normal here)\n";
  }
}

void printCompliantSummary(std::ostream& out, const CompliantCaptureResult& c, const CaptureResult& r) {
  const char* ends[3] = {"caught (the grasp locked)", "opened (a bounce)", "timed out (law.max_duration)"};
  const char* rules[3] = {"", ": the relative speed fell below law.catch_tolerance",
                          ": the springs' energy passed its maximum (the hand stopped closing)"};
  out << "\nCompliant contact (law.type compliant; the impulsive capture above is its limit):\n"
      << "  end " << ends[static_cast<int>(c.end)] << rules[static_cast<int>(c.catch_rule)] << " after " << c.duration << " s (" << c.history.size()
      << " samples, " << c.steps << " steps)\n"
      << "  peak force " << c.peak_force << " N, peak moment " << c.peak_moment << " N m\n"
      << "  impulse (f; n)   " << row(c.impulse) << "\n"
      << "  impulsive        " << row(r.impulse.F) << "\n"
      << "  energy dissipated " << c.dissipated << " J, locked in the springs " << c.spring_energy
      << " J, taken by the lock " << c.lock_loss << " J\n";
}

void runCapture(const CaptureOptions& o, std::ostream& out) {
  // An output that cannot be written is refused before any work.
  if (!o.scene.empty()) {
    namespace fs = std::filesystem;
    sceneTerminal(o.scene);
    checkOutputFile(o.scene, "--scene");
    refuseOverwritingInputs("--scene", o.scene, {{"the scenario file", o.scenario}});
    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0)
      throw InputError("--scene " + o.scene + ": gnuplot is not installed (Debian package gnuplot-nox; tools/deps.sh installs it)");
  }
  if (!o.html.empty()) {
    checkHtmlLibrary("--html", o.html);
    checkOutputFile(o.html, "--html");
    refuseOverwritingInputs("--html", o.html, {{"the scenario file", o.scenario}});
    std::error_code ec;
    if (!o.scene.empty() && (o.html == o.scene || std::filesystem::equivalent(o.html, o.scene, ec)))
      throw UsageError("--html and --scene name the same file " + o.html);
  }
  const Scenario sc = loadScenario(o.scenario);
  std::vector<InputFile> inputs = scenarioInputs(sc);  // the URDFs it names too
  const std::vector<std::string> mesh_search_path = meshSearchPath(o.mesh_path);
  if (!o.html.empty())  // and the meshes the page embeds
    for (InputFile& mesh : meshInputs(sc, mesh_search_path)) inputs.push_back(std::move(mesh));
  refuseOverwritingInputs("--scene", o.scene, inputs);
  refuseOverwritingInputs("--html", o.html, inputs);
  if (!sc.impact)
    throw InputError(sc.file + ": a plain motion (no target, no law): there is no impact to solve; run kdl_space simulate");
  if (sc.approach)
    throw InputError(sc.file + ": approach: the contact instant comes from the approach's motion; run kdl_space "
                     "simulate (it solves the capture then), or remove the approach section to solve the impact "
                     "at the scenario's states");
  stopIfInterrupted("capture " + sc.file + ": after loading it");
  const CaptureResult result = inScenario(sc, [&] { return solveCapture(sc.capture); });
  stopIfInterrupted("capture " + sc.file + ": after solving the capture");
  std::optional<CompliantCaptureResult> compliant;
  if (sc.compliant)
    compliant = inScenario(sc, [&] {
      return solveCompliantCapture(sc.capture, *sc.compliant);
    });
  stopIfInterrupted("capture " + sc.file + ": after solving it");
  if (!o.scene.empty()) {
    AtomicFile scene(o.scene, "--scene");
    writeScene(scene, {impactSnapshot(sc)},
               "kdl_space capture " + std::filesystem::path(sc.file).filename().string());
    scene.commit();
  }
  std::vector<Diagnostic> mesh_warnings;  // the page's meshes drawn as boxes (on stderr too)
  if (!o.html.empty()) {
    AtomicFile page(o.html, "--html");
    mesh_warnings = writeCaptureHtml(page, sc, result, "kdl_space capture " + std::filesystem::path(sc.file).filename().string(),
                     mesh_search_path);
    warnOnStderr(mesh_warnings);
    page.commit();
  }
  const std::vector<Diagnostic> warnings = captureWarnings(sc, sc.capture);
  if (!o.json) warnOnStderr(warnings);  // the JSON carries them; its runs keep stderr for errors
  if (o.json) {
    Json j = captureJson(sc, result);
    j["scene"] = o.scene.empty() ? Json(nullptr) : Json(o.scene);
    j["html"] = o.html.empty() ? Json(nullptr) : Json(o.html);  // the page (--html), or null
    std::vector<Diagnostic> all = warnings;
    all.insert(all.end(), mesh_warnings.begin(), mesh_warnings.end());
    j["warnings"] = warningsJson(all);
    if (compliant) j["compliant"] = compliantJson(*compliant);  // beside the impulsive capture
    out << jsonText(j, 2) << "\n";
  } else {
    printCaptureSummary(out, sc, result);
    if (compliant) printCompliantSummary(out, *compliant, result);
    printWarnings(out, warnings);
    if (!o.scene.empty()) out << "Scene: " << o.scene << "\n";
    if (!o.html.empty()) out << "Page: " << o.html << " (open it in a browser)\n";
  }
}

}  // namespace kdl_space::cli
