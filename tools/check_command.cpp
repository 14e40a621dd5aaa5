#include "check_command.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <iomanip>
#include <sstream>

#include "cli_common.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"

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
  Json props = Json::array();  // limits (null: none), damping, friction of each movable joint
  for (std::size_t i = 0; i < m.joint_properties.size() && i < m.joint_names.size(); ++i) {
    const JointProperties& p = m.joint_properties[i];
    props.push_back(Json{{"joint", m.joint_names[i]}, {"lower", jsonNumber(p.lower)}, {"upper", jsonNumber(p.upper)},
                         {"effort", jsonNumber(p.effort)}, {"velocity", jsonNumber(p.velocity)},
                         {"damping", p.damping}, {"friction", p.friction}});
  }
  j["joint_properties"] = m.loaded ? props : Json(nullptr);
  Json fixed = Json::array();
  for (const FixedJoint& f : m.joints_treated_as_fixed) fixed.push_back(Json{{"joint", f.joint}, {"reason", f.reason}});
  j["joints_treated_as_fixed"] = m.loaded ? fixed : Json(nullptr);
  return j;
}

/// One line of what the joints' <limit> and <dynamics> gave (the values are in --json).
std::string propertiesNote(const ModelSummary& m) {
  std::size_t position = 0, effort = 0, velocity = 0, damping = 0, friction = 0;
  for (const JointProperties& p : m.joint_properties) {
    position += std::isfinite(p.lower) || std::isfinite(p.upper);
    effort += std::isfinite(p.effort);
    velocity += std::isfinite(p.velocity);
    damping += p.damping > 0.0;
    friction += p.friction > 0.0;
  }
  std::ostringstream s;
  s << "of the " << plural(m.joint_properties.size(), "movable joint") << ": position limits on " << position
    << ", effort limits on " << effort << ", velocity limits on " << velocity << ", damping on " << damping
    << ", friction on " << friction << " (values in --json)";
  return s.str();
}

/// Whether condition number `a` is worse than `b`: larger, infinite, or not a number at all.
bool worse(double a, double b) {
  const auto rank = [](double c) { return std::isnan(c) ? 2 : std::isinf(c) ? 1 : 0; };
  return rank(a) != rank(b) ? rank(a) > rank(b) : rank(a) == 0 && a > b;
}

/// Leaves named in the note when no --tip was given; the JSON has them all.
constexpr std::size_t kLeavesInNote = 3;

/// One line about the model that loaded: what it is and how well conditioned at q = 0. cond(G*)
/// at every requested tip, in their order; without --tip, at the kLeavesInNote worst leaves,
/// worst first, and how many more the JSON holds.
std::string modelNote(const ModelSummary& m, bool tips_requested) {
  std::ostringstream s;
  s << "base '" << m.base << "', " << plural(m.links, "link") << ", " << plural(m.joint_names.size(), "movable joint")
    << ", total mass " << m.total_mass << " kg";
  if (!m.joint_names.empty() && std::isnan(m.condition_H_star)) s << "; at q = 0: cond(H*) not computed (see the note)";
  else if (!m.joint_names.empty()) s << "; at q = 0: cond(H*) = " << m.condition_H_star;
  std::vector<std::pair<std::string, double>> shown = m.condition_G_star;
  std::size_t more = 0;
  if (!tips_requested) {
    std::stable_sort(shown.begin(), shown.end(), [](const auto& a, const auto& b) { return worse(a.second, b.second); });
    if (shown.size() > kLeavesInNote) {
      more = shown.size() - kLeavesInNote;
      shown.resize(kLeavesInNote);
    }
  }
  for (std::size_t i = 0; i < shown.size(); ++i)
    s << (i == 0 ? (m.joint_names.empty() ? "; at q = 0: cond(G*) = " : ", cond(G*) = ") : ", ")
      << shown[i].second << " at '" << shown[i].first << "'";
  if (more)
    s << " (the " << kLeavesInNote << " largest), and " << more << " more " << (more == 1 ? "leaf" : "leaves")
      << " (all in --json)";
  return s.str();
}

/// The notes, one line each; a kind with more than kNotesOfAKind of them (massless frames of a
/// large robot) in one line that names the first few (--json lists each).
void printNotes(std::ostream& out, const UrdfReport& report) {
  constexpr std::size_t kNotesOfAKind = 3;
  std::map<std::string, std::vector<const Finding*>> by_kind;
  for (const Finding& f : report.notes) by_kind[f.kind].push_back(&f);
  for (const Finding& f : report.notes) {
    const std::vector<const Finding*>& same = by_kind[f.kind];
    if (same.size() <= kNotesOfAKind) {
      out << report.source << ": note: " << describe(f) << "\n";
    } else if (same.front() == &f) {  // the kind's line, where its first note stands
      std::ostringstream names;
      for (std::size_t k = 0; k < kNotesOfAKind; ++k) names << (k ? ", '" : "'") << same[k]->element << "'";
      out << report.source << ": note: " << same.size() << " notes " << f.kind << " (" << names.str() << " and "
          << same.size() - kNotesOfAKind << " more; each in --json), e.g. " << describe(f) << "\n";
    }
  }
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
  const UrdfReport report = checkRobotFile(o.urdf, o.tips);
  stopIfInterrupted("check " + o.urdf + ": after the checks");
  const bool failed = !report.errors.empty() || (o.strict && !report.warnings.empty());
  if (o.json) {
    Json j;
    j["errors"] = findingsJson(report.errors);
    j["warnings"] = findingsJson(report.warnings);
    j["notes"] = findingsJson(report.notes);
    j["model"] = summaryJson(report.model);
    // Names and values come from the file as written: replace what is not UTF-8.
    out << std::setprecision(17) << jsonText(j, 2) << "\n";
  } else {
    for (const Finding& f : report.errors) out << report.source << ": error: " << describe(f) << "\n";
    for (const Finding& f : report.warnings) out << report.source << ": warning: " << describe(f) << "\n";
    printNotes(out, report);
    if (report.model.loaded) {
      if (!report.model.joint_properties.empty())
        out << report.source << ": note: " << propertiesNote(report.model) << "\n";
      out << report.source << ": note: " << modelNote(report.model, !o.tips.empty()) << "\n";
    }
    out << plural(report.errors.size(), "error") << ", " << plural(report.warnings.size(), "warning");
    if (o.strict && !report.warnings.empty()) out << " (--strict: warnings fail the check)";
    out << "\n";
  }
  return failed ? kUnusable : kOk;
}

}  // namespace kdl_space::cli
