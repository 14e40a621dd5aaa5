#include "motion_report.hpp"

#include <cmath>
#include <sstream>

namespace kdl_space::cli {
namespace {

Json finiteOrNull(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

const char* integratorName(Integrator i) {
  return i == Integrator::RK4 ? "rk4" : i == Integrator::Rosenbrock ? "rosenbrock" : "dopri5";
}

double meanStep(const MotionRecord& r) {
  const long steps = r.sim.stats().accepted_steps;
  return steps == 0 ? 0.0 : (r.t_reached - r.t_start) / static_cast<double>(steps);
}

}  // namespace

std::string stiffnessAdvice(const MotionRecord& r) {
  const Stiffness& st = r.stiffness;
  const SimulationOptions& o = r.sim.options();
  if (st.fastest_joint < 0) return {};
  const std::string joint = "'" + r.sim.model().jointNames()[st.fastest_joint] + "'";
  std::ostringstream why;
  why.precision(3);
  if (o.integrator == Integrator::RK4 && o.step > st.explicit_step) {
    why << "simulation.step = " << o.step << " s is above the stable step " << st.explicit_step
        << " s of joint " << joint << " (closed-loop rate " << st.fastest_rate
        << " 1/s): lower the step or the gains, or use integrator: rosenbrock";
    return why.str();
  }
  // An explicit adaptive run whose steps are far below the output step, with a servo fast enough
  // to hold them there.
  const double mean = meanStep(r);
  if (o.integrator == Integrator::DormandPrince54 && mean > 0.0 && mean < 0.01 * r.output_step &&
      st.explicit_step < 0.01 * r.output_step) {
    why << "stiff: the servo of joint " << joint << " (closed-loop rate " << st.fastest_rate
        << " 1/s) holds dopri5's step near " << mean << " s (" << r.sim.stats().accepted_steps
        << " steps): try integrator: rosenbrock (an rtol of 1e-6 or looser suits it)";
    return why.str();
  }
  return {};
}

Json limitViolationsJson(const MotionRecord& r) {
  Json list = Json::array();
  const FloatingModel& m = r.sim.model();
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointRecord& rec = r.sim.stats().joints[j];
    if (std::isnan(rec.limit_first_time) && rec.stops == 0) continue;
    const JointProperties& p = m.jointProperties()[j];
    list.push_back(Json{{"joint", m.jointNames()[j]},
                        {"lower", p.lower},
                        {"upper", p.upper},
                        {"mode", r.sim.limitModes()[j] == LimitMode::Stop ? "stop" : "warn"},
                        {"first_time", finiteOrNull(rec.limit_first_time)},
                        {"worst", finiteOrNull(rec.limit_worst)},
                        {"stops", rec.stops}});
  }
  return list;
}

Json saturationJson(const MotionRecord& r) {
  Json joints = Json::array();
  const FloatingModel& m = r.sim.model();
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointRecord& rec = r.sim.stats().joints[j];
    if (rec.saturation_time <= 0.0) continue;
    joints.push_back(Json{{"joint", m.jointNames()[j]},
                          {"effort_limit", m.jointProperties()[j].effort},
                          {"first_time", finiteOrNull(rec.saturation_first_time)},
                          {"time", rec.saturation_time}});
  }
  return Json{{"effort_limits", r.sim.options().effort_limits},
              {"joints", joints},
              {"base_control_time", r.sim.stats().base_saturation_time}};
}

Json energySplitJson(const MotionRecord& r) {
  const Sample& first = r.samples.front();
  const Sample& last = r.samples.back();
  const double dT = last.T - first.T, work = last.work.sum();
  return Json{{"controller", last.work(0)},   {"friction", last.work(1)},  {"limits", last.work(2)},
              {"base_control", last.work(3)}, {"wrenches", last.work(4)},  {"gravity", last.work(5)},
              {"total_work", work},           {"kinetic_energy_change", dT}, {"residual", dT - work}};
}

std::pair<double, double> momentumBalance(const std::vector<Sample>& samples) {
  double dP = 0.0, dL = 0.0;
  for (const Sample& x : samples) {
    const Eigen::Matrix<double, 6, 1> e = x.h - samples.front().h - x.impulse;
    dP = std::max(dP, e.head<3>().norm());
    dL = std::max(dL, e.tail<3>().norm());
  }
  return {dP, dL};
}

Json baseControlJson(const MotionRecord& r) {
  const BaseControl& c = r.sim.baseControl();
  if (!c.on()) return nullptr;
  const Sample& last = r.samples.back();
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
  const auto [dP, dL] = momentumBalance(r.samples);
  j["impulse"] = toJson(last.impulse);
  j["momentum_balance_error"] = Json{{"linear", dP}, {"angular", dL}};
  return j;
}

Json stiffnessJson(const MotionRecord& r) {
  const Stiffness& st = r.stiffness;
  const SimulationStats& stats = r.sim.stats();
  const std::string advice = stiffnessAdvice(r);
  return Json{{"fastest_rate", st.fastest_rate},
              {"fastest_joint", st.fastest_joint < 0 ? Json(nullptr) : Json(r.sim.model().jointNames()[st.fastest_joint])},
              {"explicit_stable_step", finiteOrNull(st.explicit_step)},
              {"integrator", integratorName(r.sim.options().integrator)},
              {"min_step", stats.min_step},
              {"max_step", stats.max_step},
              {"mean_step", meanStep(r)},
              {"stiff", !advice.empty()},
              {"advice", advice.empty() ? Json(nullptr) : Json(advice)}};
}

Json frictionJson(const MotionRecord& r) {
  const FloatingModel& m = r.sim.model();
  Json joints = Json::array();
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointProperties& p = m.jointProperties()[j];
    if (p.damping == 0.0 && p.friction == 0.0) continue;
    joints.push_back(Json{{"joint", m.jointNames()[j]},
                          {"damping", p.damping},
                          {"friction", p.friction},
                          {"regularisation_velocity", r.sim.frictionVelocities()[j]}});
  }
  return Json{{"on", r.sim.options().joint_friction}, {"joints", joints}};
}

void printMotionReport(std::ostream& out, const MotionRecord& r) {
  const FloatingModel& m = r.sim.model();
  for (std::size_t j = 0; j < m.nj(); ++j) {
    const JointRecord& rec = r.sim.stats().joints[j];
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
  if (r.sim.stats().base_saturation_time > 0.0)
    out << "Base control at its limits for " << r.sim.stats().base_saturation_time << " s\n";
  const Sample& last = r.samples.back();
  const Sample& first = r.samples.front();
  if (last.work.cwiseAbs().maxCoeff() > 0.0)
    out << "Work done [J]: controller " << last.work(0) << ", friction " << last.work(1) << ", limits " << last.work(2)
        << ", base control " << last.work(3) << ", wrenches " << last.work(4) << ", gravity " << last.work(5)
        << "; kinetic energy change " << last.T - first.T << "\n";
  if (r.sim.baseControl().on()) {
    const auto [dP, dL] = momentumBalance(r.samples);
    out << "Base control: external impulse (f; n about the origin) " << last.impulse.transpose()
        << "; momentum balance error " << dP << " N s, " << dL << " N m s\n";
  }
  const std::string advice = stiffnessAdvice(r);
  if (!advice.empty()) out << "Hint: " << advice << "\n";
}

}  // namespace kdl_space::cli
