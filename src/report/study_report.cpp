#include "kdl_space/report/study_report.hpp"

#include <cstdio>

#include "kdl_space/study/study_table.hpp"

namespace kdl_space::report {
namespace {

Json quantiles(const OutcomeSummary& o) {
  return Json{{"min", o.min}, {"q05", o.q05}, {"q25", o.q25}, {"median", o.median}, {"q75", o.q75},
              {"q95", o.q95}, {"max", o.max}, {"mean", o.mean}};
}

Json gridDigests(const std::vector<GridPointDigest>& list) {
  Json a = Json::array();
  for (const GridPointDigest& d : list) {
    Json inputs = Json::object();
    for (const auto& [name, value] : d.inputs) inputs[name] = value;
    a.push_back(Json{{"grid_point", d.index}, {"count", d.count}, {"objective", d.objective}, {"inputs", inputs}});
  }
  return a;
}

Json gridPointsJson(const StudySummary& s) {
  Json a = Json::array();
  for (const GridPointSummary& g : s.grid_points) {
    Json inputs = Json::object(), outcomes = Json::object(), probabilities = Json::object();
    for (const auto& [name, value] : g.inputs) inputs[name] = value;
    for (const GridPointSummary::Outcome& o : g.outcomes) outcomes[o.name] = Json{{"mean", o.mean}, {"q95", o.q95}, {"max", o.max}};
    for (const auto& [name, p] : g.probabilities) probabilities[name] = p;
    a.push_back(Json{{"grid_point", g.index}, {"inputs", inputs}, {"count", g.count}, {"failed", g.failed},
                     {"outcomes", outcomes}, {"probabilities", probabilities}});
  }
  return a;
}

Json digests(const std::vector<SampleDigest>& list) {
  Json a = Json::array();
  for (const SampleDigest& d : list) {
    Json inputs = Json::object();
    for (const auto& [name, value] : d.inputs) inputs[name] = value;
    a.push_back(Json{{"sample", d.sample}, {"objective", d.objective}, {"inputs", inputs}});
  }
  return a;
}

}  // namespace

void writeStudyGroups(std::ostream& out, const StudySummary& s) {
  if (s.grid_points.empty()) return;
  const GridPointSummary& first = s.grid_points.front();
  for (const auto& [name, v] : first.inputs) out << name << ",";
  out << "count,failed";
  for (const GridPointSummary::Outcome& o : first.outcomes) out << "," << o.name << ".mean," << o.name << ".q95," << o.name << ".max";
  for (const auto& [name, p] : first.probabilities) out << ",P(" << name << ")";
  out << "\n";
  char buf[32];
  const auto number = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.17g", v);  // reads back exactly, as the table's
    return buf;
  };
  for (const GridPointSummary& g : s.grid_points) {
    for (const auto& [name, v] : g.inputs) out << number(v) << ",";
    out << g.count << "," << g.failed;
    for (const GridPointSummary::Outcome& o : g.outcomes)
      for (const double v : {o.mean, o.q95, o.max}) out << "," << number(v);
    for (const auto& [name, p] : g.probabilities) out << "," << number(p);
    out << "\n";
  }
}

Json studySummaryJson(const Study& st, const StudySummary& s, const std::string& table) {
  Json outcomes = Json::object(), probabilities = Json::object(), failures = Json::array();
  for (const OutcomeSummary& o : s.outcomes) outcomes[o.name] = quantiles(o);
  for (const auto& [name, p] : s.probabilities) probabilities[name] = p;
  for (const StudyFailure& f : s.failures)
    failures.push_back(Json{{"status", f.status}, {"count", f.count}, {"first_sample", f.first_sample}, {"message", f.message}});
  Json grid_inputs = Json::array();
  for (const StudyInput& in : st.inputs)
    if (in.distribution.kind == Distribution::Kind::Grid) grid_inputs.push_back(in.name);
  Json j{{"study", st.file},       {"fingerprint", fingerprintText(st)},          {"table", table.empty() ? Json(nullptr) : Json(table)},
         {"samples", s.samples},   {"failed", s.failed},         {"seed", st.seed},
         {"outcomes", outcomes},   {"probabilities", probabilities}, {"objective", st.objective},
         {"best", digests(s.best)}, {"worst", digests(s.worst)}, {"failures", failures},
         {"quantile_rank_error", s.quantile_rank_error},
         {"grid_inputs", grid_inputs}, {"grid_points", gridPointsJson(s)}};
  if (!st.objective_statistic.empty()) {  // the grid points ranked (a plain objective ranks samples only)
    j["objective_statistic"] = st.objective_statistic;
    j["best_grid_points"] = gridDigests(s.best_grid_points);
    j["worst_grid_points"] = gridDigests(s.worst_grid_points);
  }
  return j;
}

}  // namespace kdl_space::report
