// `kdl_space capture SCENARIO [--scene FILE] [--html FILE [--mesh-path DIR]...] [--json]`: the impact of the robot with its target,
// everything before and after (the library's loadScenario and solveCapture, printed), and a
// picture of the impact instant (--scene), or an interactive 3-D page of it (--html).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/report/capture_report.hpp"
#include "kdl_space/report/scene_writer.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/scenario/scenario_errors.hpp"

namespace kdl_space::cli {

struct CaptureOptions {
  std::string scenario;
  std::string scene;  ///< --scene FILE (.svg or .png); empty: none
  std::string html;   ///< --html FILE: the instant as an interactive 3-D page; empty: none
  std::vector<std::string> mesh_path;  ///< --mesh-path DIR...: where the page's package:// meshes are found
  bool json = false;
};

/// \brief Runs `f` (a library call on the scenario's capture problem); an Error it throws
/// ("target: ...") comes back of the same kind with the scenario's file in front ("FILE: target:
/// ...").
template <typename F>
auto inScenario(const Scenario& scenario, F&& f) -> decltype(f()) {
  return inScenarioFile(scenario, std::forward<F>(f));
}

/// One line "Warning: ELEMENT: MESSAGE" per warning (the text reports' form of a warning).
void printWarnings(std::ostream& out, const std::vector<Diagnostic>& warnings);
/// \brief One line "kdl_space: warning: ELEMENT: MESSAGE" per warning on stderr (the text runs'
/// warnings, and an approach's start warnings before it runs, which a failed run shows no other way).
void warnOnStderr(const std::vector<Diagnostic>& warnings);

/// The readable summary.
void printCaptureSummary(std::ostream& out, const Scenario& scenario, const CaptureResult& result);
/// The compliant contact's summary beside `limit`, the impulsive capture of the same contact.
void printCompliantSummary(std::ostream& out, const CompliantCaptureResult& contact, const CaptureResult& limit);

CLI::App* addCapture(CLI::App& app, CaptureOptions& options);

void runCapture(const CaptureOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
