// The pages of `--html` from Python (CaptureResult.to_html, OperationResult.to_html): the tool's
// writer (kdl_space/report/html_writer.hpp), its refusals as ValueError and OSError.
#pragma once

#include <memory>
#include <string>

#include "capture_types.hpp"
#include "conversions.hpp"
#include "kdl_space/operation/capture_operation.hpp"

namespace kdl_space::python {

/// CaptureResult.to_html: the capture's instant (report::writeCaptureHtml) into `path`; `mesh_path`
/// (None, a folder, or a list of folders) as the tool's --mesh-path, ROS_PACKAGE_PATH's after it.
void captureToHtml(const PyResult& result, const std::string& path, const py::object& mesh_path);

/// \brief run_operation's dict as a kdl_space.OperationResult (a dict, with to_html): `result`
/// keeps the operation's result without its samples (the page reads them from d["samples"]).
py::object operationResultOf(py::dict d, std::shared_ptr<const Scenario> scenario, OperationResult result);

/// The type kdl_space.OperationResult.
void bindHtml(py::module_& m);

}  // namespace kdl_space::python
