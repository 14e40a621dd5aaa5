#include "capture_command.hpp"

#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "capture_text.hpp"
#include "cli_common.hpp"
#include "kdl_space/report/html_writer.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/operation/overlap_check.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "kdl_space/report/capture_report.hpp"
#include "kdl_space/report/inspection_json.hpp"
#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::cli {

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
