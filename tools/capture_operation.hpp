// The phases of the capture operation that `kdl_space simulate` runs in order: the approach, the
// impact at the contact instant, the system that moves on after it (the robot with a payload, the
// joined trees, or both sides apart), and the pictures of the scene. The tool's side: the
// library's pieces (runApproach, solveCapture, joinAtGrasp, Simulator) put together as a scenario
// says.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "approach_report.hpp"
#include "cli_common.hpp"
#include "kdl_space/impact/joined_system.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "sample.hpp"
#include "scene_writer.hpp"

namespace kdl_space::cli {

/// A name of the robot's model resolved in `model` (the same model, or the robot with a payload).
unsigned int jointIn(const FloatingModel& model, const FloatingModel& robot, unsigned int j);

/// The simulator as the scenario says (see capture_operation.cpp), or its refusal in the
/// scenario's words. For the approach (`approach`) the joints are left free for its servo.
std::unique_ptr<Simulator> simulatorFor(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                        bool approach);

/// One output row from a state of the run of `sim` (`rc`: a code of energyAndMomentum).
Sample sampleOf(Simulator& sim, const SimulationState& x, int& rc);

/// The approach phase: from the robot's initial state until the hand holds the grasp point; the
/// samples (the last one: the contact instant) go to `samples`. `problem` gets the robot's and
/// the target's states at the contact instant, `s` the robot's.
ApproachOutcome approachPhase(const Scenario& sc, CaptureProblem& problem, double output_step,
                              std::vector<Sample>& samples, SimulationState& s);

/// After a capture that joins the target to the robot (a free-floating target captured rigidly
/// or translationally, a rigid target captured translationally): the joined system.
std::optional<JoinedSystem> joined(const CaptureProblem& problem, const CaptureResult& capture);

/// A free-floating target that separated after a point impact, moved on by itself.
struct TargetMotion {
  SimulationState end;
  double dP = 0.0, dL = 0.0, T = 0.0;  ///< momentum drift over the run, kinetic energy after the impact
};
/// Its motion from the impact at t0 to t_end (nothing unless a free-floating target separated).
std::optional<TargetMotion> separatedTarget(const Scenario& sc, const CaptureProblem& problem,
                                            const std::optional<CaptureResult>& capture, double t0, double t_end);

/// The target's joints in the joined model, by their name there, and the sign of their coordinate.
Json targetSigns(const JoinedSystem& joint, const std::shared_ptr<const FloatingModel>& model);

/// The scene at the start (an approach, a plain motion), at the contact or impact (t_contact) and
/// at the end of the run.
std::vector<SceneSnapshot> sceneSnapshots(const Scenario& sc, const CaptureProblem& at_contact,
                                          const std::optional<CaptureResult>& capture, bool joined,
                                          const std::shared_ptr<const FloatingModel>& model, const SimulationState& end,
                                          double t_contact, const SimulationState* target_end);

}  // namespace kdl_space::cli
