#include "kdl_space/report/motion_report.hpp"

#include <cmath>
#include <sstream>

namespace kdl_space::report {
namespace {

Json finiteOrNull(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

}  // namespace

Json limitViolationsJson(const MotionRecord& r) {
  Json list = Json::array();
  const FloatingModel& m = *r.model;
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointRecord& rec = r.stats.joints[j];
    if (std::isnan(rec.limit_first_time) && rec.stops == 0) continue;
    const JointProperties& p = m.jointProperties()[j];
    list.push_back(Json{{"joint", m.jointNames()[j]},
                        {"lower", p.lower},
                        {"upper", p.upper},
                        {"mode", r.limit_modes[j] == LimitMode::Stop ? "stop" : "warn"},
                        {"first_time", finiteOrNull(rec.limit_first_time)},
                        {"worst", finiteOrNull(rec.limit_worst)},
                        {"stops", rec.stops}});
  }
  return list;
}

Json saturationJson(const MotionRecord& r) {
  Json joints = Json::array();
  const FloatingModel& m = *r.model;
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointRecord& rec = r.stats.joints[j];
    if (rec.saturation_time <= 0.0) continue;
    joints.push_back(Json{{"joint", m.jointNames()[j]},
                          {"effort_limit", m.jointProperties()[j].effort},
                          {"first_time", finiteOrNull(rec.saturation_first_time)},
                          {"time", rec.saturation_time}});
  }
  return Json{{"effort_limits", r.options.effort_limits},
              {"joints", joints},
              {"base_control_time", r.stats.base_saturation_time}};
}

Json jointTorquesJson(const MotionRecord& r) {
  const FloatingModel& m = *r.model;
  Json joints = Json::array();
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const double peak = static_cast<Eigen::Index>(j) < r.peak_torque.size() ? r.peak_torque(static_cast<Eigen::Index>(j)) : 0.0;
    const double effort = m.jointProperties()[j].effort;
    const bool limited = std::isfinite(effort) && effort > 0.0;
    joints.push_back(Json{{"joint", m.jointNames()[j]},
                          {"peak_torque", peak},
                          {"effort_limit", limited ? Json(effort) : Json(nullptr)},
                          {"fraction_of_effort", limited ? Json(peak / effort) : Json(nullptr)}});
  }
  return joints;
}

Json energySplitJson(const MotionRecord& r) {
  const MotionSample& first = r.first;
  const MotionSample& last = r.last;
  const double dT = last.T - first.T, work = last.work.sum();
  return Json{{"controller", last.work(0)},   {"friction", last.work(1)},  {"limits", last.work(2)},
              {"base_control", last.work(3)}, {"wrenches", last.work(4)},  {"gravity", last.work(5)},
              {"total_work", work},           {"kinetic_energy_change", dT}, {"residual", dT - work}};
}

Json baseControlJson(const MotionRecord& r) {
  const BaseControl& c = r.base_control;
  if (!c.on()) return nullptr;
  const MotionSample& last = r.last;
  Json j;
  if (c.attitude.on) {
    double x, y, z, w;
    c.attitude.set_point.GetQuaternion(x, y, z, w);
    const KDL::Rotation R = KDL::Rotation::Quaternion(last.quat(0), last.quat(1), last.quat(2), last.quat(3));
    j["attitude"] = Json{{"set_point_quaternion", {x, y, z, w}},
                         {"final_error", (c.attitude.set_point * R.Inverse()).GetRot().Norm()}};
  }
  if (c.position.on)
    j["position"] = Json{{"set_point", toJson(c.position.set_point)}, {"final_error", (c.position.set_point - last.p).norm()}};
  const double dP = r.balance_linear, dL = r.balance_angular;
  j["impulse"] = toJson(last.impulse);
  j["momentum_balance_error"] = Json{{"linear", dP}, {"angular", dL}};
  return j;
}

Json wheelsJson(const MotionRecord& r) {
  const ReactionWheels& w = r.wheels;
  if (w.count() == 0) return nullptr;
  Json list = Json::array();
  for (Eigen::Index i = 0; i < w.count(); ++i) {
    const double peak = r.wheel_peak_momentum.size() > i ? r.wheel_peak_momentum(i) : 0.0;
    list.push_back(Json{{"axis", toJson(Vector3d(w.axes.col(i)))},
                        {"torque_limit", w.torque_limit(i)},
                        {"capacity", w.capacity(i)},
                        {"momentum_start", r.first.wheel_momentum.size() > i ? r.first.wheel_momentum(i) : 0.0},
                        {"momentum_final", r.last.wheel_momentum.size() > i ? r.last.wheel_momentum(i) : 0.0},
                        {"peak_momentum", peak},
                        {"peak_fraction_of_capacity", peak / w.capacity(i)},
                        {"peak_torque", r.wheel_peak_torque.size() > i ? r.wheel_peak_torque(i) : 0.0}});
  }
  return Json{{"wheels", list},
              {"saturation_time", r.stats.wheel_saturation_time},
              {"saturation_first_time", finiteOrNull(r.stats.wheel_saturation_first_time)}};
}

Json detumbleJson(const MotionRecord& r) {
  return Json{{"detumble_rate", r.detumble.threshold},
              {"time_to_detumble", finiteOrNull(r.detumble.value())},
              {"peak_base_rate", r.peak_base_rate},
              {"final_base_rate", r.last.twist.tail<3>().norm()},
              {"attitude_excursion", r.attitude_excursion},
              {"wheel_momentum_fraction", finiteOrNull(r.wheelMomentumFraction())},
              {"energy_dissipated", r.energyDissipated()}};
}

Json graspLoadJson(const MotionRecord& r, double max_force, double max_moment) {
  const GraspPeak& g = r.grasp;
  if (!g.held()) return nullptr;
  const auto limit = [](double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); };
  const auto fraction = [](double peak, double x) { return std::isfinite(x) ? Json(peak / x) : Json(nullptr); };
  return Json{{"peak_force", g.force},
              {"t_peak_force", g.t_force},
              {"peak_moment", g.moment},
              {"t_peak_moment", g.t_moment},
              {"max_force", limit(max_force)},
              {"max_moment", limit(max_moment)},
              {"force_fraction_of_limit", fraction(g.force, max_force)},
              {"moment_fraction_of_limit", fraction(g.moment, max_moment)}};
}

Json stiffnessJson(const MotionRecord& r) {
  const Stiffness& st = r.stiffness;
  const SimulationStats& stats = r.stats;
  const std::string advice = stiffnessAdvice(r);
  return Json{{"fastest_rate", st.fastest_rate},
              {"fastest_joint", st.fastest_joint < 0 ? Json(nullptr) : Json(r.model->jointNames()[st.fastest_joint])},
              {"explicit_stable_step", finiteOrNull(st.explicit_step)},
              {"integrator", toString(r.options.integrator)},
              {"min_step", stats.min_step},
              {"max_step", stats.max_step},
              {"mean_step", r.meanStep()},
              {"stiff", !advice.empty()},
              {"advice", advice.empty() ? Json(nullptr) : Json(advice)}};
}

Json frictionJson(const MotionRecord& r) {
  const FloatingModel& m = *r.model;
  Json joints = Json::array();
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointProperties& p = m.jointProperties()[j];
    if (p.damping == 0.0 && p.friction == 0.0) continue;
    joints.push_back(Json{{"joint", m.jointNames()[j]},
                          {"damping", p.damping},
                          {"friction", p.friction},
                          {"regularisation_velocity", r.friction_velocities[j]}});
  }
  return Json{{"on", r.options.joint_friction}, {"joints", joints}};
}

void printMotionReport(std::ostream& out, const MotionRecord& r) {
  const FloatingModel& m = *r.model;
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointRecord& rec = r.stats.joints[j];
    const JointProperties& p = m.jointProperties()[j];
    if (rec.stops > 0)
      out << "Joint '" << m.jointNames()[j] << "' hit its stop " << rec.stops << " time" << (rec.stops > 1 ? "s" : "")
          << " (limits [" << p.lower << ", " << p.upper << "])\n";
    if (!std::isnan(rec.limit_first_time))
      out << "Warning: joint '" << m.jointNames()[j] << "' left its limits [" << p.lower << ", " << p.upper
          << "] at t = " << rec.limit_first_time << " s (worst " << rec.limit_worst
          << "); `limits: stop` makes them hard stops\n";
    if (rec.saturation_time > 0.0)
      out << "Joint '" << m.jointNames()[j] << "': torque at its effort limit " << p.effort << " for "
          << rec.saturation_time << " s from t = " << rec.saturation_first_time << " s\n";
  }
  if (r.stats.base_saturation_time > 0.0)
    out << "Base control at its limits for " << r.stats.base_saturation_time << " s\n";
  if (r.wheels.count() > 0 && r.wheel_peak_momentum.size() == r.wheels.count()) {
    Eigen::Index worst = 0;
    (r.wheel_peak_momentum.array() / r.wheels.capacity.array()).maxCoeff(&worst);
    out << "Reaction wheels: peak momentum " << r.wheel_peak_momentum(worst) << " N m s of "
        << r.wheels.capacity(worst) << " (wheel " << worst + 1 << " of " << r.wheels.count() << ")";
    if (r.stats.wheel_saturation_time > 0.0)
      out << "; saturated (torque limit or capacity) for " << r.stats.wheel_saturation_time << " s from t = "
          << r.stats.wheel_saturation_first_time << " s";
    out << "\n";
  }
  Eigen::Index worst = -1;  // the joint nearest its effort limit
  double fraction = 0.0;
  for (Eigen::Index j = 0; j < r.peak_torque.size(); ++j) {
    const double effort = m.jointProperties()[static_cast<std::size_t>(j)].effort;
    if (std::isfinite(effort) && effort > 0.0 && r.peak_torque(j) / effort >= fraction) fraction = r.peak_torque(j) / effort, worst = j;
  }
  if (worst >= 0)
    out << "Joint torques: at most " << 100.0 * fraction << " % of an effort limit (joint '"
        << m.jointNames()[static_cast<std::size_t>(worst)] << "', " << r.peak_torque(worst) << " of "
        << m.jointProperties()[static_cast<std::size_t>(worst)].effort << ")\n";
  if (r.grasp.held())
    out << "Grasp load: peak force " << r.grasp.force << " N at t = " << r.grasp.t_force << " s, peak moment "
        << r.grasp.moment << " N m at t = " << r.grasp.t_moment << " s (on the robot at its contact point)\n";
  const MotionSample& last = r.last;
  const MotionSample& first = r.first;
  if (r.samples > 1) {
    out << "Detumble: the base's rate " << r.peak_base_rate << " rad/s at most, " << last.twist.tail<3>().norm()
        << " at the end; ";
    if (std::isnan(r.detumble.value())) out << "not below " << r.detumble.threshold << " rad/s (simulation.detumble_rate) by the end";
    else out << "below " << r.detumble.threshold << " rad/s for good after " << r.detumble.value() << " s";
    out << "; attitude excursion " << r.attitude_excursion << " rad; " << r.energyDissipated() << " J dissipated\n";
  }
  if (last.work.cwiseAbs().maxCoeff() > 0.0)
    out << "Work done [J]: controller " << last.work(0) << ", friction " << last.work(1) << ", limits " << last.work(2)
        << ", base control " << last.work(3) << ", wrenches " << last.work(4) << ", gravity " << last.work(5)
        << "; kinetic energy change " << last.T - first.T << "\n";
  if (r.base_control.on()) {
    const double dP = r.balance_linear, dL = r.balance_angular;
    out << "Base control: external impulse (f; n about the origin) " << last.impulse.transpose()
        << "; momentum balance error " << dP << " N s, " << dL << " N m s\n";
  }
  const std::string advice = stiffnessAdvice(r);
  if (!advice.empty()) out << "Hint: " << advice << "\n";
}

}  // namespace kdl_space::report
