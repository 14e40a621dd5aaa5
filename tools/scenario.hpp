// Capture scenarios (YAML or JSON): what the robot is, where and how fast it moves, what it hits
// and with which impact law. Read by `kdl_space capture` (and later `simulate`).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "kdl_space/collision.hpp"
#include "kdl_space/simulation.hpp"

namespace kdl_space::cli {

/// A free-floating system of the scenario: model, state, velocity, contact, response.
struct ScenarioSystem {
  std::string urdf;  ///< resolved path
  std::shared_ptr<const FloatingModel> model;
  State state;
  FloatingVelocity velocity;
  Contact contact;
  std::string contact_link;
  Response response = Response::FreeFloating;
};

/// The `simulation` section: what `kdl_space simulate` does after the impact.
struct SimulationSpec {
  double duration = 20.0;     ///< [s], overridden by --duration
  double output_step = 0.05;  ///< CSV row spacing [s]
  SimulationOptions options;
  std::vector<std::pair<unsigned int, JointControl>> joints;  ///< by joint index of the robot
};

struct Scenario {
  std::string file;
  ScenarioSystem robot;
  std::optional<RigidBody> rigid_target;       ///< a rigid target, or
  std::optional<ScenarioSystem> floating_target;  ///< another free-floating system
  ImpactLaw law;
  bool has_normal = false;  ///< a normal was given (virtual mass is reported)
  SimulationSpec simulation;
};

/// \brief Reads and checks a scenario file. URDF paths are relative to the scenario's folder.
/// \throws InputError naming the file and the field (e.g. "target.mass") for every problem.
Scenario loadScenario(const std::string& file);

}  // namespace kdl_space::cli
