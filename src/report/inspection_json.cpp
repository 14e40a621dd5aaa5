#include "kdl_space/report/inspection_json.hpp"

#include <cmath>
#include <variant>

namespace kdl_space::report {

Json poseJson(const PoseFigures& f) {
  return Json{{"position", toJson(f.position)},
              {"rotation", toJson(f.rotation)},
              {"quaternion", toJson(f.quaternion)},  // (x, y, z, w), as every *_quaternion of the JSON
              {"rpy", toJson(f.rpy)}};
}

Json conditioningJson(const Conditioning& c) {
  const auto finite = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  return Json{{"J_star_singular_values", toJson(c.sigma_J_star)},
              {"J_star_condition_number", finite(c.condition_number)},  // null: singular
              {"J_star_manipulability", c.manipulability_J_star},
              {"J_manipulability", c.manipulability_J}};
}

Json jointMarginsJson(const FloatingModel& model, const std::vector<JointMargin>& margins) {
  Json j = Json::object();
  for (const JointMargin& m : margins)
    j[model.jointNames()[m.joint]] = m.limited ? Json{{"margin", m.margin()},
                                                      {"to_lower", std::isfinite(m.to_lower) ? Json(m.to_lower) : Json(nullptr)},
                                                      {"to_upper", std::isfinite(m.to_upper) ? Json(m.to_upper) : Json(nullptr)}}
                                               : Json(nullptr);  // continuous: no limits
  return j;
}

Json warningsJson(const std::vector<Diagnostic>& warnings) {
  Json j = Json::array();
  for (const Diagnostic& d : warnings) {
    Json w{{"kind", d.kind}, {"element", d.element}, {"message", d.message}};
    for (const auto& [key, value] : d.details)  // an overlap's depth and moment, ...
      w[key] = std::holds_alternative<double>(value) ? Json(std::get<double>(value)) : Json(std::get<std::string>(value));
    j.push_back(std::move(w));
  }
  return j;
}

Json contactInspectionJson(const ContactInspection& c, const Contact& h, const std::string& link) {
  return Json{{"link", link},
              {"offset", toJson(toEigen(h.offset))},
              {"point", toJson(c.point)},
              {"J_star", toJsonRows(c.J_star)},  // 6 x n, even for n = 1
              {"G_star", toJson(c.G_star)},
              {"G_grounded", c.G_grounded ? toJson(*c.G_grounded) : Json(nullptr)},
              {"G_locked", toJson(c.G_locked)},
              {"pose", poseJson(poseFigures(c.frame))},
              {"conditioning", conditioningJson(c.conditioning)}};
}

Json inspectionJson(const FloatingModel& model, const Inspection& figures, const State& state, const Json& json_contacts,
                 const std::vector<std::string>& diagnostics, const std::vector<Diagnostic>& warnings) {
  Json j;
  j["mass"] = figures.mass;
  j["com"] = toJson(figures.r_g);
  j["I_g"] = toJson(figures.I_g);
  j["joint_names"] = model.jointNames();
  j["joints_treated_as_fixed"] = fixedJointsJson(model);
  // n x n, even for n = 1; null above kDenseJoints joints (not formed: a diagnostic says so)
  j["H_star"] = figures.dense ? toJsonRows(figures.H_star) : Json(nullptr);
  j["contacts"] = json_contacts;
  j["G_star_all"] = toJson(figures.G_star_all);
  j["joint_margins"] = jointMarginsJson(model, jointMargins(model, state.q));
  j["diagnostics"] = diagnostics;
  j["warnings"] = warningsJson(warnings);
  return j;
}

}  // namespace kdl_space::report
