#include "study.hpp"

#include <cerrno>
#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <iomanip>
#include <map>
#include <thread>

#include "capture.hpp"
#include "kdl_space/report/html_writer.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/report/plot_writer.hpp"
#include "kdl_space/report/study_plot.hpp"
#include "kdl_space/report/study_table.hpp"

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

/// "i/N" -> rows [floor((i-1) S / N), floor(i S / N)).
std::pair<std::uint64_t, std::uint64_t> shardRange(const std::string& text, std::uint64_t samples, std::uint64_t& i,
                                                   std::uint64_t& n) {
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
  if (b > samples)
    throw UsageError("--shard " + text + ": " + std::to_string(b) + " shards of " + std::to_string(samples) +
                     " samples would leave some empty");
  i = a, n = b;
  const auto cut = [&](std::uint64_t k) {
    return k * samples / n;  // <= 1e18: no overflow (samples <= 1e9)
  };
  return {cut(i - 1), cut(i)};
}

Json quantiles(const OutcomeSummary& o) {
  return Json{{"min", o.min}, {"q05", o.q05}, {"q25", o.q25}, {"median", o.median}, {"q75", o.q75},
              {"q95", o.q95}, {"max", o.max}, {"mean", o.mean}};
}

Json gridDigests(const std::vector<GridPointDigest>& list) {
  Json a = Json::array();
  for (const GridPointDigest& d : list) {
    Json inputs = Json::object();
    for (const auto& [name, value] : d.inputs) inputs[name] = value;
    a.push_back(Json{{"grid_point", d.index}, {"count", d.count}, {"objective", d.objective}, {"inputs", inputs}});
  }
  return a;
}

Json gridPointsJson(const StudySummary& s) {
  Json a = Json::array();
  for (const GridPointSummary& g : s.grid_points) {
    Json inputs = Json::object(), outcomes = Json::object(), probabilities = Json::object();
    for (const auto& [name, value] : g.inputs) inputs[name] = value;
    for (const GridPointSummary::Outcome& o : g.outcomes) outcomes[o.name] = Json{{"mean", o.mean}, {"q95", o.q95}, {"max", o.max}};
    for (const auto& [name, p] : g.probabilities) probabilities[name] = p;
    a.push_back(Json{{"grid_point", g.index}, {"inputs", inputs}, {"count", g.count}, {"failed", g.failed},
                     {"outcomes", outcomes}, {"probabilities", probabilities}});
  }
  return a;
}

Json digests(const std::vector<SampleDigest>& list) {
  Json a = Json::array();
  for (const SampleDigest& d : list) {
    Json inputs = Json::object();
    for (const auto& [name, value] : d.inputs) inputs[name] = value;
    a.push_back(Json{{"sample", d.sample}, {"objective", d.objective}, {"inputs", inputs}});
  }
  return a;
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

/// Called with each row of the table as it is written (sample order).
using RowSink = std::function<void(const std::vector<double>& row)>;

/// Copies a part's rows (each checked) into the table and the sink; Ctrl-C stops it (the table's
/// temporary is removed, what is on disk stays).
void appendPart(StudyPartReader& part, StudyTableWriter& table, const RowSink& sink, const std::string& stopped) {
  std::uint64_t n = 0;
  while (part.next()) {
    table.addLine(part.line());
    sink(part.row());
    if ((++n & 1023u) == 0 && interruptFlag()) throw Interrupted(stopped);
  }
  if (interruptFlag()) throw Interrupted(stopped);
}

/// `--merge`: the table from parts that must cover [0, samples) once, read in the order of their
/// rows (their head lines first, to check that they cover it), each row checked as it is copied.
std::string mergeParts(const std::vector<std::string>& paths, const std::string& table, const Study& st,
                       const std::vector<std::string>& columns, const RowSink& sink) {
  std::map<std::uint64_t, std::pair<std::uint64_t, std::string>> by_begin;  // begin -> end, path
  for (const std::string& p : paths) {
    const StudyPartReader part(p, st, columns);
    const std::uint64_t b = part.begin();
    if (!by_begin.emplace(b, std::make_pair(part.end(), p)).second)
      throw InputError("--merge: " + p + " and " + by_begin[b].second + " both hold the rows from " + std::to_string(b));
  }
  std::uint64_t next = 0;
  for (const auto& [b, entry] : by_begin) {
    if (b != next)
      throw InputError("--merge: " + std::string(b < next ? "the rows from " + std::to_string(b) + " (" + entry.second +
                                                                ") are also in another part"
                                                          : "rows " + std::to_string(next) + "-" + std::to_string(b) +
                                                                " are in no part (a shard is missing)"));
    next = entry.first;
  }
  if (next != st.samples)
    throw InputError("--merge: rows " + std::to_string(next) + "-" + std::to_string(st.samples) + " are in no part (a shard is missing)");
  StudyTableWriter out(table, "--table", st, columns, 0, st.samples);
  for (const auto& [b, entry] : by_begin) {
    StudyPartReader part(entry.second, st, columns);
    appendPart(part, out, sink, "interrupted while merging into " + table + ": nothing written; run the same command again");
  }
  out.commit();
  return std::to_string(paths.size()) + " parts merged";
}

/// Whether `path` is a complete part of rows [begin, end) of this study (every row and the
/// checksum read and checked).
bool wholePart(const std::string& path, const Study& st, const std::vector<std::string>& columns, std::uint64_t begin,
               std::uint64_t end) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  try {
    StudyPartReader part(path, st, columns);
    if (part.begin() != begin || part.end() != end) return false;
    while (part.next()) {
    }
    return true;
  } catch (const InputError&) {  // cut short, changed, or of another version of the study
    return false;
  }
}

/// The most chunk files a run keeps in TABLE.parts/ (a folder of more is slow to list and to remove).
constexpr std::uint64_t kMaxChunks = 1000000;

std::uint64_t chunkSize(const StudyOptions& o, const Study& st) {
  return o.chunk_size ? o.chunk_size : defaultChunkSize(st.samples);
}

/// Rows [begin, end) computed in chunks kept in TABLE.parts/ (those already there, of an
/// interrupted run, are used), then the table: the chunks concatenated in order, each checked.
std::string computeTable(const std::shared_ptr<const Study>& study, const StudyOptions& o, const std::string& table,
                         std::uint64_t begin, std::uint64_t end, const std::vector<std::string>& columns,
                         const RowSink& sink) {
  const Study& st = *study;
  const fs::path parts = table + ".parts";
  std::error_code ec;
  if (fs::is_directory(parts, ec) && wholePart(table, st, columns, begin, end)) {
    // A run killed while it removed its chunks: the table was already whole.
    StudyPartReader whole(table, st, columns);
    while (whole.next()) sink(whole.row());
    fs::remove_all(parts, ec);
    return "the table was whole; the chunks a stopped run left in " + parts.string() + " removed";
  }
  // The grid of chunks, generated as they are needed (nothing here grows with their number).
  const StudyGrid grid{begin, end, chunkSize(o, st)};
  const std::uint64_t count = grid.count();
  const auto chunkFile = [&](const StudyChunk& c) {
    return (parts / ("rows-" + std::to_string(c.begin) + "-" + std::to_string(c.end) + ".csv")).string();
  };
  fs::create_directories(parts, ec);
  if (ec) throw InputError("--table " + table + ": cannot create the folder " + parts.string() + " for the chunks");
  const auto t0 = std::chrono::steady_clock::now();
  const unsigned threads = o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<std::uint64_t> kept{0};  // from done and skip, which may run at once on two threads
  std::uint64_t computed = 0;
  kdl_space::runStudy(
      study, grid, threads,
      [&](const StudyChunk& c, const std::vector<double>& chunk_rows) {
        writeStudyPart(chunkFile(c), "--table", st, columns, c.begin, c.end, chunk_rows.data());
        ++kept;
        computed += c.end - c.begin;
      },
      &interruptFlag(),
      [&](const StudyChunk& c) {  // a chunk already on disk, whole (of an interrupted run)
        const bool whole = wholePart(chunkFile(c), st, columns, c.begin, c.end);
        kept += whole;
        return whole;
      });
  const std::string resume = std::to_string(kept.load()) + " of " + std::to_string(count) + " chunks kept in " +
                             parts.string() + "; run the same command again to resume";
  if (interruptFlag()) throw Interrupted(resume);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  StudyTableWriter out(table, "--table", st, columns, begin, end);
  for (std::uint64_t k = 0; k < count; ++k) {
    const StudyChunk c = grid.chunk(k);
    StudyPartReader part(chunkFile(c), st, columns);
    if (part.begin() != c.begin || part.end() != c.end)
      throw InputError(chunkFile(c) + ": holds rows " + std::to_string(part.begin()) + "-" + std::to_string(part.end()) +
                       ", not those its name says; remove it and run the same command again");
    appendPart(part, out, sink, "interrupted while writing " + table + ": " + resume);
  }
  out.commit();
  fs::remove_all(parts, ec);
  std::ostringstream h;
  h << computed << " computed on " << threads << " thread" << (threads > 1 ? "s" : "") << " in " << std::setprecision(3)
    << seconds << " s";
  if (computed < end - begin) h << ", " << (end - begin - computed) << " resumed from " << parts.string();
  return h.str();
}

}  // namespace

void writeStudyGroups(std::ostream& out, const StudySummary& s) {
  if (s.grid_points.empty()) return;
  const GridPointSummary& first = s.grid_points.front();
  for (const auto& [name, v] : first.inputs) out << name << ",";
  out << "count,failed";
  for (const GridPointSummary::Outcome& o : first.outcomes) out << "," << o.name << ".mean," << o.name << ".q95," << o.name << ".max";
  for (const auto& [name, p] : first.probabilities) out << ",P(" << name << ")";
  out << "\n";
  char buf[32];
  const auto number = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.17g", v);  // reads back exactly, as the table's
    return buf;
  };
  for (const GridPointSummary& g : s.grid_points) {
    for (const auto& [name, v] : g.inputs) out << number(v) << ",";
    out << g.count << "," << g.failed;
    for (const GridPointSummary::Outcome& o : g.outcomes)
      for (const double v : {o.mean, o.q95, o.max}) out << "," << number(v);
    for (const auto& [name, p] : g.probabilities) out << "," << number(p);
    out << "\n";
  }
}

Json studySummaryJson(const Study& st, const StudySummary& s, const std::string& table) {
  Json outcomes = Json::object(), probabilities = Json::object(), failures = Json::array();
  for (const OutcomeSummary& o : s.outcomes) outcomes[o.name] = quantiles(o);
  for (const auto& [name, p] : s.probabilities) probabilities[name] = p;
  for (const StudyFailure& f : s.failures)
    failures.push_back(Json{{"status", f.status}, {"count", f.count}, {"first_sample", f.first_sample}, {"message", f.message}});
  Json grid_inputs = Json::array();
  for (const StudyInput& in : st.inputs)
    if (in.distribution.kind == Distribution::Kind::Grid) grid_inputs.push_back(in.name);
  Json j{{"study", st.file},       {"fingerprint", fingerprintText(st)},          {"table", table},
         {"samples", s.samples},   {"failed", s.failed},         {"seed", st.seed},
         {"outcomes", outcomes},   {"probabilities", probabilities}, {"objective", st.objective},
         {"best", digests(s.best)}, {"worst", digests(s.worst)}, {"failures", failures},
         {"quantile_rank_error", s.quantile_rank_error},
         {"grid_inputs", grid_inputs}, {"grid_points", gridPointsJson(s)}};
  if (!st.objective_statistic.empty()) {  // the grid points ranked (a plain objective ranks samples only)
    j["objective_statistic"] = st.objective_statistic;
    j["best_grid_points"] = gridDigests(s.best_grid_points);
    j["worst_grid_points"] = gridDigests(s.worst_grid_points);
  }
  return j;
}

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
  const std::vector<std::string> columns = studyColumns(st);
  std::uint64_t begin = 0, end = st.samples, shard_i = 0, shard_n = 0;
  if (!o.shard.empty()) std::tie(begin, end) = shardRange(o.shard, st.samples, shard_i, shard_n);
  std::string table = o.table;
  if (table.empty())
    table = fs::path(st.file).stem().string() +
            (shard_n ? ".part-" + std::to_string(shard_i) + "-of-" + std::to_string(shard_n) : std::string()) + ".csv";
  const std::pair<const char*, std::string> outputs[] = {
      {"--table", table}, {"--plot", o.plot}, {"--heat-map", o.heat_map}, {"--summary", o.summary}, {"--groups", o.groups},
      {"--html", o.html}};
  if (o.merge.empty() && StudyGrid{begin, end, chunkSize(o, st)}.count() > kMaxChunks)
    throw UsageError("--chunk-size " + std::to_string(chunkSize(o, st)) + ": " +
                     std::to_string(StudyGrid{begin, end, chunkSize(o, st)}.count()) + " chunk files for samples " +
                     std::to_string(begin) + "-" + std::to_string(end) + ", more than " + std::to_string(kMaxChunks) +
                     "; use --chunk-size " + std::to_string((end - begin + kMaxChunks - 2) / (kMaxChunks - 1)) + " or more");
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

  // The summary from the rows as the table is written, a block at a time: never the whole table.
  StudySummarizer summarizer(study);
  std::vector<double> block;
  constexpr std::size_t kBlockRows = 4096;
  block.reserve(kBlockRows * columns.size());
  const RowSink sink = [&](const std::vector<double>& row) {
    block.insert(block.end(), row.begin(), row.end());
    if (block.size() == kBlockRows * columns.size()) summarizer.add(block.data(), kBlockRows), block.clear();
  };
  std::string how;
  {
    const TableLock lock(table, std::cerr);  // no second run on this table until this one ends
    removeStaleTemporaries(table, table + ".parts");
    how = o.merge.empty() ? computeTable(study, o, table, begin, end, columns, sink)
                          : mergeParts(o.merge, table, st, columns, sink);
  }
  summarizer.add(block.data(), block.size() / columns.size());
  std::vector<double>().swap(block);

  if (shard_n) {  // a part: its rows only; the summary is the merged table's
    out << st.file << ": shard " << shard_i << "/" << shard_n << ", samples " << begin << "-" << end << " (" << how
        << ") written to " << table << "; join the shards with: kdl_space study " << st.file << " --merge PART...\n";
    return;
  }
  const StudySummary summary = summarizer.finish();
  Json json = studySummaryJson(st, summary, table);
  json["html"] = o.html.empty() ? Json(nullptr) : Json(o.html);  // the nominal sample's page, or null
  if (!o.summary.empty()) {
    AtomicFile f(o.summary, "--summary");
    errno = 0;
    std::ofstream s(f.tmp());
    s << jsonText(json, 2) << "\n";
    s.close();
    if (!s) throw InputError("--summary " + o.summary + ": cannot write the file: " + writeFailure());
    f.commit();
  }
  if (!o.groups.empty()) {
    AtomicFile f(o.groups, "--groups");
    errno = 0;
    std::ofstream g(f.tmp());
    writeStudyGroups(g, summary);
    g.close();
    if (!g) throw InputError("--groups " + o.groups + ": cannot write the file: " + writeFailure());
    f.commit();
  }
  if (!o.plot.empty()) {
    AtomicFile f(o.plot, "--plot");
    writeStudyHistograms(f, st, columns, table, summary);
    f.commit();
  }
  if (!o.heat_map.empty()) {
    AtomicFile f(o.heat_map, "--heat-map");
    writeStudyHeatMap(f, st, summary);
    f.commit();
  }
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
