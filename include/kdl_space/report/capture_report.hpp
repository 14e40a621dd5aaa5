// What the reports say of a capture: its JSON object (the keys are a contract: see the README), the
// warnings about the robot's configuration at it, the picture of its instant, and the files a
// scenario makes a run read (which no output may replace).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/report/scene_writer.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"

namespace kdl_space::report {

/// The files a scenario makes a run read: the scenario, the robot's URDF, the target's URDF.
std::vector<InputFile> scenarioInputs(const Scenario& scenario);

/// \brief `point` (world) in the frame of `problem`'s target: a rigid target's `pose` frame, a
/// free-floating target's base frame, at the problem's states.
std::optional<Vector3d> pointInTargetFrame(const CaptureProblem& problem, const Vector3d& point);
/// The names of the joints a system brakes at the impact (model order).
std::vector<std::string> lockedNames(const FloatingSystem& system);
/// The `grasp` object of the capture JSON: robot.place: grasp's residuals; null without it.
Json graspJson(const Scenario& scenario);
/// The capture JSON object (the keys are a contract: see the README).
Json captureJson(const Scenario& scenario, const CaptureResult& result);
/// \brief The warnings about the robot's configuration at the capture (`problem`'s state and
/// contact): a joint outside its limits, J* near a singularity (checkConfiguration), and a robot
/// link that penetrates the target (overlapWarnings, moment "capture": the scenario's visuals).
std::vector<Diagnostic> captureWarnings(const Scenario& scenario, const CaptureProblem& problem);
/// The `compliant` object of the capture and simulate JSON (law type compliant): what the contact
/// gave, in the terms of captureJson's keys, and its history as columns.
Json compliantJson(const CompliantCaptureResult& contact);
/// The picture of the impact instant: one snapshot "impact" (the robot at its state, its
/// contact point, the target; a free-floating target's contact point as the grasp point).
SceneSnapshot impactSnapshot(const Scenario& scenario);

}  // namespace kdl_space::report
