// The located stop (Simulator::setStopEvent) and the approach's contact instant, against motions
// whose crossing is known in closed form:
//   1. a joint turning at a constant rate (grounded base, no torque): g = cos q - cos q_c crosses
//      at (q_c - q0) / w, far from any output sample; with a hard stop in the same step, the
//      earlier of the two wins;
//   2. approaches whose hand and target move in closed form (the arm braked, its base drifting or
//      falling as one rigid body; the target translating or spinning about a principal axis): the
//      contact instant is the first root of |d0 + dv t| = tol, |dv + g t| = speed tol, or
//      |theta0 - w t| = angle tol, and the capture's states are those of that instant. The output
//      step (0.05 s) is far coarser than the 1e-9 s asked: a contact found at the samples (the
//      code before the stop event) is late by up to one output step and fails these tests.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/simulation/approach.hpp"
#include "rigid_targets.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

// ---- 1. The simulator's stop event ----------------------------------------------------------------

/// spacedyn_twolink on a grounded base, joint2 braked, joint1 free at a constant rate: q1(t) =
/// q0 + w t exactly (one joint about a fixed axis, no torque: no acceleration).
struct TurningJoint {
  ModelPtr model;
  double q0 = 0.1, w = 0.4;
  explicit TurningJoint(double upper = 3.0) {
    const FloatingModel base = loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf");
    JointProperties p;
    p.lower = -3.0;
    p.upper = upper;
    model = std::make_shared<const FloatingModel>(base.withJointProperties({{"joint1", p}}));
  }
  SimulationOptions options(Integrator integrator) const {
    SimulationOptions o;
    o.integrator = integrator;
    o.grounded = true;
    o.joint_friction = false;
    o.step = 0.05;  // RK4's step; the adaptive methods' first
    return o;
  }
  void setUp(Simulator& sim) const { sim.setJointControl(1, JointControl{JointControl::Mode::Locked}); }
  SimulationState initial() const {
    SimulationState s;
    s.state = State(*model);
    s.velocity = FloatingVelocity(*model);
    s.state.q(0) = q0;
    s.velocity.qdot(0) = w;
    return s;
  }
};

TEST(StopEvent, LocatedBetweenTheOutputsWhereTheClosedFormCrosses) {
  const TurningJoint c;
  const double q_c = 0.5473;  // crossed at t* = 1.11825 s, between the outputs (0.25 s apart)
  const double t_star = (q_c - c.q0) / c.w;
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54, Integrator::Rosenbrock}) {
    SCOPED_TRACE(static_cast<int>(integrator));
    Simulator sim(c.model, c.options(integrator));
    c.setUp(sim);
    // Not linear in time: the secant alone does not land on the root.
    sim.setStopEvent([&](const SimulationState& x) { return std::cos(x.state.q(0)) - std::cos(q_c); });
    SimulationState s = c.initial();
    std::vector<double> seen;
    ASSERT_EQ(sim.run(s, 5.0, 0.25, [&](const SimulationState& x) { seen.push_back(x.t); }), E_NOERROR);
    EXPECT_NEAR(sim.stats().event_time, t_star, 1e-9);
    EXPECT_EQ(s.t, sim.stats().event_time);
    EXPECT_GE(s.state.q(0), q_c - 1e-15) << "g <= 0 holds at the instant";
    EXPECT_NEAR(s.state.q(0), q_c, 1e-9 * c.w);
    EXPECT_NEAR(s.velocity.qdot(0), c.w, 1e-12);
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.back(), s.t) << "the observer's last output is the instant";
    EXPECT_EQ(seen.size(), 6u) << "0, 0.25, ..., 1.0 and the instant";
  }
}

TEST(StopEvent, MetAtTheStartEndsTheRunThere) {
  const TurningJoint c;
  Simulator sim(c.model, c.options(Integrator::DormandPrince54));
  c.setUp(sim);
  sim.setStopEvent([](const SimulationState&) { return 0.0; });
  SimulationState s = c.initial();
  int outputs = 0;
  ASSERT_EQ(sim.run(s, 5.0, 0.25, [&](const SimulationState&) { ++outputs; }), E_NOERROR);
  EXPECT_EQ(s.t, 0.0);
  EXPECT_EQ(sim.stats().event_time, 0.0);
  EXPECT_EQ(sim.stats().accepted_steps, 0);
  EXPECT_EQ(outputs, 1);
  // Never met: the run goes to its end and says so.
  sim.setStopEvent([](const SimulationState&) { return 1.0; });
  s = c.initial();
  ASSERT_EQ(sim.run(s, 2.0, 0.25, nullptr), E_NOERROR);
  EXPECT_EQ(s.t, 2.0);
  EXPECT_TRUE(std::isnan(sim.stats().event_time));
}

// RK4 with steps of 0.05 s: the steps end at 1.0 and 1.05 s; the crossing at 1.01 s and the hard
// stop at 1.04 s fall in the same step. The stop is located first (afterStep); the event, earlier,
// ends the run before the impact: the joint still moves and no impact is counted. A constant
// torque accelerates the joint (q = q0 + w t + a t^2 / 2, which RK4 integrates exactly), so the
// step retaken with the joint held at the stop would put the crossing elsewhere.
TEST(StopEvent, EarlierThanAHardStopInTheSameStepWins) {
  const double torque = 2.0;
  const TurningJoint probe;
  Simulator inertia(probe.model, probe.options(Integrator::RK4));
  probe.setUp(inertia);
  double m = 0.0;
  ASSERT_EQ(inertia.apparentInertia(probe.initial(), 0, m), E_NOERROR);
  const double a = torque / m;
  const auto q = [&](double t) { return probe.q0 + probe.w * t + 0.5 * a * t * t; };
  const TurningJoint c(q(1.04));
  const double q_c = q(1.01);
  const auto pushed = [&](Simulator& sim) {
    c.setUp(sim);
    sim.setLimitMode(0, LimitMode::Stop);
    sim.setTorqueCallback([&](const SimulationState&, KDL::JntArray& tau) { tau(0) = torque; });
  };
  Simulator sim(c.model, c.options(Integrator::RK4));
  pushed(sim);
  sim.setStopEvent([&](const SimulationState& x) { return q_c - x.state.q(0); });
  SimulationState s = c.initial();
  ASSERT_EQ(sim.run(s, 5.0, 0.25, nullptr), E_NOERROR);
  EXPECT_NEAR(s.t, 1.01, 1e-9);
  EXPECT_NEAR(s.state.q(0), q_c, 1e-9);
  EXPECT_NEAR(s.velocity.qdot(0), c.w + a * 1.01, 1e-9) << "not stopped: the impact comes later";
  EXPECT_EQ(sim.stats().joints[0].stops, 0);
  EXPECT_EQ(s.work.limits, 0.0);
  // The stop alone: it is met at 1.04 s (the same run without the event).
  Simulator plain(c.model, c.options(Integrator::RK4));
  pushed(plain);
  SimulationState p = c.initial();
  ASSERT_EQ(plain.run(p, 1.05, 0.25, nullptr), E_NOERROR);
  EXPECT_EQ(plain.stats().joints[0].stops, 1);
  EXPECT_EQ(p.velocity.qdot(0), 0.0);
  EXPECT_NEAR(p.state.q(0), q(1.04), 1e-10);
}

// g <= 0 made by the stop's impulse itself (the joint's rate falls to 0 at the stop): the run ends
// at the stop's instant, after the impact.
TEST(StopEvent, MadeByAHardStopEndsTheRunAtTheStop) {
  const double upper = 0.1 + 0.4 * 1.04;
  const TurningJoint c(upper);
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54}) {
    SCOPED_TRACE(static_cast<int>(integrator));
    Simulator sim(c.model, c.options(integrator));
    c.setUp(sim);
    sim.setLimitMode(0, LimitMode::Stop);
    sim.setStopEvent([&](const SimulationState& x) { return x.velocity.qdot(0) - 0.5 * c.w; });
    SimulationState s = c.initial();
    ASSERT_EQ(sim.run(s, 5.0, 0.25, nullptr), E_NOERROR);
    EXPECT_NEAR(s.t, 1.04, 1e-9);
    EXPECT_EQ(sim.stats().event_time, s.t);
    EXPECT_EQ(s.velocity.qdot(0), 0.0);
    EXPECT_NEAR(s.state.q(0), upper, 1e-10);
    EXPECT_EQ(sim.stats().joints[0].stops, 1);
  }
}

// ---- 2. The approach's contact instant ------------------------------------------------------------

ModelPtr arm() { return std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf")); }

Contact hand(const FloatingModel& model) { return model.contact("end_effector", KDL::Vector(0, 0, 0.05)); }

/// The arm braked (every joint Locked) on a free base: one rigid body. With a base twist of pure
/// translation v0 and gravity g (at the CoM: no moment), every point moves as p0 + v0 t + g t^2 / 2.
struct BrakedArm {
  ModelPtr model = arm();
  SimulationState s;
  Vector3d p_hand;   ///< at t = 0
  KDL::Rotation R_hand;
  BrakedArm(const Vector3d& v0) {
    s.state = State(*model);
    s.velocity = FloatingVelocity(*model);
    const char* names[] = {"joint2", "joint3", "joint4", "joint6"};
    const double q[] = {0.7, 0.9, 0.8, -0.6};
    for (int k = 0; k < 4; ++k) s.state.q(model->jointIndex(names[k])) = q[k];
    s.velocity.base_twist = KDL::Twist(toKDL(v0), KDL::Vector::Zero());
    Kinematics kin(*model);
    EXPECT_EQ(forwardKinematics(*model, s.state, kin), E_NOERROR);
    p_hand = kin.point(hand(*model));
    R_hand = kin.pose(hand(*model).body).M;
  }
  std::unique_ptr<Simulator> simulator(const Vector3d& gravity) const {
    SimulationOptions o;
    o.gravity = gravity;
    auto sim = std::make_unique<Simulator>(model, o);
    for (unsigned int j = 0; j < model->nj(); ++j) sim->setJointControl(j, JointControl{JointControl::Mode::Locked});
    return sim;
  }
};

/// The first t >= 0 with |a + b t + c t^2 / 2| = r, for |a| > r (bisection to round-off on the
/// closed form, after a scan fine enough not to step over the first root).
double firstRoot(const Vector3d& a, const Vector3d& b, const Vector3d& c, double r, double t_max) {
  const auto f = [&](double t) { return (a + b * t + 0.5 * c * t * t).norm() - r; };
  double lo = 0.0;
  const double dt = 1e-4;
  while (lo < t_max && f(lo + dt) > 0.0) lo += dt;
  double hi = lo + dt;
  EXPECT_LE(f(hi), 0.0) << "no root before " << t_max;
  for (int it = 0; it < 200 && hi - lo > 1e-16; ++it) (f(0.5 * (lo + hi)) > 0.0 ? lo : hi) = 0.5 * (lo + hi);
  return hi;
}

struct ApproachRun {
  ApproachRecord rec;
  SimulationState s;
  std::vector<double> samples;
  RigidTarget target_at_contact;
  double last_distance = 0.0, last_angle = 0.0, last_speed = 0.0;  ///< the observer's, at the last sample
};

ApproachRun approach(const BrakedArm& a, Simulator& sim, const RigidTarget& target, const ApproachSpec& spec) {
  ApproachController controller(a.model, hand(*a.model), spec, FreeRigidMotion(target));
  ApproachRun out;
  out.s = a.s;
  const auto observer = [&](const SimulationState& x, const ApproachCommand& cmd) {
    out.samples.push_back(x.t);
    out.last_distance = cmd.error.head<3>().norm();
    out.last_angle = cmd.error.tail<3>().norm();
    out.last_speed = cmd.relative_speed;
  };
  EXPECT_EQ(runApproach(sim, controller, out.s, 0.05, observer, out.rec), E_NOERROR);
  EXPECT_EQ(controller.target(out.s.t, out.target_at_contact), E_NOERROR);
  return out;
}

TEST(ContactInstant, DistanceCrossingOfADriftingHandAndAMovingTarget) {
  const Vector3d v0(0.02, -0.05, 0.03), d0(0.12, -0.07, 0.05);  // d0: grasp point - hand at t = 0
  // Closing in on the grasp point, passing 2 mm from it (so the crossing is no tangency).
  const Vector3d vT = v0 - d0 / 1.3 + Vector3d(0.0, 0.001, 0.0014);
  const BrakedArm a(v0);
  const RigidTarget target = box(a.p_hand + d0 + Vector3d(0.3, 0.0, 0.0), (Vector6d() << vT, Vector3d::Zero()).finished());
  ApproachSpec spec;
  spec.grasp = target.pose.Inverse() * KDL::Frame(a.R_hand, toKDL(a.p_hand + d0));  // oriented as the hand
  const double t_star = firstRoot(d0, vT - v0, Vector3d::Zero(), spec.position_tolerance, 10.0);
  ASSERT_GT(std::abs(std::remainder(t_star, 0.05)), 1e-3) << "the crossing must fall between the samples";
  const auto sim = a.simulator(Vector3d::Zero());
  const ApproachRun r = approach(a, *sim, target, spec);
  ASSERT_TRUE(r.rec.reached);
  EXPECT_NEAR(r.rec.t_contact, t_star, 1e-9);
  EXPECT_EQ(r.s.t, r.rec.t_contact);
  EXPECT_EQ(r.samples.back(), r.rec.t_contact) << "the last sample (the capture) is the contact instant";
  // The states at contact are those of the located instant: the hand where the closed form puts
  // it, the target too, and their distance the tolerance.
  Kinematics kin(*a.model);
  ASSERT_EQ(forwardKinematics(*a.model, r.s.state, kin), E_NOERROR);
  const Vector3d p_hand = kin.point(hand(*a.model));
  EXPECT_TRUE(near(p_hand, a.p_hand + v0 * t_star, 0.0, 1e-10, "hand at contact"));
  EXPECT_TRUE(near(toEigen(r.target_at_contact.pose.p), toEigen(target.pose.p) + vT * t_star, 0.0, 1e-10,
                   "target at contact"));
  const Vector3d p_grasp = toEigen(r.target_at_contact.pose * spec.grasp.p);
  EXPECT_NEAR((p_grasp - p_hand).norm(), spec.position_tolerance, 1e-10);
  EXPECT_NEAR(r.rec.final_distance, spec.position_tolerance, 1e-10);
  EXPECT_LE(r.last_distance, spec.position_tolerance);
}

TEST(ContactInstant, SpeedCrossingOfAFallingHand) {
  // A ground test: the braked arm falls (g), the target drifts; the relative speed |dv + g t| falls
  // through the speed tolerance while the hand is already within the position tolerance.
  const Vector3d v0(0.25, 0.1, -0.05), vT(-0.05, 0.02, 0.0), g(-0.6, -0.15, 0.12);
  const BrakedArm a(v0);
  const Vector3d d0(0.01, 0.0, -0.02);
  const RigidTarget target = box(a.p_hand + d0 + Vector3d(0.3, 0.0, 0.0), (Vector6d() << vT, Vector3d::Zero()).finished());
  ApproachSpec spec;
  spec.grasp = target.pose.Inverse() * KDL::Frame(a.R_hand, toKDL(a.p_hand + d0));
  spec.position_tolerance = 1.0;
  spec.speed_tolerance = 0.1;
  const double t_star = firstRoot(v0 - vT, g, Vector3d::Zero(), spec.speed_tolerance, 10.0);
  ASSERT_GT(std::abs(std::remainder(t_star, 0.05)), 1e-3);
  const auto sim = a.simulator(g);
  const ApproachRun r = approach(a, *sim, target, spec);
  ASSERT_TRUE(r.rec.reached);
  EXPECT_NEAR(r.rec.t_contact, t_star, 1e-9);
  EXPECT_EQ(r.samples.back(), r.rec.t_contact);
  EXPECT_NEAR(r.last_speed, spec.speed_tolerance, 1e-10) << "the relative speed at contact is the tolerance";
  EXPECT_TRUE(near(toEigen(r.s.velocity.base_twist).head<3>(), v0 + g * t_star, 0.0, 1e-10, "base velocity at contact"));
}

TEST(ContactInstant, AngleCrossingOfASpinningTarget) {
  // The hand at rest at the target's CoM; the target spins about a principal axis at w, its grasp
  // frame theta0 behind the hand's orientation about that axis: the angle is |theta0 - w t|.
  const BrakedArm a(Vector3d::Zero());
  RigidTarget target = box(a.p_hand, Vector6d::Zero());
  const Matrix3d R0 = toEigen(target.pose.M);
  const Vector3d axis = R0 * Vector3d::UnitY();  // a principal axis of the box
  const double w = 0.35, theta0 = 0.6;
  target.twist << Vector3d::Zero(), w * axis;
  ApproachSpec spec;
  const KDL::Rotation behind = KDL::Rotation::Rot2(toKDL(axis), -theta0);
  spec.grasp = target.pose.Inverse() * KDL::Frame(behind * a.R_hand, toKDL(a.p_hand));
  const double t_star = (theta0 - spec.orientation_tolerance) / w;
  ASSERT_GT(std::abs(std::remainder(t_star, 0.05)), 1e-3);
  const auto sim = a.simulator(Vector3d::Zero());
  const ApproachRun r = approach(a, *sim, target, spec);
  ASSERT_TRUE(r.rec.reached);
  // The target's spin is integrated to ~1e-12 rad (FreeRigidMotion): ~3e-12 s here.
  EXPECT_NEAR(r.rec.t_contact, t_star, 1e-9);
  EXPECT_NEAR(r.rec.final_angle, spec.orientation_tolerance, 1e-10);
  EXPECT_EQ(r.samples.back(), r.rec.t_contact);
}

}  // namespace
}  // namespace kdl_space::test
