// CaptureResult.to_html and kdl_space.OperationResult (run_operation's dict with to_html): the
// bindings parse the path and the samples, the tool's HtmlWriter draws the page.
#include "expose_html.hpp"

#include <filesystem>
#include <functional>

#include "kdl_space/report/capture_report.hpp"
#include "kdl_space/report/html_writer.hpp"

namespace kdl_space::python {
namespace {

/// What the page of a run needs besides its samples: the scenario (the robot's and the target's
/// URDFs, the grasp frame) and the operation's result without its samples.
struct PyOperationRun {
  std::shared_ptr<const Scenario> scenario;
  std::shared_ptr<const OperationResult> result;
};

py::handle operation_result_type;  // kdl_space.OperationResult (kept alive by the module)

/// The page's warnings (a mesh drawn as its box, a reference dropped) as Python warnings, each
/// naming its link, as the tool prints them on stderr.
void warnInPython(const std::vector<Diagnostic>& warnings) {
  for (const Diagnostic& d : warnings) {
    const std::string text = (d.element.empty() ? "" : d.element + ": ") + d.message;
    if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) != 0) throw py::error_already_set();
  }
}

/// Refused as the tool refuses --html (three.js missing, a folder that cannot hold the file: OSError;
/// a path that is one of the run's inputs: ValueError), then written under a temporary name and
/// renamed: a failed call leaves no file. Every message names the path.
void writePage(const std::string& path, const Scenario& sc, const std::vector<std::string>& mesh_search_path,
               const std::function<void(const AtomicFile&)>& draw) {
  try {
    if (path.empty()) throw UsageError("to_html: the file name is empty");
    report::checkHtmlLibrary("to_html", path);
    checkOutputFile(path, "to_html");
    std::vector<InputFile> inputs = report::scenarioInputs(sc);
    for (InputFile& mesh : report::meshInputs(sc, mesh_search_path)) inputs.push_back(std::move(mesh));  // the page's meshes
    refuseOverwritingInputs("to_html", path, inputs);
    AtomicFile file(path, "to_html");
    draw(file);
    file.commit();
  } catch (const UsageError& e) {
    throw py::value_error(e.what());
  } catch (const InputError& e) {
    PyErr_SetString(PyExc_OSError, e.what());
    throw py::error_already_set();
  }
}

/// to_html's `mesh_path` (None, one folder, or a list of folders; str or os.PathLike) as the
/// tool's --mesh-path: each must be a folder (ValueError naming it); ROS_PACKAGE_PATH's come after.
std::vector<std::string> meshSearchPathOf(const py::object& mesh_path) {
  std::vector<std::string> dirs;
  if (mesh_path.is_none()) return report::meshSearchPath(dirs);
  const py::object fspath = py::module_::import("os").attr("fspath");
  const bool one = py::isinstance<py::str>(mesh_path) || py::hasattr(mesh_path, "__fspath__");
  for (const py::handle dir : one ? py::list(py::make_tuple(mesh_path)) : py::list(mesh_path)) {
    const std::string d = py::cast<std::string>(fspath(dir));
    std::error_code ec;
    if (!std::filesystem::is_directory(d, ec))
      throw py::value_error("to_html: mesh_path " + d + " is not a folder (give the folder that holds the package folders)");
    dirs.push_back(d);
  }
  return report::meshSearchPath(dirs);
}

Phase phaseOf(const std::string& name) {
  if (name == "approach") return Phase::Approach;
  if (name == "capture") return Phase::Capture;
  if (name == "post") return Phase::Post;
  if (name == "motion") return Phase::Motion;
  if (name == "contact") return Phase::Contact;
  throw py::value_error("to_html: samples['phase']: '" + name + "' is not approach, capture, post, motion or contact");
}

using Rows = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// The result's samples (its 'samples' arrays: t, phase, base_position, base_quaternion, q), one
/// at a time into the writer, as the tool's observer gives them.
void operationToHtml(py::object self, const std::string& path, const py::object& mesh_path) {
  const PyOperationRun& run = py::cast<const PyOperationRun&>(self.attr("_run"));
  const py::dict samples = self["samples"];
  const auto t = samples["t"].cast<Rows>(), p = samples["base_position"].cast<Rows>(),
             quat = samples["base_quaternion"].cast<Rows>(), q = samples["q"].cast<Rows>();
  const auto phase = samples["phase"].cast<py::list>();
  const py::ssize_t k = t.size(), n = q.ndim() == 2 ? q.shape(1) : 0;
  const OperationResult& r = *run.result;
  if (p.ndim() != 2 || p.shape(0) != k || p.shape(1) != 3 || quat.ndim() != 2 || quat.shape(0) != k || quat.shape(1) != 4 ||
      q.ndim() != 2 || q.shape(0) != k || n != static_cast<py::ssize_t>(r.model->nj()) || py::len(phase) != static_cast<std::size_t>(k))
    throw py::value_error("to_html " + path + ": the result's samples (t, phase, base_position, base_quaternion, q) are "
                          "not those run_operation returned");
  const std::string title = "kdl_space.run_operation " + std::filesystem::path(run.scenario->file).filename().string();
  const std::vector<std::string> search_path = meshSearchPathOf(mesh_path);
  writePage(path, *run.scenario, search_path, [&](const AtomicFile& file) {
    report::HtmlWriter page(*run.scenario, search_path);
    warnInPython(page.warnings());
    MotionSample x;
    x.q.resize(n);
    for (py::ssize_t i = 0; i < k; ++i) {
      x.t = t.at(i);
      x.phase = phaseOf(py::cast<std::string>(phase[static_cast<std::size_t>(i)]));
      x.p = Eigen::Vector3d(p.at(i, 0), p.at(i, 1), p.at(i, 2));
      x.quat = Eigen::Vector4d(quat.at(i, 0), quat.at(i, 1), quat.at(i, 2), quat.at(i, 3));
      for (py::ssize_t j = 0; j < n; ++j) x.q(j) = q.at(i, j);
      page.add(r, x);
    }
    page.write(file, r, title);
  });
}

}  // namespace

void captureToHtml(const PyResult& x, const std::string& path, const py::object& mesh_path) {
  const std::string title = "kdl_space.solve_capture " + std::filesystem::path(x.scenario->file).filename().string();
  const std::vector<std::string> search_path = meshSearchPathOf(mesh_path);
  writePage(path, *x.scenario, search_path,
            [&](const AtomicFile& file) { warnInPython(report::writeCaptureHtml(file, *x.scenario, x.r, title, search_path)); });
}

py::object operationResultOf(py::dict d, std::shared_ptr<const Scenario> scenario, OperationResult result) {
  std::vector<MotionSample>().swap(result.approach_samples);  // the page reads the dict's arrays
  std::vector<MotionSample>().swap(result.samples);
  py::object out = operation_result_type(d);
  out.attr("_run") = PyOperationRun{std::move(scenario), std::make_shared<const OperationResult>(std::move(result))};
  return out;
}

void bindHtml(py::module_& m) {
  py::class_<PyOperationRun>(m, "_OperationRun", "The run behind an OperationResult (what its to_html draws).");
  const py::object builtins = py::module_::import("builtins");
  py::dict ns;
  ns["__module__"] = "kdl_space";
  ns["__doc__"] = "What run_operation returns: the dict `kdl_space simulate --json` prints, with 'samples', and "
                  "to_html(path).";
  py::object cls = builtins.attr("type")("OperationResult", py::make_tuple(builtins.attr("dict")), ns);
  cls.attr("to_html") = py::cpp_function(
      &operationToHtml, py::name("to_html"), py::is_method(cls), py::arg("path"), py::arg("mesh_path") = py::none(),
      "Writes the run as the interactive 3-D page of `kdl_space simulate --html` (one self-contained HTML file; "
      "the same writer), drawn from this result's 'samples'. mesh_path: a folder or a list of folders where the "
      "URDFs' package:// meshes are found (the tool's --mesh-path), searched before ROS_PACKAGE_PATH's. ValueError "
      "for a path that is one of the run's inputs (the scenario, its URDFs, the meshes the page embeds) or a "
      "mesh_path that is not a folder, OSError for a folder that cannot hold it or three.js missing (Debian's "
      "libjs-three); each names the path.");
  const py::object dict_type = builtins.attr("dict");
  cls.attr("__reduce__") = py::cpp_function([dict_type](py::object self) { return py::make_tuple(dict_type, py::make_tuple(dict_type(self))); },
                                            py::name("__reduce__"), py::is_method(cls),
                                            "Pickled (and copied) as a plain dict: to_html stays with the original.");
  m.attr("OperationResult") = cls;
  operation_result_type = cls.release();
}

}  // namespace kdl_space::python
