// `kdl_space ik SCENARIO --position X Y Z --rpy R P Y [--prefer NAME=VALUE ...] [--json]`: the
// joint angles that put the robot's contact frame (robot.contact: its link's axes, origin at the
// offset) at a world pose, the base where the scenario puts it (the library's
// solveInverseKinematics, printed). Exit 3 when the pose is out of reach, with how far it came.
#pragma once

#include <CLI/CLI.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/report/ik_json.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::cli {

struct IkCliOptions {
  std::string scenario;
  std::vector<double> position;         ///< the goal's world position [m]
  std::vector<double> rpy{0, 0, 0};     ///< the goal's roll pitch yaw about fixed axes [rad]
  std::vector<std::string> prefer;      ///< NAME=VALUE: the preferred posture (default: robot.q)
  double position_tolerance = 1e-10;    ///< [m]
  double orientation_tolerance = 1e-10; ///< [rad]
  unsigned int restarts = 16;
  bool json = false;
};

CLI::App* addIk(CLI::App& app, IkCliOptions& options);

void runIk(const IkCliOptions& options, std::ostream& out);

}  // namespace kdl_space::cli
