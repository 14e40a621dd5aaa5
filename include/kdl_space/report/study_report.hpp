// A study's summary as the reports write it: the JSON of `kdl_space study --json` and `--summary`
// (and Python's StudyResult.summary; its keys are a contract, docs/studies.md) and the
// per-grid-point aggregates as CSV (`--groups`).
#pragma once

#include <ostream>
#include <string>

#include "kdl_space/report/json.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space::report {

/// \brief The summary JSON: study, fingerprint, table (the file; null when there is none), samples,
/// failed, seed, outcomes, probabilities, objective, best, worst, failures, quantile_rank_error,
/// grid_inputs, grid_points, and with an objective's statistic objective_statistic,
/// best_grid_points and worst_grid_points.
Json studySummaryJson(const Study& study, const StudySummary& summary, const std::string& table);

/// \brief The per-grid-point aggregates as CSV (`--groups`): the grid inputs, count, failed, then
/// per outcome OUTCOME.mean, OUTCOME.q95, OUTCOME.max, then per limit P(exceeds.*); one row a point.
/// Nothing without grid inputs.
void writeStudyGroups(std::ostream& out, const StudySummary& summary);

}  // namespace kdl_space::report
