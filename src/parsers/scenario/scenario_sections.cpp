#include "parsers/scenario/scenario_sections.hpp"

#include <cmath>

#include "spatial/message_text.hpp"

namespace kdl_space::sections {
namespace {

using detail::listNames;
using detail::number;
using fields::echo;
using fields::Field;

/// One joint's control: free, locked or {pd: {kp, kd, set_point: NUMBER | hold}}.
JointControl jointControl(const Field& j) {
  JointControl c;
  if (j.isScalar()) {
    const std::string mode = j.text();
    if (mode == "free") c.mode = JointControl::Mode::Free;
    else if (mode == "locked") c.mode = JointControl::Mode::Locked;
    else j.fail(echo(mode) + " is not one of free, locked, {pd: {kp, kd, set_point}}");
    return c;
  }
  j.onlyKeys({"pd"});
  const Field pd = j.at("pd");
  pd.onlyKeys({"kp", "kd", "set_point"});
  c.mode = JointControl::Mode::PD;
  c.kp = pd.at("kp").number();
  c.kd = pd.at("kd").number();
  const Field set_point = pd.at("set_point");
  if (set_point.isScalar() && set_point.text() == "hold") c.hold = true;
  else c.set_point = set_point.number();
  if (c.kp < 0.0) pd.at("kp").fail("must be >= 0, got " + number(c.kp));
  if (c.kd < 0.0) pd.at("kd").fail("must be >= 0, got " + number(c.kd));
  return c;
}

LimitMode limitMode(const Field& f) {
  const std::string mode = f.text();
  if (mode == "warn") return LimitMode::Warn;
  if (mode == "stop") return LimitMode::Stop;
  if (mode == "ignore") return LimitMode::Ignore;
  f.fail(echo(mode) + " is not one of warn, stop, ignore");
}

/// Gains kp, kd (>= 0) and a limit per axis (> 0; default none) of a base controller.
void gains(const Field& f, const char* limit_key, double& kp, double& kd, Vector3d& limit) {
  kp = f.at("kp").number();
  kd = f.at("kd").number();
  if (kp < 0.0) f.at("kp").fail("must be >= 0, got " + number(kp));
  if (kd < 0.0) f.at("kd").fail("must be >= 0, got " + number(kd));
  if (f.has(limit_key)) {
    limit = f.at(limit_key).perAxis();
    if (!(limit.array() > 0.0).all()) f.at(limit_key).fail("must be > 0 on every axis");
  }
}

BaseControl baseControl(const Field& f) {
  f.onlyKeys({"attitude", "position", "phases"});
  BaseControl c;
  if (f.has("phases")) {  // where it acts: said, not implied (the approach only when asked)
    const Field ph = f.at("phases");
    c.after_capture = false;
    for (const Field& name : ph.items("phases [approach, after]")) {
      if (name.text() == "approach") c.in_approach = true;
      else if (name.text() == "after") c.after_capture = true;
      else name.fail(echo(name.text()) + " is not one of approach, after");
    }
    if (!c.in_approach && !c.after_capture)
      ph.fail("is empty: give approach, after or both (the default is [after]), or leave out base_control");
  }
  if (f.has("attitude")) {
    const Field a = f.at("attitude");
    a.onlyKeys({"kp", "kd", "set_point", "torque_limit"});
    BaseControl::Attitude& att = c.attitude;
    att.on = true;
    gains(a, "torque_limit", att.kp, att.kd, att.torque_limit);
    const Field sp = a.at("set_point");
    if (sp.isScalar()) {
      if (sp.text() != "hold") sp.fail(echo(sp.text()) + " is not one of hold, {rpy: [r, p, y]}, {quaternion: [x, y, z, w]}");
      att.hold = true;
    } else {
      sp.onlyKeys({"rpy", "quaternion"});
      if (sp.has("rpy") == sp.has("quaternion")) sp.fail("give one of rpy, quaternion");
      if (sp.has("rpy")) {
        const Eigen::VectorXd r = sp.at("rpy").angles(3);
        att.set_point = KDL::Rotation::RPY(r(0), r(1), r(2));
      } else {
        const Eigen::VectorXd q = sp.at("quaternion").vector(4);
        if (std::abs(q.norm() - 1.0) > 1e-6)
          sp.at("quaternion").fail("is not a rotation: a unit quaternion has norm 1, this one " + number(q.norm()));
        att.set_point = KDL::Rotation::Quaternion(q(0), q(1), q(2), q(3));
      }
    }
  }
  if (f.has("position")) {
    const Field p = f.at("position");
    p.onlyKeys({"kp", "kd", "set_point", "force_limit"});
    BaseControl::Position& pos = c.position;
    pos.on = true;
    gains(p, "force_limit", pos.kp, pos.kd, pos.force_limit);
    const Field sp = p.at("set_point");
    if (sp.isScalar()) {
      if (sp.text() != "hold") sp.fail(echo(sp.text()) + " is not one of hold, [x, y, z]");
      pos.hold = true;
    } else {
      pos.set_point = sp.vector(3);
    }
  }
  return c;
}

ScheduledWrench wrench(const Field& f, const FloatingModel& robot) {
  f.onlyKeys({"link", "point", "force", "torque", "frame", "start", "end"});
  ScheduledWrench w;
  const std::string link = f.at("link").text();
  const int body = robot.bodyIndex(link);
  if (body < 0) {
    std::vector<std::string> links;
    for (const Body& b : robot.bodies()) links.push_back(b.name);
    f.at("link").fail("the robot has no link " + echo(link) + " (its links: " + listNames(links) + ")");
  }
  w.body = static_cast<unsigned int>(body);
  if (f.has("point")) w.point = f.at("point").vector(3);
  if (f.has("force")) w.wrench.head<3>() = f.at("force").vector(3);
  if (f.has("torque")) w.wrench.tail<3>() = f.at("torque").vector(3);
  if (f.has("frame")) {
    const std::string frame = f.at("frame").text();
    if (frame == "link") w.body_axes = true;
    else if (frame != "world") f.at("frame").fail(echo(frame) + " is not one of world, link");
  }
  w.start = f.at("start").number();
  if (f.has("end")) {
    w.end = f.at("end").number();
    if (!(w.end > w.start)) f.at("end").fail("must be after start (" + number(w.start) + " s), got " + number(w.end));
  }
  return w;
}

/// `after_capture: {law: hold | momentum_distribution, unload_gain}`: the law of the motion after
/// the capture; momentum_distribution drives the robot's PD servos and unloads through the base's
/// attitude control, so it needs both.
void afterCapture(const Field& section, SimulationSpec& s) {
  const Field f = section.at("after_capture");
  f.onlyKeys({"law", "unload_gain", "bandwidth", "stiffness", "damping"});
  const Field law = f.at("law");
  if (law.text() == "hold") s.after_capture = SimulationSpec::Law::Hold;
  else if (law.text() == "momentum_distribution") s.after_capture = SimulationSpec::Law::MomentumDistribution;
  else if (law.text() == "impedance") s.after_capture = SimulationSpec::Law::Impedance;
  else law.fail(echo(law.text()) + " is not one of hold, momentum_distribution, impedance");
  const bool impedance = s.after_capture == SimulationSpec::Law::Impedance;
  for (const auto& [key, value] : {std::pair{"stiffness", &s.impedance_stiffness}, std::pair{"damping", &s.impedance_damping}}) {
    if (!f.has(key)) continue;
    if (!impedance) f.at(key).fail("is impedance's: the law is " + law.text());
    *value = f.at(key).vector(2);
    if ((value->array() < 0.0).any())
      f.at(key).fail("each value must be >= 0 (translation, rotation), got " + number(value->minCoeff()));
  }
  if (impedance) {
    if (!(s.impedance_damping.maxCoeff() > 0.0)) f.at("damping").fail("the arm is a damper at the grasp: give it some damping");
    bool servo = false;
    for (const auto& [j, c] : s.joints) servo = servo || c.mode == JointControl::Mode::PD;
    if (!servo)
      law.fail("impedance drives the arm's servos: give the robot's joints pd servos in simulation.joints (the law "
               "replaces them; their kd damps a redundant arm's self-motion)");
    if (s.grounded.value_or(false)) law.fail("impedance holds the target on a free base; this base is grounded");
  }
  if (f.has("unload_gain")) {
    if (s.after_capture != SimulationSpec::Law::MomentumDistribution)
      f.at("unload_gain").fail("is momentum_distribution's: the law is " + law.text());
    s.unload_gain = f.at("unload_gain").number();
    if (s.unload_gain < 0.0) f.at("unload_gain").fail("must be >= 0 [1/s], got " + number(s.unload_gain));
  }
  if (f.has("bandwidth")) {
    if (s.after_capture != SimulationSpec::Law::MomentumDistribution)
      f.at("bandwidth").fail("is momentum_distribution's: the law is " + law.text());
    s.bandwidth = f.at("bandwidth").number();
    if (!(s.bandwidth > 0.0)) f.at("bandwidth").fail("must be > 0 [1/s], got " + number(s.bandwidth));
  }
  if (s.after_capture != SimulationSpec::Law::MomentumDistribution) return;
  bool servo = false;
  for (const auto& [j, c] : s.joints) servo = servo || c.mode == JointControl::Mode::PD;
  if (!servo)
    law.fail("momentum_distribution drives the arm's servos: give the robot's joints pd servos in simulation.joints "
             "(the law drives their rates, at after_capture.bandwidth)");
  if (!s.base_control.attitude.on || !s.base_control.after_capture)
    law.fail("momentum_distribution unloads the arm through the base's attitude control: give "
             "simulation.base_control.attitude (acting after the capture), with robot.base_actuators.wheels");
  if (s.grounded.value_or(false)) law.fail("momentum_distribution keeps a free base from turning; this base is grounded");
}

}  // namespace

SimulationSpec simulation(const Field& f, const FloatingModel& robot, const FloatingModel* target) {
  f.onlyKeys({"duration", "output_step", "integrator", "step", "rtol", "atol", "max_step", "max_steps", "gravity",
              "joints", "base", "limits", "effort_limits", "friction", "friction_velocity", "base_control", "wrenches",
              "target_joints", "after_capture", "detumble_rate"});
  SimulationSpec s;
  const auto positive = [&](const char* key, double& value) {
    if (!f.has(key)) return;
    value = f.at(key).number();
    if (!(value > 0.0)) f.at(key).fail("must be > 0, got " + number(value));
  };
  positive("duration", s.duration);
  positive("output_step", s.output_step);
  positive("step", s.options.step);
  positive("rtol", s.options.rtol);
  positive("atol", s.options.atol);
  positive("max_step", s.options.max_step);
  positive("friction_velocity", s.options.friction_velocity);
  if (f.has("max_steps")) {
    const double budget = f.at("max_steps").number();
    if (!(budget >= 1.0) || budget != std::floor(budget) || budget > 1e12)
      f.at("max_steps").fail("must be a whole number of steps from 1 to 1e12, got " + number(budget));
    s.options.max_steps = static_cast<long>(budget);
  }
  if (f.has("integrator")) {
    const Field integrator = f.at("integrator");
    try {
      s.options.integrator = integratorFromName(integrator.text());
    } catch (const InputError& e) {
      integrator.fail(e.what());  // the file, line and field in front of the library's message
    }
  }
  if (f.has("gravity")) s.options.gravity = f.at("gravity").vector(3);
  if (f.has("base")) {
    const std::string base = f.at("base").text();
    if (base == "free") s.grounded = false;
    else if (base == "grounded") s.grounded = true;
    else f.at("base").fail(echo(base) + " is not one of free, grounded");
  }
  if (f.has("effort_limits")) s.options.effort_limits = f.at("effort_limits").flag();
  if (f.has("friction")) s.options.joint_friction = f.at("friction").flag();
  if (f.has("joints")) s.joints = byJoint<JointControl>(f.at("joints"), robot, jointControl);
  if (f.has("target_joints")) {  // a captured free-floating target's own joints, after the capture
    if (!target) f.at("target_joints").fail("only a free-floating target (target.urdf with movable joints) has joints");
    s.target_joints = byJoint<JointControl>(f.at("target_joints"), *target, jointControl);
  }
  if (f.has("limits")) {
    const Field limits = f.at("limits");
    if (limits.isScalar()) {
      const LimitMode mode = limitMode(limits);
      for (unsigned int j = 0; j < robot.nj(); ++j) {
        const JointProperties& p = robot.jointProperties()[j];
        // "stop" for all: the joints with limits (a continuous joint has none to stop at)
        if (mode != LimitMode::Stop || (std::isfinite(p.lower) && std::isfinite(p.upper))) s.limits.emplace_back(j, mode);
      }
    } else {
      for (const auto& [j, mode] : byJoint<LimitMode>(limits, robot, limitMode)) {
        const JointProperties& p = robot.jointProperties()[j];
        const std::string& name = robot.jointNames()[j];
        if (mode == LimitMode::Stop && !(std::isfinite(p.lower) && std::isfinite(p.upper))) {
          if (limits.has(name))
            limits.at(name).fail("joint " + echo(name) + " has no position limits (a continuous joint): it has no stop");
          continue;  // a pattern's stop passes over a continuous joint
        }
        s.limits.emplace_back(j, mode);
      }
    }
  }
  if (f.has("base_control")) s.base_control = baseControl(f.at("base_control"));
  if (f.has("wrenches"))
    for (const Field& w : f.at("wrenches").items("wrenches {link, force, torque, start, end}")) s.wrenches.push_back(wrench(w, robot));
  if (f.has("after_capture")) afterCapture(f, s);
  if (f.has("detumble_rate")) {  // [rad/s] or {deg_per_s: ...}
    s.detumble_rate = f.at("detumble_rate").angle(true);
    if (!(s.detumble_rate > 0.0)) f.at("detumble_rate").fail("must be > 0, got " + number(s.detumble_rate));
  }
  return s;
}

void groundForTheCapture(const Field& base, FloatingSystem& robot) {
  if (toEigen(robot.velocity.base_twist) != Vector6d::Zero())
    base.fail("grounded holds the base still, in the capture too, but robot.base.twist is not zero: give it zero, "
              "or simulation.base: free");
  robot.response = Response::Grounded;  // the capture's base held as the motion's (not free, then refused)
}

}  // namespace kdl_space::sections
