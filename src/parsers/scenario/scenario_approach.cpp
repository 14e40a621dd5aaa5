#include "parsers/scenario/scenario_approach.hpp"

#include <cmath>

#include "spatial/message_text.hpp"
#include "parsers/scenario/scenario_sections.hpp"

namespace kdl_space::sections {

using detail::number;
using fields::echo;
using fields::Field;

ApproachSpec approach(const Field& f, const FloatingModel& robot, const KDL::Vector* grasp_position) {
  f.onlyKeys({"grasp", "track", "gain", "damping", "singular_threshold", "rate_limits", "servo_bandwidth", "null_space",
              "tolerance", "max_duration", "pre_grasp", "joint_limits"});
  ApproachSpec a;
  const auto positive = [](const Field& owner, const char* key, double& value) {
    if (!owner.has(key)) return;
    value = owner.at(key).number();
    if (!(value > 0.0)) owner.at(key).fail("must be > 0, got " + number(value));
  };
  const Field grasp = f.at("grasp");  // required: in the target's frame
  grasp.onlyKeys({"position", "rpy"});
  const Eigen::VectorXd p = grasp_position && !grasp.has("position") ? Eigen::VectorXd(toEigen(*grasp_position))
                                                                      : grasp.at("position").vector(3);
  const Eigen::VectorXd r = grasp.has("rpy") ? grasp.at("rpy").angles(3) : Eigen::VectorXd::Zero(3);
  a.grasp = KDL::Frame(KDL::Rotation::RPY(r(0), r(1), r(2)), KDL::Vector(p(0), p(1), p(2)));
  if (f.has("track")) {
    const std::string track = f.at("track").text();
    if (track == "pose") a.orientation = true;
    else if (track == "position") a.orientation = false;
    else f.at("track").fail(echo(track) + " is not one of pose, position");
  }
  positive(f, "gain", a.gain);
  positive(f, "singular_threshold", a.threshold);
  positive(f, "servo_bandwidth", a.servo_bandwidth);
  positive(f, "max_duration", a.max_duration);
  if (f.has("damping")) {
    a.damping = f.at("damping").number();
    if (a.damping < 0.0) f.at("damping").fail("must be >= 0, got " + number(a.damping));
  }
  if (f.has("null_space")) {
    const std::string task = f.at("null_space").text();
    if (task == "none") a.null_space = NullSpaceTask::None;
    else if (task == "reaction") a.null_space = NullSpaceTask::Reaction;
    else f.at("null_space").fail(echo(task) + " is not one of none, reaction");
  }
  // Rate limits: the URDF's velocity limits, overridden by name or pattern (or "*").
  a.rate_limits = defaultRateLimits(robot);
  if (f.has("rate_limits")) {
    const auto limit = [](const Field& e) {
      const double v = e.number();
      if (!(v > 0.0)) e.fail("must be > 0 (rad/s or m/s), got " + number(v));
      return v;
    };
    for (const auto& [j, v] : byJoint<double>(f.at("rate_limits"), robot, limit)) a.rate_limits[j] = v;
  }
  if (f.has("pre_grasp")) {  // {} for the defaults
    const Field g = f.at("pre_grasp");
    g.onlyKeys({"standoff", "rate", "acceleration"});
    ApproachSpec::PreGrasp pre;
    if (g.has("standoff")) {
      pre.standoff = g.at("standoff").number();
      if (!(pre.standoff >= 0.0)) g.at("standoff").fail("must be >= 0 [m], got " + number(pre.standoff));
    }
    positive(g, "rate", pre.rate);
    if (pre.rate > 1.0) g.at("rate").fail("is the fraction of each joint's rate limit the move may use: at most 1, got " + number(pre.rate));
    positive(g, "acceleration", pre.acceleration);
    a.pre_grasp = pre;
  }
  if (f.has("joint_limits")) {
    const Field l = f.at("joint_limits");
    l.onlyKeys({"zone", "gain"});
    if (l.has("zone")) {
      a.limit_zone = l.at("zone").number();
      if (!(a.limit_zone >= 0.0 && a.limit_zone < 0.5))
        l.at("zone").fail("is the fraction of each joint's range near a limit where it is pushed away: [0, 0.5), got " +
                          number(a.limit_zone));
    }
    positive(l, "gain", a.limit_gain);
  }
  if (f.has("tolerance")) {
    const Field t = f.at("tolerance");
    t.onlyKeys({"position", "orientation", "speed"});
    positive(t, "position", a.position_tolerance);
    positive(t, "orientation", a.orientation_tolerance);
    positive(t, "speed", a.speed_tolerance);
  }
  return a;
}

}  // namespace kdl_space::sections
