// The JSON of `inspect` (an Inspection: algorithm/inspection.hpp) and of its parts that the other
// reports share: a pose, J*'s conditioning, the joints' margins, the warnings. Keys are a contract.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/algorithm/inspection.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/report/json.hpp"

namespace kdl_space::report {

/// A pose as JSON: position, rotation (rows), quaternion (x, y, z, w), rpy.
Json poseJson(const PoseFigures& figures);
/// Conditioning as JSON: J_star_singular_values, J_star_condition_number (null if singular),
/// J_star_manipulability, J_manipulability.
Json conditioningJson(const Conditioning& c);
/// Joint name -> {margin, to_lower, to_upper} (null for a continuous joint, or a side without limit).
Json jointMarginsJson(const FloatingModel& model, const std::vector<JointMargin>& margins);
/// The "warnings" list of the JSON outputs: [{kind, element, message}] and each one's details.
Json warningsJson(const std::vector<Diagnostic>& warnings);
/// One contact point of `inspect --json`: link, offset, point, J_star (6 x n), G_star, G_grounded
/// (null where H is not positive definite), G_locked, pose, conditioning.
Json contactInspectionJson(const ContactInspection& c, const Contact& h, const std::string& link);
/// The object of `inspect --json`: `contacts` from contactInspectionJson, the diagnostics and
/// warnings as the tool lists them; H_star null when the inspection formed none.
Json inspectionJson(const FloatingModel& model, const Inspection& figures, const State& state, const Json& contacts,
                    const std::vector<std::string>& diagnostics, const std::vector<Diagnostic>& warnings);

}  // namespace kdl_space::report
