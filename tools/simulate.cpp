#include "simulate.hpp"

#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include "capture.hpp"
#include "cli_common.hpp"
#include "csv_writer.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "operation_report.hpp"
#include "plot_writer.hpp"
#include "scene_writer.hpp"

namespace kdl_space::cli {
namespace {

namespace fs = std::filesystem;

/// Everything that can be refused without simulating is refused first: the outputs' terminals,
/// files that cannot be written, the scenario or another output named twice, gnuplot missing.
void checkOutputs(const SimulateOptions& o) {
  if (!o.plot.empty()) plotTerminal(o.plot);
  if (!o.scene.empty()) sceneTerminal(o.scene, 3);
  const std::pair<const char*, std::string> outputs[] = {{"--csv", o.csv}, {"--plot", o.plot}, {"--scene", o.scene}};
  std::error_code ec;
  for (const auto& [option, path] : outputs) {
    if (path.empty()) continue;
    checkOutputFile(path, option);
    refuseOverwritingInputs(option, path, {{"the scenario file", o.scenario}});
    for (const auto& [other, other_path] : outputs)
      if (other != option && !other_path.empty() && (path == other_path || fs::equivalent(path, other_path, ec)))
        throw UsageError(std::string(option) + " and " + other + " name the same file " + path);
  }
  for (const auto& [option, path] : outputs)
    if (!path.empty() && std::string(option) != "--csv" && std::system("command -v gnuplot >/dev/null 2>&1") != 0)
      throw InputError(std::string(option) + " " + path +
                       ": gnuplot is not installed (Debian package gnuplot-nox; tools/deps.sh installs it)");
}

std::string title(const Scenario& sc) { return "kdl_space simulate " + fs::path(sc.file).filename().string(); }

/// An approach that never reached its grasp: what happened is written out (the CSV, the plot)
/// before the run is refused.
void writeApproachOutputs(const SimulateOptions& o, const Scenario& sc, const OperationResult& partial) {
  const std::vector<std::string>& joints = sc.capture.robot.model->jointNames();
  if (!o.csv.empty()) {
    CsvWriter csv(o.csv, joints, sc.simulation.base_control.on());
    for (const MotionSample& x : partial.approach_samples) csv.write(x);
    csv.close();
    csv.file().commit();
  }
  if (!o.plot.empty()) {
    AtomicFile plot(o.plot, "--plot");
    writePlot(plot, partial.approach_samples, joints, title(sc) + ": the approach", true);
    plot.commit();
  }
}

/// The plot and the scene of a finished run, under temporary names; then every output gets its
/// name (a failed rename takes the others back).
void writeOutputs(const SimulateOptions& o, const Scenario& sc, const OperationResult& r, std::optional<CsvWriter>& csv) {
  if (csv) csv->close();
  std::unique_ptr<AtomicFile> plot_file, scene_file;
  if (!o.plot.empty()) {
    plot_file = std::make_unique<AtomicFile>(o.plot, "--plot");
    std::vector<MotionSample> all = r.approach_samples;
    all.insert(all.end(), r.samples.begin(), r.samples.end());
    writePlot(*plot_file, all, r.model->jointNames(), title(sc), r.record.torques || r.approach,
              sc.impact && r.approach ? r.t_capture : std::numeric_limits<double>::quiet_NaN());
  }
  if (!o.scene.empty()) {
    scene_file = std::make_unique<AtomicFile>(o.scene, "--scene");
    writeScene(*scene_file, sceneSnapshots(sc, r), title(sc), "--scene");
  }
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
  checkOutputs(o);
  const Scenario sc = loadScenario(o.scenario);
  for (const auto& [option, path] : {std::pair<const char*, const std::string&>{"--csv", o.csv}, {"--plot", o.plot}, {"--scene", o.scene}})
    refuseOverwritingInputs(option, path, scenarioInputs(sc));  // the URDFs it names too
  OperationOptions options;
  options.duration = o.duration;
  options.keep_samples = !o.plot.empty();  // the plot draws them all; the CSV is written as they come
  std::optional<CsvWriter> csv;
  if (!o.csv.empty())
    options.observer = [&](const OperationResult& so_far, const MotionSample& x) {
      if (!csv) csv.emplace(o.csv, so_far.model->jointNames(), sc.simulation.base_control.on());
      csv->write(x);
    };
  OperationResult r;
  try {
    r = runCaptureOperation(sc, options);
  } catch (const OperationError& e) {
    if (e.partial() && e.partial()->approach && !e.partial()->approach->record.reached) writeApproachOutputs(o, sc, *e.partial());
    throw;  // the temporaries are removed: no file is left
  }
  writeOutputs(o, sc, r, csv);
  const OperationFiles files{o.csv, o.plot};
  if (o.json)
    out << operationJson(sc, r, files).dump(2) << "\n";
  else
    printOperation(out, sc, r, files);
}

}  // namespace kdl_space::cli
