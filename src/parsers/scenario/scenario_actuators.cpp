#include "parsers/scenario/scenario_actuators.hpp"

#include <cmath>

#include "spatial/message_text.hpp"

namespace kdl_space::sections {
namespace {

using detail::number;
using fields::Field;

/// One value per wheel: a number for every wheel, or a list of m; each > 0 (`what`: its unit).
Eigen::VectorXd perWheel(const Field& f, Eigen::Index m, bool positive) {
  Eigen::VectorXd v = f.isSequence() ? f.vector(static_cast<int>(m)) : Eigen::VectorXd::Constant(m, f.number());
  for (Eigen::Index i = 0; i < m; ++i)
    if (positive ? !(v(i) > 0.0) : false)
      f.fail("must be > 0 for every wheel, got " + number(v(i)) + (m > 1 ? " for wheel " + std::to_string(i + 1) : ""));
  return v;
}

ReactionWheels wheels(const Field& f, Eigen::VectorXd& momentum) {
  f.onlyKeys({"axes", "torque_limit", "capacity", "momentum"});
  ReactionWheels w;
  if (f.has("axes")) {  // one spin axis per wheel, in the base's frame
    const std::vector<Field> axes = f.at("axes").items("axes [[x, y, z], ...] (one per wheel, base frame)");
    if (axes.empty()) f.at("axes").fail("is empty: give one axis [x, y, z] per wheel, or leave it out (one wheel per base axis)");
    w.axes.resize(3, static_cast<Eigen::Index>(axes.size()));
    for (std::size_t i = 0; i < axes.size(); ++i) {
      const Eigen::VectorXd a = axes[i].vector(3);
      if (a.norm() < 1e-9) axes[i].fail("is zero: a wheel's spin axis has a direction");
      w.axes.col(static_cast<Eigen::Index>(i)) = a.normalized();
    }
  } else {
    w.axes = Eigen::Matrix3d::Identity();
  }
  const Eigen::Index m = w.count();
  w.torque_limit = perWheel(f.at("torque_limit"), m, true);
  w.capacity = perWheel(f.at("capacity"), m, true);
  momentum = f.has("momentum") ? perWheel(f.at("momentum"), m, false) : Eigen::VectorXd::Zero(m);
  for (Eigen::Index i = 0; i < m; ++i)
    if (std::abs(momentum(i)) > w.capacity(i))
      f.at("momentum").fail("wheel " + std::to_string(i + 1) + " starts at " + number(momentum(i)) +
                            " N m s, past its capacity " + number(w.capacity(i)) + " N m s");
  return w;
}

}  // namespace

BaseActuators baseActuators(const Field& f) {
  f.onlyKeys({"wheels", "thrusters"});
  BaseActuators a;
  a.given = true;
  if (f.has("wheels")) a.wheels = wheels(f.at("wheels"), a.wheel_momentum);
  if (f.has("thrusters")) {
    const Field t = f.at("thrusters");
    t.onlyKeys({"force_limit", "torque_limit"});
    a.thrusters = true;
    for (const char* key : {"force_limit", "torque_limit"}) {
      if (!t.has(key)) continue;
      const Vector3d limit = t.at(key).perAxis();
      if (!(limit.array() > 0.0).all()) t.at(key).fail("must be > 0 on every axis");
      (std::string(key) == "force_limit" ? a.thruster_force : a.thruster_torque) = limit;
    }
    if (!t.has("force_limit") && !t.has("torque_limit")) t.fail("give force_limit [N] and/or torque_limit [N m] (per base axis)");
  }
  if (!f.has("wheels") && !f.has("thrusters")) f.fail("give wheels and/or thrusters");
  return a;
}

void checkBaseControlHardware(const BaseActuators& a, const BaseControl& control, const Field& base_control) {
  if (!a.given) return;  // no hardware given: the base control's own limits, as before
  const bool wheel_torque = a.wheels.count() > 0;
  const bool thruster_torque = a.thrusters && std::isfinite(a.thruster_torque.maxCoeff());
  const bool thruster_force = a.thrusters && std::isfinite(a.thruster_force.maxCoeff());
  if (control.attitude.on && !wheel_torque && !thruster_torque)
    base_control.at("attitude").fail("robot.base_actuators has neither wheels nor thrusters' torque_limit to turn the base with");
  if (control.position.on && !thruster_force)
    base_control.at("position").fail("robot.base_actuators has no thrusters' force_limit to move the base with");
}

}  // namespace kdl_space::sections
