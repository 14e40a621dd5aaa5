#include "kdl_space/parsers/scenario/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kdl_space {

StepEstimate fewestSteps(const SimulationSpec& spec, double duration, double output_step) {
  const bool rk4 = spec.options.integrator == Integrator::RK4;
  const double step = rk4 ? spec.options.step : spec.options.max_step;
  StepEstimate e;
  e.longest = std::min(step, output_step);
  e.limited_by = e.longest == output_step ? "output_step" : rk4 ? "step" : "max_step";
  e.steps = std::ceil(duration / e.longest * (1.0 - 1e-12));  // 1e-12: a duration a whole number of steps
  return e;
}

std::unique_ptr<Simulator> makeSimulator(const Scenario& sc, const std::shared_ptr<const FloatingModel>& model,
                                         bool approach) {
  const SimulationSpec& spec = sc.simulation;
  const FloatingSystem& robot = sc.capture.robot;
  const auto jointIn = [&](unsigned int j) {  // a joint of the robot's model, in `model`
    return static_cast<unsigned int>(model->jointIndex(robot.model->jointNames()[j]));
  };
  SimulationOptions options = spec.options;
  options.grounded = spec.grounded.value_or(robot.response == Response::Grounded);
  auto sim = std::make_unique<Simulator>(model, options);
  JointControl locked;
  locked.mode = JointControl::Mode::Locked;
  for (unsigned int j = 0; j < robot.model->nj(); ++j)
    if (robot.response == Response::JointsLocked || (!robot.locked.empty() && robot.locked[j]))
      sim->setJointControl(jointIn(j), locked);
  if (!approach)
    for (const auto& [joint, control] : spec.joints) sim->setJointControl(jointIn(joint), control);
  for (const auto& [joint, mode] : spec.limits) sim->setLimitMode(jointIn(joint), mode);
  // The base's actuators, and its control in the phases the scenario names (base_control.phases;
  // default: after) within their limits.
  const BaseActuators& hardware = sc.base_actuators;
  if (hardware.wheels.count() > 0 && !options.grounded) sim->setReactionWheels(hardware.wheels);
  if (approach ? spec.base_control.in_approach : spec.base_control.after_capture) {
    BaseControl control = spec.base_control;
    if (hardware.given) {
      control.position.force_limit = control.position.force_limit.cwiseMin(hardware.thruster_force);
      if (hardware.wheels.count() == 0)
        control.attitude.torque_limit = control.attitude.torque_limit.cwiseMin(hardware.thruster_torque);
    }
    sim->setBaseControl(control);
  }
  if (!approach && spec.after_capture == SimulationSpec::Law::MomentumDistribution) {
    MomentumDistribution law;  // over the robot's PD servos, at their joints' rate limits
    law.on = true;
    law.unload_gain = spec.unload_gain;
    law.bandwidth = spec.bandwidth;
    law.joints.assign(model->nj(), false);
    law.rate_limit = Eigen::VectorXd::Constant(model->nj(), std::numeric_limits<double>::infinity());
    for (unsigned int j = 0; j < model->nj(); ++j) law.rate_limit(j) = model->jointProperties()[j].velocity;
    for (const auto& [joint, control] : spec.joints)
      if (control.mode == JointControl::Mode::PD) law.joints[jointIn(joint)] = true;
    sim->setMomentumDistribution(law);
  }
  if (!approach && spec.after_capture == SimulationSpec::Law::Impedance) {
    GraspImpedance law;  // over the robot's PD servos, at its contact point, within the grasp's limit
    law.on = true;
    law.joints.assign(model->nj(), false);
    for (const auto& [joint, control] : spec.joints)
      if (control.mode == JointControl::Mode::PD) law.joints[jointIn(joint)] = true;
    law.contact.body = model->bodyIndex(robot.model->bodies()[robot.contact.body].name);
    law.contact.offset = robot.contact.offset;
    law.stiffness = spec.impedance_stiffness;
    law.damping = spec.impedance_damping;
    law.max_force = sc.max_grasp_force;
    law.max_moment = sc.max_grasp_moment;
    sim->setGraspImpedance(law);
  }
  for (ScheduledWrench w : spec.wrenches) {
    w.body = static_cast<unsigned int>(model->bodyIndex(robot.model->bodies()[w.body].name));
    sim->addWrench(w);
  }
  return sim;
}

}  // namespace kdl_space
