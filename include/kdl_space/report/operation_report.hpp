// What the reports say of a capture operation (runCaptureOperation's result): its JSON object (keys
// are a contract: add, never rename; `simulate --json`, Python's run_operation), and the scene at
// the start, the contact and the end.
#pragma once

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::report {

/// The output files named in the report (empty: none).
struct OperationFiles {
  std::string csv, plot, html;
};

/// The JSON object of `kdl_space simulate --json`.
Json operationJson(const Scenario& sc, const OperationResult& r, const OperationFiles& files = {});

/// The target's joints in the joined model, by their name there, and the sign of their coordinate.
Json targetSigns(const JoinedSystem& joint, const std::shared_ptr<const FloatingModel>& model);

/// The scene at the start (an approach, a plain motion), at the contact or impact and at the end
/// of the run.
std::vector<SceneSnapshot> sceneSnapshots(const Scenario& sc, const OperationResult& r);

}  // namespace kdl_space::report
