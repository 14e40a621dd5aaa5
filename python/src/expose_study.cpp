// kdl_space.Study and load_study (study.hpp): a study file read and checked, its rows computed on
// this process's threads (runStudy, GIL released) and its summary as the dict `kdl_space study
// --json` prints. The engines in Python (kdl_space.study: threads, Dask) are python/kdl_space/study.py.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <thread>

#include "capture_types.hpp"
#include "conversions.hpp"
#include "json_objects.hpp"
#include "kdl_space/report/capture_report.hpp"
#include "kdl_space/report/study_report.hpp"
#include "kdl_space/study/study.hpp"
#include "kdl_space/study/study_table.hpp"
#include "kdl_space/study/study_to_table.hpp"

namespace kdl_space::python {
namespace {

struct PyStudy {
  std::shared_ptr<const Study> study;
  std::vector<std::string> columns;
};

const char* kindName(Distribution::Kind k) {
  switch (k) {
    case Distribution::Kind::Uniform: return "uniform";
    case Distribution::Kind::Normal: return "normal";
    case Distribution::Kind::LogNormal: return "log_normal";
    case Distribution::Kind::Grid: break;
  }
  return "grid";
}

/// `name`: a whole number 0 <= value <= most, else ValueError naming it.
std::uint64_t bounded(long long value, std::uint64_t most, const char* name, const std::string& what) {
  if (value < 0 || static_cast<unsigned long long>(value) > most)
    throw py::value_error(std::string(name) + ": expected 0 <= " + name + " <= " + std::to_string(most) + " (" + what +
                          "), got " + std::to_string(value));
  return static_cast<std::uint64_t>(value);
}

/// Runs `work(cancel)` on a thread of its own with the GIL released; this thread waits in slices of
/// 50 ms and checks for signals between them, so Ctrl-C sets `cancel` within a slice (the library
/// stops within a sample) and raises KeyboardInterrupt, not after a chunk of up to 65,536 samples.
void runAnsweringCtrlC(const std::function<void(const std::atomic<bool>& cancel)>& work) {
  std::atomic<bool> cancel{false};
  std::mutex mutex;
  std::condition_variable finished_cv;
  bool finished = false, interrupted = false;
  std::exception_ptr error;
  {
    py::gil_scoped_release nogil;
    std::thread runner([&] {
      try {
        work(cancel);
      } catch (...) {
        error = std::current_exception();
      }
      const std::lock_guard<std::mutex> lock(mutex);
      finished = true;
      finished_cv.notify_all();
    });
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        if (finished_cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return finished; })) break;
      }
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {  // the error (KeyboardInterrupt) is set: raised below
        interrupted = true;
        cancel = true;
        break;
      }
    }
    runner.join();
  }
  if (interrupted) {
    if (error) {  // the library's Cancelled says what it kept: the KeyboardInterrupt's message
      try {
        std::rethrow_exception(error);
      } catch (const Cancelled& e) {
        PyErr_Clear();
        PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
      } catch (...) {
      }
    }
    throw py::error_already_set();
  }
  if (error) std::rethrow_exception(error);
}

py::array_t<double> studyRows(const PyStudy& s, long long begin_arg, long long end_arg, long long threads_arg) {
  const Study& st = *s.study;
  const std::uint64_t end = bounded(end_arg, st.samples, "end", "the study's samples");
  const std::uint64_t begin = bounded(begin_arg, end, "begin", "end");
  const unsigned threads = static_cast<unsigned>(bounded(threads_arg, 4096, "threads", "0: all cores"));
  const std::size_t m = s.columns.size();
  py::array_t<double> out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(end - begin), static_cast<py::ssize_t>(m)});
  double* data = out.mutable_data();
  runAnsweringCtrlC([&](const std::atomic<bool>& cancel) {
    runStudy(s.study, StudyGrid{begin, end, defaultChunkSize(st.samples)}, threads,
             [&](const StudyChunk& c, const std::vector<double>& chunk_rows) {
               std::memcpy(data + (c.begin - begin) * m, chunk_rows.data(), chunk_rows.size() * sizeof(double));
             }, &cancel);
  });
  return out;
}

/// Rows 0..n-1 of the table from the inputs `given` ((n, studyInputCount) values: a caller's own
/// draws), on one evaluator, GIL released; with the failures' messages by sample.
py::tuple studyRowsDrawn(const PyStudy& s, py::handle given) {
  const Study& st = *s.study;
  const long k = static_cast<long>(studyInputCount(st));
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  Array a = Array::ensure(given);
  if (!a) {
    PyErr_Clear();
    throw py::value_error("draws: expected an array of numbers of shape (n, " + std::to_string(k) + ")");
  }
  if (a.ndim() != 2 || a.shape(1) != k || static_cast<std::uint64_t>(a.shape(0)) > st.samples)
    throw py::value_error("draws: expected shape (n, " + std::to_string(k) + ") (the study's input columns), n <= samples");
  const std::size_t n = static_cast<std::size_t>(a.shape(0)), m = s.columns.size();
  py::array_t<double> out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(m)});
  double* data = out.mutable_data();
  std::vector<std::pair<std::uint64_t, std::string>> failures;
  {
    py::gil_scoped_release nogil;
    StudyEvaluator evaluator(s.study);
    for (std::size_t i = 0; i < n; ++i) {
      evaluator.evaluate(i, a.data() + i * static_cast<std::size_t>(k), data + i * m);
      if (!evaluator.failure().empty()) failures.emplace_back(i, evaluator.failure());
    }
  }
  py::dict messages;
  for (const auto& [i, why] : failures) messages[py::int_(i)] = why;
  return py::make_tuple(out, messages);
}

/// The summary as `kdl_space study --json` writes it (report::studySummaryJson), without "table" (no file).
py::dict summary(const PyStudy& s, py::handle given) {
  const Study& st = *s.study;
  const long m = static_cast<long>(s.columns.size());
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  Array a = Array::ensure(given);
  if (!a) {
    PyErr_Clear();
    throw py::value_error("rows: expected an array of numbers of shape (n, " + std::to_string(m) + ")");
  }
  if (a.ndim() != 2 || a.shape(1) != m)
    throw py::value_error("rows: expected shape (n, " + std::to_string(m) + ") (the study's columns), got " +
                          std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()))))));
  StudySummary sum;
  {
    py::gil_scoped_release nogil;
    StudySummarizer summarizer(s.study);
    summarizer.add(a.data(), static_cast<std::size_t>(a.shape(0)));
    sum = summarizer.finish();
  }
  report::Json j = report::studySummaryJson(st, sum, "");
  j.erase("table");
  return toPython(j);
}

/// `table` as a study's table file at `path` (the tool's format, byte for byte), whole or not at all.
void writeTable(const PyStudy& s, py::handle given, const std::string& path) {
  const Study& st = *s.study;
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  Array a = Array::ensure(given);
  const long m = static_cast<long>(s.columns.size());
  if (!a || a.ndim() != 2 || a.shape(1) != m || static_cast<std::uint64_t>(a.shape(0)) > st.samples) {
    PyErr_Clear();
    throw py::value_error("table: expected an array of shape (n, " + std::to_string(m) + "), n <= " +
                          std::to_string(st.samples) + " (rows 0..n-1 of the study)");
  }
  checkOutputFile(path, "to_csv");
  std::vector<InputFile> inputs = report::scenarioInputs(st.scenario);  // no output replaces an input
  inputs.push_back({"the study file", st.file});
  refuseOverwritingInputs("to_csv", path, inputs);
  py::gil_scoped_release nogil;
  writeStudyPart(path, "to_csv", st, s.columns, 0, static_cast<std::uint64_t>(a.shape(0)), a.data());
}

/// runStudyToTable: the summary (none for a shard) and what was done, as a dict.
py::dict toTable(const PyStudy& s, const std::string& table, long long threads, py::object shard, std::vector<std::string> merge,
                 long long chunk_size) {
  TableOptions o;
  o.table = table;
  o.option = "table";
  o.threads = static_cast<unsigned>(bounded(threads, 4096, "threads", "0: all cores"));
  o.chunk_size = bounded(chunk_size, 100000000, "chunk_size", "0: the study's");
  o.merge = std::move(merge);
  if (!shard.is_none()) {
    const auto pair = argumentAs<std::pair<long long, long long>>(shard, "shard", "a pair (i, n) of whole numbers");
    o.shard = bounded(pair.first, 1u << 30, "shard[0]", "1 <= i <= n");
    o.shards = bounded(pair.second, 1u << 30, "shard[1]", "n <= the study's samples");
  }
  tableRows(*s.study, o);  // UsageError (ValueError) before any work
  std::vector<InputFile> inputs = report::scenarioInputs(s.study->scenario);
  inputs.push_back({"the study file", s.study->file});
  for (const std::string& part : o.merge) inputs.push_back({"one of the parts merged", part});
  checkOutputFile(o.table, "table");
  refuseOverwritingInputs("table", o.table, inputs);
  std::vector<std::string> notes;
  o.note = [&](const std::string& note) { notes.push_back(note); };
  TableRun run;
  runAnsweringCtrlC([&](const std::atomic<bool>& cancel) {
    o.cancel = &cancel;
    run = runStudyToTable(s.study, o);
  });
  for (const std::string& note : notes) PyErr_WarnEx(PyExc_UserWarning, note.c_str(), 1);
  py::dict d;
  d["table"] = run.table, d["begin"] = run.begin, d["end"] = run.end, d["computed"] = run.computed;
  d["resumed"] = run.resumed, d["threads"] = run.threads, d["seconds"] = run.seconds, d["how"] = run.how;
  if (run.summary) {
    report::Json j = report::studySummaryJson(*s.study, *run.summary, run.table);
    d["summary"] = toPython(j);
  } else {
    d["summary"] = py::none();
  }
  return d;
}

/// A caller's own draws (kdl_space.study's sampler=): the study's, and rows from given ones.
void bindStudyDraws(py::class_<PyStudy>& study) {
  study
      .def("draws", [](const PyStudy& s, long long i) {
        const std::vector<double> v = studyDraws(*s.study, bounded(i, s.study->samples - 1, "i", "samples - 1"));
        return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
      }, py::arg("i"),
           "Sample i's inputs as the study draws them: the values of its table's input columns (input_columns).")
      .def_property_readonly("input_columns", [](const PyStudy& s) {
        return std::vector<std::string>(s.columns.begin() + 2, s.columns.begin() + 2 + static_cast<long>(studyInputCount(*s.study)));
      }, "The table's input columns, in order (after sample and status): what draws() and rows_drawn() hold.")
      .def("rows_drawn", &studyRowsDrawn, py::arg("draws"),
           "(rows, failures): rows 0..n-1 of the table computed from the inputs `draws` ((n, len(input_columns)): "
           "a caller's own draws, kdl_space.study's sampler=) instead of the study's, and {sample: why} for "
           "those that failed. GIL released.");
}

}  // namespace

void bindStudy(py::module_& m) {
  py::class_<PyStudy> study(m, "Study",
                      "A capture study (load_study): a scenario plus distributions over its inputs; sample i depends "
                      "only on (seed, i), so its rows are the same whatever computes them.");
  study.def_property_readonly("file", [](const PyStudy& s) { return s.study->file; }, "The path it was read from.")
      .def_property_readonly("fingerprint", [](const PyStudy& s) { return s.study->fingerprint; },
                             "Of the study's, scenario's and URDFs' bytes (tables' parts must agree).")
      .def_property_readonly("samples", [](const PyStudy& s) { return s.study->samples; }, "Rows in the whole table.")
      .def_property_readonly("seed", [](const PyStudy& s) { return s.study->seed; })
      .def_property_readonly("latin_hypercube", [](const PyStudy& s) { return s.study->latin_hypercube; },
                             "`sampling: latin_hypercube` (else independent draws).")
      .def_property_readonly("inputs", [](const PyStudy& s) {
        std::vector<std::string> names;
        for (const StudyInput& in : s.study->inputs) names.push_back(in.name);
        return names;
      }, "The inputs' names, in file order.")
      .def_property_readonly("distributions", [](const PyStudy& s) {
        py::dict d;
        for (const StudyInput& in : s.study->inputs) {
          const Distribution& x = in.distribution;
          py::dict one;
          one["kind"] = kindName(x.kind), one["a"] = x.a, one["b"] = x.b;
          if (x.kind == Distribution::Kind::Grid) one["count"] = x.count;
          if (std::isfinite(x.min)) one["min"] = x.min;  // a truncated normal's bounds
          if (std::isfinite(x.max)) one["max"] = x.max;
          d[py::str(in.name)] = one;
        }
        return d;
      }, "Input name -> {kind: uniform (a, b: range) | normal (a: mean, b: std; min, max: truncated to) | "
         "log_normal (a: median, b: factor) | grid (a, b, count)}.")
      .def_readonly("columns", &PyStudy::columns,
                    "The table's columns: sample, status, the inputs drawn (target.tumble adds its axis), the outcomes.")
      .def_property_readonly("objective", [](const PyStudy& s) { return s.study->objective; },
                             "The outcome the best (smallest) and worst samples rank by.")
      .def_property_readonly("objective_statistic", [](const PyStudy& s) -> py::object {
        if (s.study->objective_statistic.empty()) return py::none();
        return py::str(s.study->objective_statistic);
      }, "`objective: {outcome, statistic}`'s statistic (mean, q95, max, probability): the grid points rank by it; "
         "None: the samples rank by the outcome.")
      .def_property_readonly("scenario", [](const PyStudy& s) { return PyScenario{s.study->scenario}; }, "Its Scenario.")
      .def_property_readonly("motion_duration", [](const PyStudy& s) { return s.study->motion_duration; },
                             "[s]; 0: no motion after the capture.")
      .def_property_readonly("heat_map", [](const PyStudy& s) -> py::object {
        if (!s.study->heat_map) return py::none();
        const StudyHeatMap& h = *s.study->heat_map;
        return py::make_tuple(h.x, h.y, h.outcome);
      }, "(x, y, outcome) column names, or None.")
      .def_property_readonly("heat_map_statistic", [](const PyStudy& s) -> py::object {
        if (!s.study->heat_map) return py::none();
        return py::str(s.study->heat_map->statistic);
      }, "The per-grid-point aggregate the heat map draws (mean, q95, max, probability), or None.")
      .def_property_readonly("default_chunk_size", [](const PyStudy& s) { return defaultChunkSize(s.study->samples); },
                             "Samples per chunk on the study's grid of chunks (what the engines use by default).")
      .def("chunks", [](const PyStudy& s, long long chunk_size, long long begin, py::object end_arg) {
        const std::uint64_t end = end_arg.is_none() ? s.study->samples
                                                    : bounded(py::cast<long long>(end_arg), s.study->samples, "end", "the study's samples");
        const std::uint64_t b = bounded(begin, end, "begin", "end");
        const std::uint64_t size = bounded(chunk_size, 100000000, "chunk_size", "0: the study's");
        std::vector<std::pair<std::uint64_t, std::uint64_t>> out;
        for (const StudyChunk& c : studyChunks(b, end, size ? size : defaultChunkSize(s.study->samples)))
          out.emplace_back(c.begin, c.end);
        return out;
      }, py::arg("chunk_size") = 0, py::arg("begin") = 0, py::arg("end") = py::none(),
           "The chunks [(begin, end), ...] of rows [begin, end) on the study's grid of chunks of chunk_size "
           "samples (0: default_chunk_size), as the command-line tool cuts them.")
      .def("rows", &studyRows, py::arg("begin"), py::arg("end"), py::arg("threads") = 1,
           "Rows [begin, end) of the table, (end - begin, len(columns)) float64, computed on `threads` threads "
           "(0: all cores) in chunks, GIL released; Ctrl-C stops the run within a sample and raises KeyboardInterrupt. A sample that cannot "
           "be computed has its status (an error code) and NaN outcomes. ValueError unless 0 <= begin <= end <= "
           "samples.")
      .def("summary", &summary, py::arg("rows"),
           "The summary of a table (rows of this study, any order), as `kdl_space study --json` prints it: study, "
           "fingerprint (hex), samples, failed, seed, outcomes {name: {min, q05, q25, median, q75, q95, max, "
           "mean}}, quantile_rank_error (0: exact quantiles; else the bound on their ranks' error as a "
           "fraction of the samples computed), probabilities {exceeds.*: p}, objective, best and worst [{sample, objective, inputs}], failures "
           "[{status, count, first_sample, message}] (one per distinct status; the message from evaluating "
           "first_sample again, GIL released).")
      .def("write_table", &writeTable, py::arg("table"), py::arg("path"),
           "Writes rows 0..n-1 of this study's table (an array (n, len(columns))) to `path` as `kdl_space study -o` "
           "does, byte for byte (the tool merges, resumes from and plots it), whole or not at all. ValueError for a "
           "path that is one of the study's inputs; OSError-like InputError for one that cannot be written.")
      .def("to_table", &toTable, py::arg("table"), py::arg("threads") = 0, py::arg("shard") = py::none(),
           py::arg("merge") = std::vector<std::string>{}, py::arg("chunk_size") = 0,
           "runStudyToTable (kdl_space.study_to_table): the study's table written to `table` as `kdl_space study "
           "-o` writes it.")
      .def("__repr__", [](const PyStudy& s) {
        std::ostringstream r;
        r << "<kdl_space.Study '" << s.study->file << "' " << s.study->samples << " samples, inputs [";
        for (std::size_t i = 0; i < s.study->inputs.size(); ++i) r << (i ? ", " : "") << s.study->inputs[i].name;
        r << "], columns (" << s.columns.size() << ",)>";
        return r.str();
      });
  bindStudyDraws(study);

  m.def("self_motion", [](const ScenarioArg& scenario, double s) {
    std::vector<double> q;
    {
      py::gil_scoped_release nogil;
      q = selfMotionJoints(scenario.get(), s);
    }
    py::dict out;
    const std::vector<std::string>& names = scenario.get().capture.robot.model->jointNames();
    for (std::size_t j = 0; j < names.size(); ++j) out[py::str(names[j])] = q[j];
    return out;
  }, py::arg("scenario"), py::arg("s"),
        "The joint angles {joint: angle} a study's `robot.self_motion` value s gives: the scenario's capture "
        "configuration moved s [rad, joint-space arc length] along the 7-joint arm's self-motion, the hand's pose "
        "held (a study's q.JOINT columns). InputError 'robot.self_motion: ...' for an arm with no one-parameter "
        "self-motion, or a singularity on the way.");

  m.def("load_study", [](const std::string& path) {
    auto st = std::make_shared<const Study>(loadStudy(path));
    std::vector<std::string> columns = studyColumns(*st);
    return PyStudy{std::move(st), std::move(columns)};
  }, py::arg("path"), "Reads and checks a study file (YAML or JSON) and its scenario; InputError 'FILE[:LINE]: FIELD: what "
                      "is wrong'.");
}

}  // namespace kdl_space::python
