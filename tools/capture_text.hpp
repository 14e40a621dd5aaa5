// The text of `kdl_space capture` (and of simulate's capture): the impact's readable summary, and
// a compliant contact's beside its impulsive limit. (The JSON: kdl_space/report/capture_report.hpp.)
#pragma once

#include <ostream>

#include "kdl_space/impact/capture.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"

namespace kdl_space::cli {

/// The readable summary.
void printCaptureSummary(std::ostream& out, const Scenario& scenario, const CaptureResult& result);
/// The compliant contact's summary beside `limit`, the impulsive capture of the same contact.
void printCompliantSummary(std::ostream& out, const CompliantCaptureResult& contact, const CaptureResult& limit);

}  // namespace kdl_space::cli
