#include "study_command.hpp"

#include <cerrno>
#include <algorithm>
#include <charconv>
#include <fstream>
#include <filesystem>
#include <functional>
#include <iostream>
#include <iomanip>

#include "cli_common.hpp"
#include "kdl_space/report/html_writer.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/report/plot_writer.hpp"
#include "kdl_space/report/study_plot.hpp"
#include "kdl_space/report/study_report.hpp"
#include "kdl_space/study/study_to_table.hpp"

namespace kdl_space::cli {
namespace fs = std::filesystem;

CLI::App* addStudy(CLI::App& app, StudyOptions& o) {
  CLI::App* cmd = app.add_subcommand("study", "Run a capture study: a scenario's capture over distributions of its inputs");
  cmd->add_option("STUDY", o.study, "Study file (YAML or JSON): scenario, samples, seed, inputs (docs/studies.md)")->required();
  cmd->add_option("-o,--table", o.table, "The table (CSV); default STEM.csv, or STEM.part-i-of-N.csv for a shard")
      ->type_name("FILE");
  cmd->add_option("--threads", o.threads, "Threads (default 0: all cores)")->check(CLI::Range(0u, 4096u));
  cmd->add_option("--shard", o.shard, "Compute shard i of N (1 <= i <= N) only, for a batch scheduler's job array")
      ->type_name("i/N");
  cmd->add_option("--merge", o.merge, "Join the tables of shards (or any parts) into the whole table")->type_name("PART...");
  cmd->add_option("--chunk-size", o.chunk_size, "Samples per chunk kept on disk while the run goes (default: the study's)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100000000}));
  cmd->add_option("--plot", o.plot, "Draw a histogram of each outcome (.svg or .png)")->type_name("FILE");
  cmd->add_option("--heat-map", o.heat_map, "Draw the study's heat_map (.svg or .png)")->type_name("FILE");
  cmd->add_option("--summary", o.summary, "Write the summary as JSON")->type_name("FILE");
  cmd->add_option("--groups", o.groups,
                  "Write the per-grid-point aggregates (mean, q95, max of each outcome, P(exceeds.*)) as CSV")
      ->type_name("FILE");
  cmd->add_option("--html", o.html,
                  "Write the study's nominal sample (its scenario as written: the capture, and the study's motion "
                  "after it) as an interactive 3-D page (one self-contained HTML file)")
      ->type_name("FILE");
  addMeshPathOption(cmd, o.mesh_path);
  cmd->add_flag("--json", o.json, "Print the summary as one JSON object instead of text");
  return cmd;
}

namespace {

/// \brief The page of the study's nominal sample (`--html`): its scenario as written, the capture at
/// its states and, if the study has a motion, that motion after it (as a sample's: the servos hold
/// the capture configuration). Written under a temporary name before the study runs (a page
/// that cannot be drawn is refused before the long work); the caller commits it. A motion that
/// fails still gives its page, noted, with a warning: the study's samples may fail too.
std::unique_ptr<AtomicFile> nominalSamplePage(const Study& st, const std::string& path,
                                              const std::vector<std::string>& mesh_search_path) {
  auto file = std::make_unique<AtomicFile>(path, "--html");
  const Scenario& sc = st.scenario;
  const std::string title = "kdl_space study " + fs::path(st.file).filename().string() + ": the nominal sample";
  if (!(st.motion_duration > 0.0)) {
    const CaptureResult r = inScenario(sc, [&] { return solveCapture(sc.capture); });
    warnOnStderr(writeCaptureHtml(*file, sc, r, title, mesh_search_path));
    return file;
  }
  HtmlWriter page(sc, mesh_search_path);
  warnOnStderr(page.warnings());  // the meshes it draws as boxes
  OperationOptions o;  // what a sample's motion runs (StudyEvaluator's motionPeaks)
  o.approach = false;
  o.duration = st.motion_duration;
  o.output_step = st.motion_output_step;
  o.hold_servos = true;
  o.keep_samples = false;
  o.cancelled = [] { return interruptFlag().load(std::memory_order_relaxed); };
  o.observer = [&](const OperationResult& so_far, const MotionSample& x) { page.add(so_far, x); };
  try {
    page.write(*file, runCaptureOperation(sc, o), title);
  } catch (const OperationError& e) {
    if (e.code() == E_CANCELLED) throw Interrupted(std::string(e.what()) + "; no output written");
    if (!e.partial() || page.frames() == 0) throw;
    std::cerr << "kdl_space: warning: --html " << path << ": the nominal sample's motion failed; its page shows it "
              << "until then: " << e.what() << "\n";
    page.write(*file, *e.partial(), title, std::string("The nominal sample's motion failed: ") + e.what());
  }
  return file;
}

/// "i/N" -> (i, N), whole numbers with 1 <= i <= N (runStudyToTable checks N <= samples).
std::pair<std::uint64_t, std::uint64_t> parseShard(const std::string& text, std::uint64_t samples) {
  // Whole numbers in full (from_chars: no sign, no saturation of one too large to hold).
  const std::size_t slash = text.find('/');
  std::uint64_t a = 0, b = 0;
  const auto whole = [&](const char* from, const char* to, std::uint64_t& v) {
    const auto [end, ec] = std::from_chars(from, to, v);
    if (ec == std::errc::result_out_of_range)
      throw UsageError("--shard " + text + ": " + std::string(from, to) + " is too large: at most " +
                       std::to_string(samples) + " shards (the study's samples)");
    return from != to && ec == std::errc() && end == to;
  };
  const char* begin = text.data();
  if (slash == std::string::npos || !whole(begin, begin + slash, a) || !whole(begin + slash + 1, begin + text.size(), b) ||
      b == 0 || a < 1 || a > b)
    throw UsageError("--shard " + text + ": expected i/N with 1 <= i <= N (e.g. 2/8)");
  return {a, b};
}

void printSummary(std::ostream& out, const Study& st, const StudySummary& s, const std::string& table) {
  out << st.file << ": " << s.samples << " captures (" << s.failed << " could not be computed), seed " << st.seed
      << "; table " << table << "\n";
  for (const StudyFailure& f : s.failures)
    out << "  status " << f.status << ": " << f.count << " sample" << (f.count > 1 ? "s" : "") << ", the first " << f.first_sample
        << ": " << f.message << "\n";
  out << "\n";
  out << std::left << std::setw(28) << "outcome" << std::right;
  for (const char* h : {"min", "5%", "25%", "median", "75%", "95%", "max"}) out << std::setw(12) << h;
  out << "\n" << std::setprecision(4);
  for (const OutcomeSummary& o : s.outcomes) {
    out << std::left << std::setw(28) << o.name << std::right;
    for (const double v : {o.min, o.q05, o.q25, o.median, o.q75, o.q95, o.max}) out << std::setw(12) << v;
    out << "\n";
  }
  if (s.quantile_rank_error > 0.0)
    out << "(quantiles from a streaming sketch: each within a rank of +-" << s.quantile_rank_error
        << " of the computed samples of the exact one)\n";
  if (!s.probabilities.empty()) out << "\n";
  for (const auto& [name, p] : s.probabilities) out << "P(" << name << ") = " << p << "\n";
  const auto list = [&](const char* title, const std::vector<SampleDigest>& ds) {
    out << "\n" << title << " by " << st.objective << ":\n";
    for (const SampleDigest& d : ds) {
      out << "  sample " << d.sample << ": " << d.objective << "  (";
      for (std::size_t k = 0; k < d.inputs.size(); ++k) out << (k ? ", " : "") << d.inputs[k].first << " = " << d.inputs[k].second;
      out << ")\n";
    }
  };
  list("best (smallest)", s.best);
  list("worst (largest)", s.worst);
  const auto points = [&](const char* title, const std::vector<GridPointDigest>& ds) {
    out << "\n" << title << " by the " << st.objective_statistic << " of " << st.objective << ":\n";
    for (const GridPointDigest& d : ds) {
      out << "  grid point " << d.index << " (" << d.count << " samples): " << d.objective << "  (";
      for (std::size_t k = 0; k < d.inputs.size(); ++k) out << (k ? ", " : "") << d.inputs[k].first << " = " << d.inputs[k].second;
      out << ")\n";
    }
  };
  if (!st.objective_statistic.empty()) {
    points("best grid points (smallest)", s.best_grid_points);
    points("worst grid points (largest)", s.worst_grid_points);
  }
}

/// The files `--summary`, `--groups`, `--plot` and `--heat-map` of a whole table (each whole or not at all).
void writeSummaryFiles(const StudyOptions& o, const Study& st, const Json& json, const StudySummary& summary,
                       const std::string& table) {
  const auto text = [](const std::string& path, const char* option, const std::function<void(std::ostream&)>& write) {
    AtomicFile f(path, option);
    errno = 0;
    std::ofstream s(f.tmp());
    write(s);
    s.close();
    if (!s) throw InputError(std::string(option) + " " + path + ": cannot write the file: " + writeFailure());
    f.commit();
  };
  if (!o.summary.empty()) text(o.summary, "--summary", [&](std::ostream& s) { s << jsonText(json, 2) << "\n"; });
  if (!o.groups.empty()) text(o.groups, "--groups", [&](std::ostream& s) { writeStudyGroups(s, summary); });
  if (!o.plot.empty()) {
    AtomicFile f(o.plot, "--plot");
    writeStudyHistograms(f, st, studyColumns(st), table, summary);
    f.commit();
  }
  if (!o.heat_map.empty()) {
    AtomicFile f(o.heat_map, "--heat-map");
    writeStudyHeatMap(f, st, summary);
    f.commit();
  }
}

}  // namespace

void runStudyCommand(const StudyOptions& o, std::ostream& out) {
  if (!o.shard.empty() && !o.merge.empty()) throw UsageError("--shard and --merge: a run computes a shard or merges them, not both");
  if (!o.plot.empty()) plotTerminal(o.plot);
  const std::string map_ext = o.heat_map.size() > 4 ? o.heat_map.substr(o.heat_map.size() - 4) : "";
  if (!o.heat_map.empty() && map_ext != ".svg" && map_ext != ".png" && map_ext != ".csv")
    throw UsageError("--heat-map " + o.heat_map + ": the file name must end in .svg or .png (or .csv for its cells' data)");
  const auto study = std::make_shared<const Study>(loadStudy(o.study));
  const Study& st = *study;
  if (!o.heat_map.empty() && !st.heat_map)
    throw UsageError("--heat-map " + o.heat_map + ": the study names no heat_map (x, y, outcome) in " + st.file);
  if (!o.groups.empty() && std::none_of(st.inputs.begin(), st.inputs.end(), [](const StudyInput& in) {
        return in.distribution.kind == Distribution::Kind::Grid;
      }))
    throw UsageError("--groups " + o.groups + ": the study has no grid input (grid: [from, to, count]) to group its samples by");
  TableOptions t;
  if (!o.shard.empty()) std::tie(t.shard, t.shards) = parseShard(o.shard, st.samples);
  t.table = !o.table.empty() ? o.table
                             : fs::path(st.file).stem().string() +
                                   (t.shards ? ".part-" + std::to_string(t.shard) + "-of-" + std::to_string(t.shards) : "") + ".csv";
  t.threads = o.threads;
  t.merge = o.merge;
  t.chunk_size = o.chunk_size;
  t.cancel = &interruptFlag();
  t.note = [](const std::string& note) { std::cerr << "kdl_space: " << note << "\n"; };
  const auto [begin, end] = tableRows(st, t);  // checked before any work
  const std::string& table = t.table;
  const std::pair<const char*, std::string> outputs[] = {
      {"--table", table}, {"--plot", o.plot}, {"--heat-map", o.heat_map}, {"--summary", o.summary}, {"--groups", o.groups},
      {"--html", o.html}};
  std::error_code ec;
  std::vector<InputFile> inputs = scenarioInputs(st.scenario);  // no output replaces what the run reads
  inputs.push_back({"the study file", o.study});
  for (const std::string& part : o.merge) inputs.push_back({"one of the parts merged", part});
  const std::vector<std::string> mesh_search_path = meshSearchPath(o.mesh_path);
  if (!o.html.empty())  // the meshes the page embeds
    for (InputFile& mesh : meshInputs(st.scenario, mesh_search_path)) inputs.push_back(std::move(mesh));
  for (const auto& [option, path] : outputs) {
    if (path.empty()) continue;
    checkOutputFile(path, option);
    refuseOverwritingInputs(option, path, inputs);
  }
  if ((!o.plot.empty() || (!o.heat_map.empty() && map_ext != ".csv")) && std::system("command -v gnuplot >/dev/null 2>&1") != 0)
    throw InputError("--plot: gnuplot is not installed (Debian package gnuplot-nox; tools/deps.sh installs it)");
  std::unique_ptr<AtomicFile> page;
  if (!o.html.empty()) {
    for (const auto& [other, other_path] : outputs)  // the page in no other output's file
      if (std::string(other) != "--html" && !other_path.empty() && (o.html == other_path || fs::equivalent(o.html, other_path, ec)))
        throw UsageError("--html and " + std::string(other) + " name the same file " + o.html);
    if (!o.shard.empty() || !o.merge.empty())
      throw UsageError("--html " + o.html + ": the nominal sample's page is drawn by the whole study's run (not with --shard or --merge)");
    checkHtmlLibrary("--html", o.html);
    page = nominalSamplePage(st, o.html, mesh_search_path);
  }
  TableRun run;
  try {
    run = runStudyToTable(study, t);
  } catch (const Cancelled& e) {  // Ctrl-C: what is kept and how to resume
    throw Interrupted(e.what());
  }
  const std::string& how = run.how;
  if (t.shards) {  // a part: its rows only; the summary is the merged table's
    out << st.file << ": shard " << t.shard << "/" << t.shards << ", samples " << begin << "-" << end << " (" << how
        << ") written to " << table << "; join the shards with: kdl_space study " << st.file << " --merge PART...\n";
    return;
  }
  const StudySummary& summary = *run.summary;
  Json json = studySummaryJson(st, summary, table);
  json["html"] = o.html.empty() ? Json(nullptr) : Json(o.html);  // the nominal sample's page, or null
  writeSummaryFiles(o, st, json, summary, table);
  if (page) page->commit();
  if (o.json) {
    out << jsonText(json, 2) << "\n";
  } else {
    printSummary(out, st, summary, table);
    if (page) out << "Page of the nominal sample: " << o.html << " (open it in a browser)\n";
    out << "\n(" << how << ")\n";
  }
}

}  // namespace kdl_space::cli
