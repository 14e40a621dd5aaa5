// kdl_space.Study and load_study (study.hpp): a study file read and checked, its rows computed on
// this process's threads (runStudy, GIL released) and its summary as the dict `kdl_space study
// --json` prints. The engines in Python (kdl_space.study: threads, Dask) are python/kdl_space/study.py.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
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
#include "kdl_space/study/study.hpp"

namespace kdl_space::python {
namespace {

struct PyStudy {
  std::shared_ptr<const Study> study;
  std::vector<std::string> columns;
};

std::string hex(std::uint64_t fingerprint) {
  char fp[17];
  std::snprintf(fp, sizeof fp, "%016" PRIx64, fingerprint);
  return fp;
}

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

py::array_t<double> studyRows(const PyStudy& s, long long begin_arg, long long end_arg, long long threads_arg) {
  const Study& st = *s.study;
  const std::uint64_t end = bounded(end_arg, st.samples, "end", "the study's samples");
  const std::uint64_t begin = bounded(begin_arg, end, "begin", "end");
  const unsigned threads = static_cast<unsigned>(bounded(threads_arg, 4096, "threads", "0: all cores"));
  const std::size_t m = s.columns.size();
  py::array_t<double> out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(end - begin), static_cast<py::ssize_t>(m)});
  double* data = out.mutable_data();
  // The run on threads of its own, GIL released; this thread waits in slices of 50 ms and checks
  // for signals between them, so Ctrl-C is answered within a slice and a sample (runStudy sees the
  // cancel between samples), not after a chunk of up to 65,536 samples.
  std::atomic<bool> cancel{false};
  std::mutex mutex;
  std::condition_variable finished_cv;
  bool finished = false, interrupted = false;
  std::exception_ptr error;
  {
    py::gil_scoped_release nogil;
    std::thread runner([&] {
      try {
        runStudy(s.study, StudyGrid{begin, end, defaultChunkSize(st.samples)}, threads,
                 [&](const StudyChunk& c, const std::vector<double>& chunk_rows) {
                   std::memcpy(data + (c.begin - begin) * m, chunk_rows.data(), chunk_rows.size() * sizeof(double));
                 }, &cancel);
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
  if (interrupted) throw py::error_already_set();
  if (error) std::rethrow_exception(error);
  return out;
}

py::dict quantiles(const OutcomeSummary& o) {
  py::dict d;
  d["min"] = o.min, d["q05"] = o.q05, d["q25"] = o.q25, d["median"] = o.median;
  d["q75"] = o.q75, d["q95"] = o.q95, d["max"] = o.max, d["mean"] = o.mean;
  return d;
}

py::list digests(const std::vector<SampleDigest>& list) {
  py::list a;
  for (const SampleDigest& x : list) {
    py::dict inputs, d;
    for (const auto& [name, value] : x.inputs) inputs[py::str(name)] = value;
    d["sample"] = x.sample, d["objective"] = x.objective, d["inputs"] = inputs;
    a.append(d);
  }
  return a;
}

py::dict named(const std::vector<std::pair<std::string, double>>& values) {
  py::dict d;
  for (const auto& [name, v] : values) d[py::str(name)] = v;
  return d;
}

/// A grid point's aggregates, as in `kdl_space study --json`'s grid_points.
py::dict gridPoint(const GridPointSummary& g) {
  py::dict d, outcomes;
  for (const GridPointSummary::Outcome& o : g.outcomes) {
    py::dict x;
    x["mean"] = o.mean, x["q95"] = o.q95, x["max"] = o.max;
    outcomes[py::str(o.name)] = x;
  }
  d["grid_point"] = g.index, d["inputs"] = named(g.inputs), d["count"] = g.count, d["failed"] = g.failed;
  d["outcomes"] = outcomes, d["probabilities"] = named(g.probabilities);
  return d;
}

py::list gridDigests(const std::vector<GridPointDigest>& list) {
  py::list a;
  for (const GridPointDigest& x : list) {
    py::dict d;
    d["grid_point"] = x.index, d["count"] = x.count, d["objective"] = x.objective, d["inputs"] = named(x.inputs);
    a.append(d);
  }
  return a;
}

/// The summary as `kdl_space study --json` writes it (tools/study.cpp), without "table" (no file).
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
  py::dict outcomes, probabilities, d;
  for (const OutcomeSummary& o : sum.outcomes) outcomes[py::str(o.name)] = quantiles(o);
  for (const auto& [name, p] : sum.probabilities) probabilities[py::str(name)] = p;
  d["study"] = st.file, d["fingerprint"] = hex(st.fingerprint), d["samples"] = sum.samples, d["failed"] = sum.failed;
  d["seed"] = st.seed, d["outcomes"] = outcomes, d["probabilities"] = probabilities, d["objective"] = st.objective;
  d["best"] = digests(sum.best), d["worst"] = digests(sum.worst);
  d["quantile_rank_error"] = sum.quantile_rank_error;
  py::list failures;
  for (const StudyFailure& f : sum.failures) {
    py::dict x;
    x["status"] = f.status, x["count"] = f.count, x["first_sample"] = f.first_sample, x["message"] = f.message;
    failures.append(x);
  }
  d["failures"] = failures;
  py::list grid_inputs, points;
  for (const StudyInput& in : st.inputs)
    if (in.distribution.kind == Distribution::Kind::Grid) grid_inputs.append(in.name);
  for (const GridPointSummary& g : sum.grid_points) points.append(gridPoint(g));
  d["grid_inputs"] = grid_inputs, d["grid_points"] = points;
  if (!st.objective_statistic.empty()) {
    d["objective_statistic"] = st.objective_statistic;
    d["best_grid_points"] = gridDigests(sum.best_grid_points), d["worst_grid_points"] = gridDigests(sum.worst_grid_points);
  }
  return d;
}

}  // namespace

void bindStudy(py::module_& m) {
  py::class_<PyStudy>(m, "Study",
                      "A capture study (load_study): a scenario plus distributions over its inputs; sample i depends "
                      "only on (seed, i), so its rows are the same whatever computes them.")
      .def_property_readonly("file", [](const PyStudy& s) { return s.study->file; }, "The path it was read from.")
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
      .def("__repr__", [](const PyStudy& s) {
        std::ostringstream r;
        r << "<kdl_space.Study '" << s.study->file << "' " << s.study->samples << " samples, inputs [";
        for (std::size_t i = 0; i < s.study->inputs.size(); ++i) r << (i ? ", " : "") << s.study->inputs[i].name;
        r << "], columns (" << s.columns.size() << ",)>";
        return r.str();
      });

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
