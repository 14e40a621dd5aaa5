// The readable summary of `kdl_space simulate` (the operation's text; its JSON is the report layer's).
#pragma once

#include <ostream>

#include "cli_common.hpp"
#include "kdl_space/report/operation_report.hpp"

namespace kdl_space::cli {

/// The readable summary of `kdl_space simulate`.
void printOperation(std::ostream& out, const Scenario& sc, const OperationResult& r, const OperationFiles& files = {});

}  // namespace kdl_space::cli
