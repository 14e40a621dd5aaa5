// The scenario's `law` section (scenario_law.hpp).
#include "parsers/scenario/scenario_law.hpp"

#include <string>

#include "spatial/message_text.hpp"

namespace kdl_space::laws {

using detail::number;
using fields::echo;
using fields::Field;

CompliantGrasp compliantLaw(const Field& f) {
  f.onlyKeys({"type", "normal", "stiffness", "damping", "damping_time", "catch_tolerance", "max_duration", "lock",
              "max_grasp_wrench"});
  CompliantGrasp g;
  const auto six = [&](const char* key, bool zero_ok) {
    const Vector6d v = f.at(key).vector(6);
    for (int k = 0; k < 6; ++k)
      if (v(k) < 0.0 || (!zero_ok && v(k) == 0.0))
        f.at(key).fail(std::string("each value must be ") + (zero_ok ? ">= 0" : "> 0") + " (x, y, z [N/m or N s/m]; about "
                       "x, y, z [N m/rad or N m s/rad]), got " + number(v(k)));
    return v;
  };
  if (f.has("stiffness")) g.stiffness = six("stiffness", false);
  if (f.has("damping") && f.has("damping_time"))
    f.at("damping_time").fail("give damping (per axis) or damping_time (D = damping_time * stiffness), not both");
  if (f.has("damping")) g.damping = six("damping", true);
  const auto positive = [&](const char* key, double& value, double upper) {
    if (!f.has(key)) return;
    value = f.at(key).number();
    if (!(value >= 0.0) || value > upper || (value == 0.0 && std::string(key) != "damping_time"))
      f.at(key).fail("must be " + std::string(std::string(key) == "damping_time" ? ">= 0" : "> 0") +
                     (upper < 1e300 ? " and < " + number(upper) : std::string()) + ", got " + number(value));
  };
  positive("damping_time", g.damping_time, 1e308);
  positive("max_duration", g.max_duration, 1e308);
  positive("catch_tolerance", g.catch_tolerance, 1.0);
  if (g.catch_tolerance >= 1.0) f.at("catch_tolerance").fail("must be < 1, got " + number(g.catch_tolerance));
  if (f.has("lock")) {
    const std::string lock = f.at("lock").text();
    if (lock == "never") g.lock = GraspLock::Never;
    else if (lock == "tolerance") g.lock = GraspLock::Tolerance;
    else if (lock == "spring_maximum") g.lock = GraspLock::SpringMaximum;
    else
      f.at("lock").fail(echo(lock) + " is not one of never (the grasp stays compliant), tolerance (it locks when the "
                        "relative speed has fallen to law.catch_tolerance), spring_maximum (also when the springs' "
                        "energy peaks)");
  }
  if (f.has("normal")) {
    const Vector3d n = f.at("normal").vector(3);
    if (!(n.norm() > 1e-12)) f.at("normal").fail("has zero length");
    g.normal = n.normalized();
  }
  return g;
}

void graspLimit(const Field& f, double& force, double& moment) {
  if (!f.has("max_grasp_wrench")) return;
  const Field limit = f.at("max_grasp_wrench");
  const std::string type = f.at("type").text();
  if (type != "capture" && type != "compliant" && type != "translational")
    limit.fail("a " + type + " impact holds nothing after it: the grasp's limit goes with a capture or compliant law");
  limit.onlyKeys({"force", "moment"});
  if (!limit.has("force") && !limit.has("moment")) limit.fail("give force [N], moment [N m], or both");
  const auto positive = [&](const char* key, double& value) {
    if (!limit.has(key)) return;
    value = limit.at(key).number();
    if (!(value > 0.0)) limit.at(key).fail("must be > 0, got " + number(value));
  };
  positive("force", force);
  positive("moment", moment);
}

ImpactLaw law(const Field& f, bool& has_normal) {
  ImpactLaw l;
  if (f.at("type").text() == "compliant") {  // the impulsive limit: a rigid capture
    has_normal = f.has("normal");
    if (has_normal) l.normal = f.at("normal").vector(3).normalized();
    return l;
  }
  f.onlyKeys({"type", "normal", "restitution", "friction", "max_grasp_wrench"});
  const std::string type = f.at("type").text();
  if (type == "capture") l.kind = ImpactKind::Capture;
  else if (type == "point") l.kind = ImpactKind::PointImpact;
  else if (type == "friction") l.kind = ImpactKind::FrictionalImpact;
  else if (type == "translational") l.kind = ImpactKind::TranslationalCapture;
  else f.at("type").fail(echo(type) + " is not one of capture, point, friction, translational, compliant");
  const bool point = l.kind == ImpactKind::PointImpact || l.kind == ImpactKind::FrictionalImpact;
  has_normal = f.has("normal");
  if (point && !has_normal) f.at("normal");  // reports "missing"
  if (has_normal) {
    const Vector3d n = f.at("normal").vector(3);
    if (!(n.norm() > 1e-12)) f.at("normal").fail("has zero length");
    l.normal = n.normalized();
  }
  if (f.has("restitution")) {
    l.restitution = f.at("restitution").number();
    if (l.restitution < 0.0 || l.restitution > 1.0) f.at("restitution").fail("must lie in [0, 1], got " + number(l.restitution));
  } else if (point) {
    f.at("restitution");  // reports "missing"
  }
  if (f.has("friction")) {
    l.friction = f.at("friction").number();
    if (l.friction < 0.0) f.at("friction").fail("must be >= 0, got " + number(l.friction));
  } else if (l.kind == ImpactKind::FrictionalImpact) {
    f.at("friction");  // reports "missing"
  }
  return l;
}

}  // namespace kdl_space::laws
