// The scenario loader's `simulation` section and its per-joint fields by name or pattern
// (private to the library).
#pragma once

#include <fnmatch.h>

#include "spatial/message_text.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "parsers/scenario/scenario_fields.hpp"

namespace kdl_space::sections {

/// Per-joint values given by name or pattern, resolved to joint indices: "*" first, then the
/// other patterns in file order, then exact names (the most specific wins). A name that is no
/// joint and a pattern that matches none are refused.
template <typename T, typename Read>
std::vector<std::pair<unsigned int, T>> byJoint(const fields::Field& f, const FloatingModel& robot, Read read) {
  const std::vector<std::string>& names = robot.jointNames();
  std::vector<std::pair<int, T>> chosen(names.size(), {-1, T{}});  // (rank, value)
  const std::vector<fields::Field::Entry> entries = f.entries();  // not at(key): O(n) each
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const std::string& key = entries[k].name;
    const fields::Field& entry = entries[k].required();
    const bool pattern = key.find_first_of("*?[") != std::string::npos;
    const int rank = key == "*" ? 0 : pattern ? 1 + static_cast<int>(k) : 1 << 30;
    bool matched = false;
    const T value = read(entry);
    for (std::size_t j = 0; j < names.size(); ++j) {
      if (pattern ? fnmatch(key.c_str(), names[j].c_str(), 0) != 0 : key != names[j]) continue;
      matched = true;
      if (rank >= chosen[j].first) chosen[j] = {rank, value};
    }
    if (!matched)
      entry.fail(std::string(pattern ? "the pattern matches no movable joint" : "the robot has no movable joint " + fields::echo(key)) +
                 " (its movable joints: " + detail::listNames(names) + ")");
  }
  std::vector<std::pair<unsigned int, T>> out;
  for (std::size_t j = 0; j < names.size(); ++j)
    if (chosen[j].first >= 0) out.emplace_back(static_cast<unsigned int>(j), chosen[j].second);
  return out;
}


/// Reads and checks the `simulation` section for the robot `robot`; InputError naming the field.
/// `target`: a free-floating target's model (its joints' controls: target_joints), or null.
SimulationSpec simulation(const fields::Field& f, const FloatingModel& robot, const FloatingModel* target = nullptr);

/// `simulation.base: grounded` (the field `base`) for a free robot of an impact: grounded in the
/// capture too (Response::Grounded), its base at rest, or InputError naming the field.
void groundForTheCapture(const fields::Field& base, FloatingSystem& robot);

}  // namespace kdl_space::sections
