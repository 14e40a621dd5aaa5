// What `kdl_space simulate` reports of the approach phase: its JSON object and its text.
#pragma once

#include <ostream>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/operation/capture_operation.hpp"

namespace kdl_space::report {

/// The `approach` object of the JSON (keys are a contract: add, never rename).
Json approachJson(const Scenario& scenario, const ApproachOutcome& outcome);
/// The approach in a few lines of text.
void printApproach(std::ostream& out, const Scenario& scenario, const ApproachOutcome& outcome);

}  // namespace kdl_space::report
