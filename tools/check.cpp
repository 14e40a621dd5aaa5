#include "check.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "cli_common.hpp"
#include "kdl_space/urdf_check.hpp"

namespace kdl_space::cli {
namespace {

std::string plural(std::size_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

/// A number for JSON: null when not finite (JSON has no NaN or infinity).
Json jsonNumber(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json findingsJson(const std::vector<Finding>& findings) {
  Json list = Json::array();
  for (const Finding& f : findings) list.push_back(Json{{"kind", f.kind}, {"element", f.element}, {"message", f.message}});
  return list;
}

Json summaryJson(const ModelSummary& m) {
  Json j;
  j["robot"] = m.robot;
  j["base"] = m.base.empty() ? Json(nullptr) : Json(m.base);
  j["links"] = m.links;
  j["joints"] = m.joints;
  j["loaded"] = m.loaded;
  j["joint_names"] = m.loaded ? Json(m.joint_names) : Json(nullptr);
  j["total_mass"] = m.loaded ? Json(m.total_mass) : Json(nullptr);
  j["condition_H_star"] = m.loaded ? jsonNumber(m.condition_H_star) : Json(nullptr);
  Json g = Json::array();
  for (const auto& [link, condition] : m.condition_G_star) g.push_back(Json{{"link", link}, {"condition", jsonNumber(condition)}});
  j["condition_G_star"] = g;
  return j;
}

/// One line about the model that loaded: what it is and how well conditioned at q = 0.
std::string modelNote(const ModelSummary& m) {
  std::ostringstream s;
  s << "base '" << m.base << "', " << plural(m.links, "link") << ", " << plural(m.joint_names.size(), "movable joint")
    << ", total mass " << m.total_mass << " kg";
  if (!m.joint_names.empty()) s << "; at q = 0: cond(H*) = " << m.condition_H_star;
  for (std::size_t i = 0; i < m.condition_G_star.size(); ++i)
    s << (i == 0 ? (m.joint_names.empty() ? "; at q = 0: cond(G*) = " : ", cond(G*) = ") : ", ")
      << m.condition_G_star[i].second << " at '" << m.condition_G_star[i].first << "'";
  return s.str();
}

}  // namespace

CLI::App* addCheck(CLI::App& app, CheckOptions& o) {
  CLI::App* cmd = app.add_subcommand("check", "Report every problem of a URDF file as a free-floating model");
  cmd->add_option("FILE", o.urdf, "URDF file; its root link is the free-floating base")->required();
  cmd->add_option("--tip", o.tips, "Contact link to check and to compute G* at (repeat for several)")
      ->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--json", o.json, "Print one JSON object: errors, warnings, notes, model");
  cmd->add_flag("--strict", o.strict, "Exit with 3 on warnings too");
  return cmd;
}

int runCheck(const CheckOptions& o, std::ostream& out) {
  const UrdfReport report = checkUrdfFile(o.urdf, o.tips);
  const bool failed = !report.errors.empty() || (o.strict && !report.warnings.empty());
  if (o.json) {
    Json j;
    j["errors"] = findingsJson(report.errors);
    j["warnings"] = findingsJson(report.warnings);
    j["notes"] = findingsJson(report.notes);
    j["model"] = summaryJson(report.model);
    // Names and values come from the file as written: replace what is not UTF-8.
    out << std::setprecision(17) << j.dump(2, ' ', false, Json::error_handler_t::replace) << "\n";
  } else {
    for (const Finding& f : report.errors) out << report.source << ": error: " << describe(f) << "\n";
    for (const Finding& f : report.warnings) out << report.source << ": warning: " << describe(f) << "\n";
    for (const Finding& f : report.notes) out << report.source << ": note: " << describe(f) << "\n";
    if (report.model.loaded) out << report.source << ": note: " << modelNote(report.model) << "\n";
    out << plural(report.errors.size(), "error") << ", " << plural(report.warnings.size(), "warning");
    if (o.strict && !report.warnings.empty()) out << " (--strict: warnings fail the check)";
    out << "\n";
  }
  return failed ? kUnusable : kOk;
}

}  // namespace kdl_space::cli
