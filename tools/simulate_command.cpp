#include "simulate_command.hpp"

#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <memory>
#include <optional>

#include "cli_common.hpp"
#include "kdl_space/report/csv_writer.hpp"
#include "kdl_space/report/html_writer.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/report/operation_report.hpp"
#include "operation_text.hpp"
#include "kdl_space/report/plot_writer.hpp"
#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::cli {
namespace {

namespace fs = std::filesystem;

/// Everything that can be refused without simulating is refused first: the outputs' terminals,
/// files that cannot be written, the scenario or another output named twice, gnuplot missing.
void checkOutputs(const SimulateOptions& o) {
  if (!o.plot.empty()) plotTerminal(o.plot);
  if (!o.scene.empty()) sceneTerminal(o.scene, 3);
  if (!o.html.empty()) checkHtmlLibrary("--html", o.html);
  const std::pair<const char*, std::string> outputs[] = {
      {"--csv", o.csv}, {"--plot", o.plot}, {"--scene", o.scene}, {"--html", o.html}};
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
    if (!path.empty() && (std::string(option) == "--plot" || std::string(option) == "--scene") && std::system("command -v gnuplot >/dev/null 2>&1") != 0)
      throw InputError(std::string(option) + " " + path +
                       ": gnuplot is not installed (Debian package gnuplot-nox; tools/deps.sh installs it)");
}

std::string title(const Scenario& sc) { return "kdl_space simulate " + fs::path(sc.file).filename().string(); }

/// The run's size is known before it starts: refused (exit 2) past --max-output-rows, with what
/// to change.
void checkOutputSize(const SimulateOptions& o, const Scenario& sc, const OperationOptions& options) {
  const double rows = estimatedOutputRows(sc, options);
  if (rows <= o.max_output_rows) return;
  std::ostringstream why;
  const auto count = [&](double n) {  // digits, not 1e+07
    if (n < 1e18) why << static_cast<unsigned long long>(n); else why << n;
  };
  why << std::setprecision(6) << "simulate " << o.scenario << ": the run would give up to ";
  count(rows);
  why << " output rows (";
  if (sc.approach) why << "an approach of up to " << sc.approach->max_duration << " s (approach.max_duration) and ";
  why << options.duration.value_or(sc.simulation.duration) << " s of motion, a row every "
      << sc.simulation.output_step << " s), more than --max-output-rows ";
  count(o.max_output_rows);
  why << ": give a coarser simulation.output_step, a shorter --duration, or raise --max-output-rows";
  throw UsageError(why.str());
}

/// The files written as the samples come (the CSV's rows, the plot's data): opened at the first
/// sample, when the system's joints are known; nothing is named until every output is complete.
struct Streams {
  std::optional<CsvWriter> csv;
  std::unique_ptr<AtomicFile> plot_file;
  std::optional<PlotWriter> plot;
  std::unique_ptr<AtomicFile> html_file;
  std::optional<HtmlWriter> html;  ///< the page's frames, decimated as the samples come

  /// `visuals`: the URDF visuals the run read for --html (readPageVisuals), not read again.
  Streams(const SimulateOptions& o, const Scenario& sc, PageVisuals visuals = {}) {
    if (!o.plot.empty()) plot_file = std::make_unique<AtomicFile>(o.plot, "--plot");
    if (!o.html.empty()) {
      html_file = std::make_unique<AtomicFile>(o.html, "--html");
      html.emplace(sc, std::move(visuals));
      warnOnStderr(html->warnings());  // the meshes it draws as boxes
    }
  }
  void add(const SimulateOptions& o, const Scenario& sc, const std::vector<std::string>& joints, const MotionSample& x) {
    if (!o.csv.empty()) {
      if (!csv) {
        const long wheels = sc.base_actuators.wheels.count();
        csv.emplace(o.csv, joints, sc.simulation.base_control.on() || wheels > 0, sc.compliant.has_value(), wheels,
                    holdsTarget(sc));
      }
      csv->write(x);
    }
    if (plot_file) {
      if (!plot) plot.emplace(*plot_file, joints, &sc);
      plot->add(x);
    }
  }
};

/// An approach that never reached its grasp: what happened is written out (the CSV, the plot,
/// the page: how close it came) before the run is refused (its samples are held: at most
/// approach.max_duration's).
void writeApproachOutputs(const SimulateOptions& o, const Scenario& sc, const OperationResult& partial, Streams& out,
                          const std::string& why) {
  const std::vector<std::string>& joints = sc.capture.robot.model->jointNames();
  OperationResult so_far = partial;  // the robot alone: the system the approach moved
  so_far.model = sc.capture.robot.model;
  for (const MotionSample& x : partial.approach_samples) {
    out.add(o, sc, joints, x);
    if (out.html) out.html->add(so_far, x);
  }
  if (out.csv) out.csv->close();
  if (out.plot) out.plot->draw(title(sc) + ": the approach", true);
  if (out.html) out.html->write(*out.html_file, so_far, title(sc) + ": the approach", "The approach failed: " + why);
  if (out.csv) out.csv->file().commit();
  if (out.plot_file) out.plot_file->commit();
  if (out.html_file) out.html_file->commit();
}

/// Ctrl-C while the outputs are drawn: nothing is named.
void checkInterrupt() {
  if (interruptFlag().load()) throw Interrupted("simulate: after the run, while drawing its outputs; no output written");
}

/// The plot (from the streamed data) and the scene of a finished run, under temporary names; then
/// every output gets its name (a failed rename takes the others back).
void writeOutputs(const SimulateOptions& o, const Scenario& sc, const OperationResult& r, Streams& out) {
  if (out.csv) out.csv->close();
  if (out.plot)
    out.plot->draw(title(sc), r.record.torques || r.approach,
                   sc.impact && r.approach ? r.t_capture : std::numeric_limits<double>::quiet_NaN());
  std::unique_ptr<AtomicFile> scene_file;
  if (!o.scene.empty()) {
    scene_file = std::make_unique<AtomicFile>(o.scene, "--scene");
    writeScene(*scene_file, sceneSnapshots(sc, r), title(sc), "--scene");
  }
  if (out.html) out.html->write(*out.html_file, r, title(sc));
  checkInterrupt();
  AtomicFile* const files[] = {out.csv ? &out.csv->file() : nullptr, out.plot ? out.plot_file.get() : nullptr,
                               scene_file.get(), out.html ? out.html_file.get() : nullptr};
  std::vector<AtomicFile*> named;
  try {
    for (AtomicFile* f : files)
      if (f) {
        f->commit();
        named.push_back(f);
      }
  } catch (const InputError&) {  // a failed rename takes the others back
    for (AtomicFile* f : named) f->retract();
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
  cmd->add_option("--html", o.html,
                  "Write the run as an interactive 3-D animation: one self-contained HTML page (the robot's URDF "
                  "visuals, the target, the contact point, the hand's path, the impulse; a time line with the phases)")
      ->type_name("FILE")->check(file_name);
  addMeshPathOption(cmd, o.mesh_path);
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the summary");
  cmd->add_option("--max-output-rows", o.max_output_rows,
                  "Refuse a run that could give more output rows (samples of the approach and the motion) than this, "
                  "before it starts (default 10000000)")
      ->type_name("N")->check(positiveNumber());
  return cmd;
}

void runSimulate(const SimulateOptions& o, std::ostream& out) {
  checkOutputs(o);
  const Scenario sc = loadScenario(o.scenario);
  std::vector<InputFile> inputs = scenarioInputs(sc);  // the URDFs it names too
  // The URDFs' visuals, read once for the run: the meshes the page embeds are inputs too.
  PageVisuals visuals = o.html.empty() ? PageVisuals{} : readPageVisuals(sc, meshSearchPath(o.mesh_path));
  for (InputFile& mesh : meshInputs(visuals)) inputs.push_back(std::move(mesh));
  for (const auto& [option, path] : {std::pair<const char*, const std::string&>{"--csv", o.csv}, {"--plot", o.plot}, {"--scene", o.scene}, {"--html", o.html}})
    refuseOverwritingInputs(option, path, inputs);
  OperationOptions options;
  options.duration = o.duration;
  checkOutputSize(o, sc, options);
  options.keep_samples = false;  // the CSV and the plot's data are written as the samples come
  options.cancelled = [] { return interruptFlag().load(std::memory_order_relaxed); };
  Streams streams(o, sc, std::move(visuals));
  if (!o.csv.empty() || !o.plot.empty() || !o.html.empty())
    options.observer = [&](const OperationResult& so_far, const MotionSample& x) {
      streams.add(o, sc, so_far.model->jointNames(), x);
      if (streams.html) streams.html->add(so_far, x);
    };
  // Before the run, --json too: a start pose near a singularity otherwise shows only as a failed
  // approach, which prints no JSON.
  if (options.approach) warnOnStderr(approachStartWarnings(sc));
  OperationResult r;
  try {
    r = runCaptureOperation(sc, options);
  } catch (const OperationError& e) {
    // Ctrl-C: the temporaries go with `streams`; nothing partial is left.
    if (e.code() == E_CANCELLED) throw Interrupted(std::string(e.what()) + "; no output written");
    const bool approach_failed = e.partial() && e.partial()->approach && !e.partial()->approach->record.reached;
    if (approach_failed) writeApproachOutputs(o, sc, *e.partial(), streams, e.what());
    if (o.json && e.partial()) {  // the JSON too: the failure and what was recorded up to it (exit 3 all the same)
      OperationResult so_far = *e.partial();
      if (!so_far.model) so_far.model = sc.capture.robot.model;
      const OperationFiles written = approach_failed ? OperationFiles{o.csv, o.plot, o.html} : OperationFiles{};
      Json j = operationJson(sc, so_far, written);
      j["failure"] = Json{{"message", e.what()}, {"code", e.code()}, {"phase", approach_failed ? "approach" : "motion"}};
      out << jsonText(j, 2) << "\n";
    }
    throw;  // the temporaries are removed: no file is left
  }
  writeOutputs(o, sc, r, streams);
  if (r.capture && !o.json) warnOnStderr(captureWarnings(sc, r.at_contact));
  // What the motion found (a sampled controller's gains, a stiff servo): on stderr whatever the
  // format of stdout (they may explain a motion that then went wrong).
  warnOnStderr(r.warnings);
  // The page's meshes drawn as boxes of inertia: on stderr at the start, in the JSON's warnings too.
  if (streams.html) r.warnings.insert(r.warnings.end(), streams.html->warnings().begin(), streams.html->warnings().end());
  const OperationFiles files{o.csv, o.plot, o.html};
  if (o.json)
    out << jsonText(operationJson(sc, r, files), 2) << "\n";
  else
    printOperation(out, sc, r, files);
}

}  // namespace kdl_space::cli
