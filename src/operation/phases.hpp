// The phases of the capture operation that runCaptureOperation puts in order (private): the
// approach, and the motion of a free-floating target that separated after a point impact.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario_errors.hpp"

namespace kdl_space::operation {

/// \brief The approach: from the robot's initial state until the hand holds the grasp point; its
/// samples (the last one: the contact instant, Phase::Capture) go to result.approach_samples,
/// the robot's and the target's states at the contact instant to result.at_contact, the robot's
/// to s. `cancelled`: the caller's cancel poll (Simulator::setCancelPoll; may be empty).
/// \throws InputError (the scenario's terms) when the approach cannot run or fails.
void approach(const Scenario& sc, double output_step, const std::function<bool()>& cancelled, OperationResult& result,
              SimulationState& s);

/// \brief A free-floating target that separated (after a point impact, or a compliant contact
/// that opened), moved on by itself from its state and velocity at t0 to t_end (targetSimulator:
/// its brakes and servos; gravity as the robot's; a grounded target held).
TargetMotion separatedTarget(const Scenario& sc, const FloatingSystem& target, double t0, double t_end,
                             double output_step, const std::function<bool()>& cancelled);

void graspOverloadWarning(const Scenario& sc, OperationResult& r);

/// \brief The motion after the capture (runMotionAfterCapture's, and a compliant capture's): the
/// approach's and the contact's samples put in result.model's joints and given to the observer,
/// then result.model's motion from s (its t the start) for result.duration, and `separated`'s by
/// itself. result's model, joined, duration and output_step are set.
void runMotion(const Scenario& sc, const CaptureProblem& problem, SimulationState s,
               const std::optional<FloatingSystem>& separated, const OperationOptions& options, OperationResult& result);

/// \brief The compliant capture (sc.compliant) at the contact instant result.t_capture: the
/// contact integrated (its samples to result.contact_samples), then what moves on after it (the
/// joined system if caught, the robot and the target apart if it opened) by runMotion. `limit`,
/// the impulsive capture of the same contact, goes to result.capture. \throws OperationError (a
/// contact that neither caught nor opened, a cancelled run), InputError in the scenario's terms.
void compliantCapture(const Scenario& sc, const CaptureProblem& problem, const std::optional<CaptureResult>& limit,
                      const OperationOptions& options, OperationResult& result);

/// \brief A free-floating target's own simulator (the scenario's simulation options; its brakes:
/// target.mode, target.locked; its servos: simulation.target_joints; a grounded target held).
/// \throws ModelError (a set-up call) for a control the simulator refuses.
std::unique_ptr<Simulator> targetSimulator(const Scenario& sc, const FloatingSystem& target);

/// \brief A free-floating robot target's motion during the approach, from its scenario state at
/// t = 0, integrated by targetSimulator (the grasp in its contact link's frame).
std::shared_ptr<FloatingApproachTarget> approachTarget(const Scenario& sc, const FloatingSystem& target,
                                                       const std::function<bool()>& cancelled);

/// The reaction wheels' momenta where the motion after the contact starts: where the approach left
/// them (r.wheel_momentum_at_contact), else the scenario's at the start; empty without wheels.
Eigen::VectorXd wheelsAtContact(const Scenario& sc, const OperationResult& r);

/// The simulator as the scenario says, or its refusal in the scenario's words.
std::unique_ptr<Simulator> simulatorFor(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                        bool approach);

/// `f()`; an error it throws comes back with the scenario's file in front ("FILE: target: ..."),
/// of its own type (an OperationError, which names the file already, as it is).
template <typename F>
auto inScenario(const Scenario& scenario, F&& f) -> decltype(f()) {
  return inScenarioFile<OperationError>(scenario, std::forward<F>(f));
}

}  // namespace kdl_space::operation
