// The approach (resolved motion rate control with J*) and the free motion of a rigid target,
// against independent routes:
//   1. FreeRigidMotion: a spin about a principal axis in closed form; in general the world angular
//      momentum and the energy stay what they were (Euler's equations are not used to check);
//   2. along an approach simulated in the real floating dynamics, the hand's twist by the O(n)
//      momentum route (MomentumSolver, from the integrated base twist) equals J* qdot (dense
//      route) with zero momentum, and J* qdot plus eq. 4's R_h term with momentum;
//   3. the approach converges on a reachable grasp point, fixed or on a tumbling target, and
//      says how close it came to an unreachable one;
//   4. the reaction null space turns the base less than the minimum-norm rates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "kdl_space/simulation/approach.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "rigid_targets.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

ModelPtr arm() { return std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf")); }

SimulationState startState(const FloatingModel& model) {
  SimulationState s;
  s.state = State(model);
  s.velocity = FloatingVelocity(model);
  const char* names[] = {"joint2", "joint3", "joint4", "joint6"};
  const double q[] = {0.7, 0.9, 0.8, -0.6};
  for (int k = 0; k < 4; ++k) s.state.q(model.jointIndex(names[k])) = q[k];
  return s;
}

Contact hand(const FloatingModel& model) { return model.contact("end_effector", KDL::Vector(0, 0, 0.05)); }

/// The hand's position at s (forward kinematics).
Vector3d handAt(const FloatingModel& model, const State& state) {
  Kinematics kin(model);
  EXPECT_EQ(forwardKinematics(model, state, kin), E_NOERROR);
  return kin.point(hand(model));
}

TEST(FreeRigidMotion, SpinAboutAPrincipalAxisIsAUniformRotation) {
  RigidTarget t = box(Vector3d(1, 2, 3), Vector6d::Zero());
  const Vector3d axis_body = Vector3d::UnitY();  // a principal axis of the box
  const double rate = 0.7;
  const Matrix3d R0 = toEigen(t.pose.M);
  t.twist << 0.1, -0.2, 0.05, rate * (R0 * axis_body);
  FreeRigidMotion motion(t);
  for (double time : {0.0, 0.0004, 1.2345, 7.0}) {
    RigidTarget at;
    ASSERT_EQ(motion.at(time, at), E_NOERROR);
    const Matrix3d expected = Eigen::AngleAxisd(rate * time, R0 * axis_body).toRotationMatrix() * R0;
    EXPECT_TRUE(near(toEigen(at.pose.M), expected, 1e-12, 1e-12)) << time;
    EXPECT_TRUE(near(toEigen(at.pose.p), Vector3d(1, 2, 3) + time * Vector3d(0.1, -0.2, 0.05), 1e-12, 1e-12));
    EXPECT_TRUE(near(at.twist.tail<3>(), rate * (R0 * axis_body), 1e-12, 1e-12));
  }
}

TEST(FreeRigidMotion, TumblingKeepsItsAngularMomentumAndEnergy) {
  Vector6d twist;
  twist << 0, 0, 0, 0.4, -0.9, 0.6;  // not about a principal axis: the angular velocity wanders
  RigidTarget t = box(Vector3d::Zero(), twist);
  t.com = Vector3d(0.1, 0.0, -0.2);
  FreeRigidMotion motion(t);
  const auto momentum = [](const RigidTarget& b) {
    const Matrix3d R = toEigen(b.pose.M);
    return Vector3d(R * b.inertia * R.transpose() * b.twist.tail<3>());
  };
  const Vector3d L0 = momentum(t);
  const double T0 = 0.5 * twist.tail<3>().dot(L0);
  RigidTarget later, again;
  ASSERT_EQ(motion.at(20.0, later), E_NOERROR);
  EXPECT_GT((later.twist.tail<3>() - twist.tail<3>()).norm(), 0.1);  // it did wander
  EXPECT_TRUE(near(momentum(later), L0, 1e-10, 1e-12));
  EXPECT_NEAR(0.5 * later.twist.tail<3>().dot(momentum(later)), T0, 1e-10 * T0);
  // the CoM (not the frame's origin) moves on its straight line: here it stays put
  EXPECT_TRUE(near(toEigen(later.pose * toKDL(t.com)), toEigen(t.pose * toKDL(t.com)), 1e-12, 1e-12));
  // a function of time alone: asking earlier times afterwards gives the same answer
  ASSERT_EQ(motion.at(3.21, again), E_NOERROR);
  FreeRigidMotion fresh(t);
  RigidTarget first;
  ASSERT_EQ(fresh.at(3.21, first), E_NOERROR);
  EXPECT_EQ(toEigen(first.pose.M), toEigen(again.pose.M));
  // a finer grid agrees to the method's order
  FreeRigidMotion fine(t, 2.5e-4);
  RigidTarget f;
  ASSERT_EQ(fine.at(20.0, f), E_NOERROR);
  EXPECT_TRUE(near(toEigen(f.pose.M), toEigen(later.pose.M), 1e-11, 1e-12));
  EXPECT_EQ(motion.at(-1.0, f), E_BAD_ARGUMENT);
  EXPECT_EQ(motion.at(std::nan(""), f), E_NOT_FINITE);
}

TEST(FreeRigidMotion, LongTumblesKeepBoundedMemoryAndAnswerToTheBitInAnyOrder) {
  // The grid is not kept (issue 35, item 4: it was 32 bytes a step): at most 8 checkpoints here,
  // so that 440 s on the 1 ms grid (440,000 steps) thin them six times (the spacing doubles from
  // 1,024 steps to 65,536). Every answer, asked in any order, is the one a fresh motion with the
  // default 4,096 checkpoints gives, to the bit, and a second route steps the grid by hand.
  Vector6d twist;
  twist << 0.01, 0, 0, 0.4, -0.9, 0.6;
  const RigidTarget t = box(Vector3d::Zero(), twist);
  EXPECT_THROW(FreeRigidMotion(t, 1e-3, 1), ModelError);
  const std::vector<double> times = {439.9996, 0.25, 102.4009, 102.3995, 300.5, 204.801, 439.9991, 12.5};
  FreeRigidMotion shuffled(t, 1e-3, 8);
  std::vector<RigidTarget> got(times.size());
  for (std::size_t i = 0; i < times.size(); ++i) ASSERT_EQ(shuffled.at(times[i], got[i]), E_NOERROR);
  RigidTarget again;
  ASSERT_EQ(shuffled.at(times[0], again), E_NOERROR);  // from a checkpoint of the thinned set
  EXPECT_EQ(toEigen(again.pose.M), toEigen(got[0].pose.M));
  EXPECT_EQ(again.twist, got[0].twist);
  for (std::size_t i = 0; i < times.size(); ++i) {
    FreeRigidMotion fresh(t);
    RigidTarget a;
    ASSERT_EQ(fresh.at(times[i], a), E_NOERROR);
    EXPECT_EQ(toEigen(a.pose.M), toEigen(got[i].pose.M)) << times[i];
    EXPECT_EQ(a.twist, got[i].twist) << times[i];
  }
  // The second route at 102.4009 s: 102,400 grid steps by the same RK4 on the quaternion, then
  // the 0.9e-3 s step (the class's formula, written here again from its documentation).
  Eigen::Quaterniond q;
  t.pose.M.GetQuaternion(q.x(), q.y(), q.z(), q.w());
  const Matrix3d R0 = toEigen(t.pose.M);
  const Vector3d L = R0 * t.inertia * R0.transpose() * twist.tail<3>();
  const Matrix3d I_inv = t.inertia.inverse();
  const auto rate = [&](const Eigen::Vector4d& x) {
    const Matrix3d R = Eigen::Quaterniond(x(3), x(0), x(1), x(2)).toRotationMatrix();
    const Vector3d w = R * (I_inv * (R.transpose() * L));
    const Eigen::Quaterniond d = Eigen::Quaterniond(0.0, w.x(), w.y(), w.z()) * Eigen::Quaterniond(x(3), x(0), x(1), x(2));
    return Eigen::Vector4d(0.5 * d.x(), 0.5 * d.y(), 0.5 * d.z(), 0.5 * d.w());
  };
  const auto rk4 = [&](const Eigen::Vector4d& x, double h) {
    const Eigen::Vector4d k1 = rate(x), k2 = rate(x + 0.5 * h * k1), k3 = rate(x + 0.5 * h * k2), k4 = rate(x + h * k3);
    return Eigen::Vector4d((x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)).normalized());
  };
  Eigen::Vector4d x(q.x(), q.y(), q.z(), q.w());
  for (int k = 0; k < 102400; ++k) x = rk4(x, 1e-3);
  x = rk4(x, 102.4009 - 102400 * 1e-3);
  const std::size_t j = std::find(times.begin(), times.end(), 102.4009) - times.begin();
  // The same steps in another order of operations: round-off apart (~1e-16 a step, 1e5 steps).
  EXPECT_TRUE(near(toEigen(got[j].pose.M), Matrix3d(Eigen::Quaterniond(x(3), x(0), x(1), x(2)).toRotationMatrix()), 1e-11, 1e-11));
}

/// Runs an approach of the default arm to a grasp point `offset` from the hand (world), on a
/// target with `twist`, checking eq. 4 at every output sample by the O(n) route.
ApproachRecord approach(const Vector6d& base_twist, const Vector6d& target_twist, const Vector3d& offset,
                        ApproachSpec spec, double* worst_eq4 = nullptr, double* drift_seen = nullptr) {
  const ModelPtr model = arm();
  SimulationState s = startState(*model);
  s.velocity.base_twist = toTwist(base_twist);
  const Vector3d p_hand = handAt(*model, s.state);
  RigidTarget target = box(p_hand + offset + Vector3d(0.3, 0.0, 0.0), target_twist);
  // the grasp frame: 0.3 m from the CoM (the target frame's origin), oriented as the hand now is
  Kinematics kin(*model);
  EXPECT_EQ(forwardKinematics(*model, s.state, kin), E_NOERROR);
  const KDL::Rotation R_hand = kin.pose(hand(*model).body).M;
  spec.grasp = target.pose.Inverse() * KDL::Frame(R_hand, toKDL(p_hand + offset));
  ApproachController controller(model, hand(*model), spec, FreeRigidMotion(target));
  SimulationOptions options;
  options.rtol = 1e-10;
  Simulator sim(model, options);
  MomentumSolver momentum(model);
  FreeFloatingSolver dense(model);
  KDL::Jacobian J(model->nj());
  double worst = 0.0, drift = 0.0;
  ApproachRecord rec;
  const auto observer = [&](const SimulationState& x, const ApproachCommand& cmd) {
    Kinematics k(*model);
    ASSERT_EQ(forwardKinematics(*model, x.state, k), E_NOERROR);
    ASSERT_EQ(momentum.compute(k, x.velocity), E_NOERROR);
    Vector6d t_h;
    ASSERT_EQ(momentum.contactTwist(hand(*model), t_h), E_NOERROR);
    ASSERT_EQ(dense.compute(x.state), E_NOERROR);
    ASSERT_EQ(dense.J_star(hand(*model), J), E_NOERROR);
    const Vector6d gap = t_h - J.data * x.velocity.qdot.data;  // eq. 4: R_h M_a^-1 (P_g; L_g)
    worst = std::max(worst, (gap - cmd.drift).norm() / (1e-3 + t_h.norm()));
    drift = std::max(drift, gap.norm());
  };
  EXPECT_EQ(runApproach(sim, controller, s, 0.05, observer, rec), E_NOERROR);
  if (worst_eq4) *worst_eq4 = worst;
  if (drift_seen) *drift_seen = drift;
  if (rec.reached) {  // the hand is where the controller says (forward kinematics, the target's own motion)
    KDL::Frame G;
    Vector6d g;
    EXPECT_EQ(controller.grasp(s.t, G, g), E_NOERROR);
    EXPECT_LE((handAt(*model, s.state) - toEigen(G.p)).norm(), spec.position_tolerance);
  }
  return rec;
}

TEST(Approach, ZeroMomentumFixedTargetHandMovesAsJStarSays) {
  double worst = 1.0, drift = 1.0;
  const ApproachRecord rec =
      approach(Vector6d::Zero(), Vector6d::Zero(), Vector3d(0.05, -0.1, 0.08), ApproachSpec{}, &worst, &drift);
  EXPECT_TRUE(rec.reached);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(drift, 1e-9);  // no momentum: no drift term
  EXPECT_LE(rec.final_distance, ApproachSpec{}.position_tolerance);
  EXPECT_LE(rec.final_angle, ApproachSpec{}.orientation_tolerance);
  EXPECT_GT(rec.base_rotation, 1e-4);  // the base reacts: the floating dynamics, not a fixed base
}

TEST(Approach, WithMomentumTheRhTermClosesTheGap) {
  Vector6d base;
  base << 0.002, -0.001, 0.0, 0.0, 0.0, 0.004;  // a drifting, slowly turning satellite
  Vector6d target;
  target << 0.0, 0.0, 0.0, 0.02, -0.03, 0.01;  // tumbling
  double worst = 1.0, drift = 0.0;
  const ApproachRecord rec = approach(base, target, Vector3d(0.05, -0.1, 0.08), ApproachSpec{}, &worst, &drift);
  EXPECT_TRUE(rec.reached);
  EXPECT_GT(drift, 1e-3);   // the momentum moves the hand by itself
  EXPECT_LT(worst, 1e-9);   // and eq. 4's R_h term is exactly that motion
}

TEST(Approach, AnUnreachableGraspIsReportedWithTheClosestDistance) {
  ApproachSpec spec;
  spec.max_duration = 4.0;
  const ApproachRecord rec = approach(Vector6d::Zero(), Vector6d::Zero(), Vector3d(6.0, 0.0, 0.0), spec);
  EXPECT_FALSE(rec.reached);
  EXPECT_TRUE(std::isnan(rec.t_contact));
  EXPECT_GT(rec.closest_distance, 1.0);
  EXPECT_LT(rec.closest_distance, 6.0);  // it did reach out
  EXPECT_NEAR(rec.duration, 4.0, 1e-12);
}

TEST(Approach, ReactionNullSpaceTurnsTheBaseLess) {
  ApproachSpec spec;
  spec.orientation = false;  // a 3-row task: four rates of the seven are free for the base
  const ApproachRecord plain = approach(Vector6d::Zero(), Vector6d::Zero(), Vector3d(0.1, -0.15, 0.1), spec);
  spec.null_space = NullSpaceTask::Reaction;
  const ApproachRecord reaction = approach(Vector6d::Zero(), Vector6d::Zero(), Vector3d(0.1, -0.15, 0.1), spec);
  EXPECT_TRUE(plain.reached);
  EXPECT_TRUE(reaction.reached);
  EXPECT_LT(reaction.base_rotation, 0.8 * plain.base_rotation);  // measured: 0.015 rad against 0.022
}

TEST(Approach, AGroundedArmTracksWithTheFixedBaseJacobian) {
  // A ground test bed: the base held, so the hand's twist is J qdot (no J*, no drift), and the
  // approach still converges.
  const ModelPtr model = arm();
  SimulationState s = startState(*model);
  const Vector3d p_hand = handAt(*model, s.state);
  RigidTarget target = box(p_hand + Vector3d(0.35, -0.1, 0.08), Vector6d::Zero());
  Kinematics kin(*model);
  ASSERT_EQ(forwardKinematics(*model, s.state, kin), E_NOERROR);
  ApproachSpec spec;
  spec.grasp = target.pose.Inverse() * KDL::Frame(kin.pose(hand(*model).body).M, toKDL(p_hand + Vector3d(0.05, -0.1, 0.08)));
  ApproachController controller(model, hand(*model), spec, FreeRigidMotion(target));
  SimulationOptions options;
  options.grounded = true;
  Simulator sim(model, options);
  FreeFloatingSolver dense(model);
  KDL::Jacobian J(model->nj());
  double worst = 0.0;
  int checked = 0;
  const auto observer = [&](const SimulationState& x, const ApproachCommand& cmd) {
    ASSERT_EQ(dense.compute(x.state), E_NOERROR);
    ASSERT_EQ(dense.J(hand(*model), J), E_NOERROR);
    checked += cmd.damping == 0.0 && cmd.scale == 1.0;
    EXPECT_EQ(cmd.drift, Vector6d::Zero());
    // the commanded rates do the reference twist through J (damping 0 away from singularities)
    if (cmd.damping == 0.0 && cmd.scale == 1.0)
      worst = std::max(worst, (J.data * cmd.qdot.data - cmd.reference).norm() / (1e-3 + cmd.reference.norm()));
  };
  ApproachRecord rec;
  ASSERT_EQ(runApproach(sim, controller, s, 0.05, observer, rec), E_NOERROR);
  EXPECT_TRUE(rec.reached);
  EXPECT_EQ(rec.base_rotation, 0.0);
  EXPECT_GT(checked, 5);
  EXPECT_LT(worst, 1e-9);
}

TEST(Approach, RefusesBadSettings) {
  const ModelPtr model = arm();
  const FreeRigidMotion target(box(Vector3d(1, 0, 0), Vector6d::Zero()));
  ApproachSpec spec;
  spec.gain = 0.0;
  EXPECT_THROW(ApproachController(model, hand(*model), spec, target), ModelError);
  spec = ApproachSpec{};
  spec.position_tolerance = -1.0;
  EXPECT_THROW(ApproachController(model, hand(*model), spec, target), ModelError);
  spec = ApproachSpec{};
  spec.rate_limits = {1.0};
  EXPECT_THROW(ApproachController(model, hand(*model), spec, target), ModelError);
  EXPECT_THROW(ApproachController(model, Contact{99, KDL::Vector::Zero()}, ApproachSpec{}, target), ModelError);
}

}  // namespace
}  // namespace kdl_space::test
