// The JSON of the reports (a contract: keys are added, never renamed): the document type, its text,
// and the pieces every result's JSON is made of (matrices, the joints treated as fixed).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kdl_space/multibody/model.hpp"

namespace kdl_space::report {

/// Keys in the order they are set: the order every report's JSON shows.
using Json = nlohmann::ordered_json;

/// \brief A JSON document as text (`indent` -1: one line). Whatever bytes a string holds are
/// written: control characters escaped (`\u001b`), bytes that are not UTF-8 replaced by U+FFFD,
/// never an exception at the end of a run (nlohmann's default throws type_error 316).
inline std::string jsonText(const Json& j, int indent = -1) {
  return j.dump(indent, ' ', false, Json::error_handler_t::replace);
}

/// A matrix as a JSON array of rows; a column vector as a flat array.
Json toJson(const Eigen::MatrixXd& m);

/// A matrix as a JSON array of rows, always: an r x c matrix is r arrays of c numbers, a column
/// (c = 1) included (for matrices whose column count is the number of joints: J*, H*).
Json toJsonRows(const Eigen::MatrixXd& m);

/// The joints of the description that are not coordinates: [{"joint", "reason"}] (JSON key
/// `joints_treated_as_fixed` beside every `joint_names`).
Json fixedJointsJson(const FloatingModel& model);

/// Row labels of a twist or wrench: vx vy vz wx wy wz.
const std::vector<std::string>& twistLabels();

}  // namespace kdl_space::report
