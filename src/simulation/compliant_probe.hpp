// The compliant capture's reading of the joined state (src/simulation/compliant_capture.cpp): the
// grasp's torques and wrench, the relative speed and the springs' energy, each side's own state.
#pragma once

#include <Eigen/LU>
#include <cmath>

#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/simulation/compliant_capture.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::detail {

/// The grasp joints' order is (x, y, z, rz, ry, rx); the law's axes are (x, y, z, about x, y, z).
constexpr int kAxisOf[6] = {0, 1, 2, 5, 4, 3};

/// Reads the joined state at the samples: the grasp's wrench, the sides' own momenta.
class Probe {
 public:
  Probe(const JoinedSystem& js, const FloatingSystem& robot, const FloatingSystem& target, const Vector6d& K,
        const Vector6d& D)
      : js_(js), robot_(robot), target_(target), K_(K), D_(D), kin_(*js.model), rkin_(*robot.model),
        tkin_(*target.model), rmom_(robot.model), tmom_(target.model), jmom_(js.model) {
    const FloatingModel& m = *js.model;
    for (int k = 0; k < 6; ++k)
      for (std::size_t b = 0; b < m.bodies().size(); ++b)
        if (m.bodies()[b].joint == js.grasp_joints[k]) body_[k] = static_cast<int>(b);
    robot_contact_ = robot.contact;  // the robot's bodies keep their indices in the joined model
    target_base_ = m.bodyIndex(js.target_prefix + target.model->bodies()[0].name);
  }
  /// tau on the grasp joints (model order of the grasp: x, y, z, rz, ry, rx).
  double torque(int k, const SimulationState& s) const {
    const int j = js_.grasp_joints[k], a = kAxisOf[k];
    return -K_(a) * s.state.q(j) - D_(a) * s.velocity.qdot(j);
  }
  double relativeSpeed2(const SimulationState& s) const {
    double sum = 0.0;
    for (int k = 0; k < 6; ++k) sum += K_(kAxisOf[k]) * std::pow(s.velocity.qdot(js_.grasp_joints[k]), 2);
    return sum;
  }
  /// dV/dt of the springs' energy V: q^T K qdot over the grasp joints.
  double springPower(const SimulationState& s) const {
    double P = 0.0;
    for (int k = 0; k < 6; ++k) {
      const int j = js_.grasp_joints[k];
      P += K_(kAxisOf[k]) * s.state.q(j) * s.velocity.qdot(j);
    }
    return P;
  }
  double springEnergy(const State& st) const {
    double V = 0.0;
    for (int k = 0; k < 6; ++k) V += 0.5 * K_(kAxisOf[k]) * std::pow(st.q(js_.grasp_joints[k]), 2);
    return V;
  }
  /// The sample: the wrench W on the target's side of the grasp solves S^T W = tau (the massless
  /// grasp links pass it on unchanged); the robot gets -W, moved to its contact point.
  ContactSample sample(const SimulationState& s, double t0) {
    ContactSample out;
    out.t = s.t - t0;
    if (forwardKinematics(*js_.model, s.state, kin_)) throw InputError("contact: the joined state cannot be computed");
    Matrix6d S;
    Vector6d tau;
    for (int k = 0; k < 6; ++k) {
      S.col(k) = kin_.S[body_[k]];
      tau(k) = torque(k, s);
      out.deflection(k) = s.state.q(js_.grasp_joints[k]);
    }
    const Vector6d W = S.transpose().fullPivLu().solve(tau);
    const Vector3d f = -W.head<3>();
    const Vector3d n_b = -W.tail<3>();  // about the base origin p_b
    const Vector3d p_c = kin_.point(robot_contact_);
    out.wrench << f, n_b - (p_c - kin_.p_b).cross(f);
    return out;
  }
  /// Splits the joined state into each side's own state and velocity, and their momenta.
  void split(const SimulationState& s, FloatingSystem& r_end, FloatingSystem& t_end, Vector6d& h_r, Vector6d& h_t) {
    const FloatingModel& rm = *robot_.model;
    const FloatingModel& tm = *target_.model;
    r_end = robot_;
    t_end = target_;
    State& rs = r_end.state;
    State& ts = t_end.state;
    FloatingVelocity& rv = r_end.velocity;
    FloatingVelocity& tv = t_end.velocity;
    rs.world_T_base = s.state.world_T_base;
    rv = FloatingVelocity(rm);
    rv.base_twist = s.velocity.base_twist;
    for (unsigned int j = 0; j < rm.nj(); ++j) {
      rs.q(j) = s.state.q(js_.robot_joints[j]);
      rv.qdot(j) = s.velocity.qdot(js_.robot_joints[j]);
    }
    if (forwardKinematics(*js_.model, s.state, kin_)) throw InputError("contact: the joined state cannot be computed");
    if (jmom_.compute(kin_, s.velocity)) throw InputError("contact: the joined velocity cannot be computed");
    Vector6d base_twist;
    jmom_.contactTwist(Contact{target_base_, KDL::Vector::Zero()}, base_twist);
    ts.world_T_base = kin_.pose(target_base_);
    tv = FloatingVelocity(tm);
    tv.base_twist = KDL::Twist(KDL::Vector(base_twist(0), base_twist(1), base_twist(2)),
                               KDL::Vector(base_twist(3), base_twist(4), base_twist(5)));
    for (unsigned int j = 0; j < tm.nj(); ++j) {
      ts.q(j) = js_.target_joint_sign[j] * s.state.q(js_.target_joints[j]);
      tv.qdot(j) = js_.target_joint_sign[j] * s.velocity.qdot(js_.target_joints[j]);
    }
    if (forwardKinematics(rm, rs, rkin_) || rmom_.compute(rkin_, rv) || forwardKinematics(tm, ts, tkin_) ||
        tmom_.compute(tkin_, tv))
      throw InputError("contact: a side's state after the contact cannot be computed");
    h_r = rmom_.momentum();
    h_t = tmom_.momentum();
  }

 private:
  const JoinedSystem& js_;
  const FloatingSystem& robot_;
  const FloatingSystem& target_;
  Vector6d K_, D_;
  Kinematics kin_, rkin_, tkin_;
  MomentumSolver rmom_, tmom_, jmom_;  ///< each side's, the joined system's (built once)
  int body_[6] = {0, 0, 0, 0, 0, 0};
  Contact robot_contact_;
  int target_base_ = -1;
};

}  // namespace kdl_space::detail
