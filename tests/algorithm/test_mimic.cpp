// Mimic joints (issue 12, item 5): a joint that follows another is not a coordinate; J*, H*, G*
// and the velocity jump use the coupled coordinates (J T, T^T H T). Checked against the same
// robot read without its <mimic> elements, with the coupling written out by hand.
// Issue 28: the O(n) recursions (RecursiveExIITSolver, ForwardDynamicsSolver) carry the couplings
// as constraints (src/algorithm/mimic_coupling.hpp): checked against the dense route.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "generated_chain.hpp"
#include "multibody/mimic_route.hpp"

namespace kdl_space {
namespace {

std::string link(const std::string& name, double mass, double x) {
  const std::string m = std::to_string(mass), c = std::to_string(x);
  return R"(<link name=")" + name + R"("><inertial><origin xyz=")" + c + R"( 0.01 0" rpy="0.1 0.2 0.3"/><mass value=")" + m +
         R"("/><inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0.001" ixz="0" iyz="0.002"/></inertial></link>)";
}

std::string joint(const std::string& name, const std::string& parent, const std::string& child, const std::string& xyz,
                  const std::string& axis, const std::string& mimic = "") {
  return R"(<joint name=")" + name + R"(" type="revolute"><parent link=")" + parent + R"("/><child link=")" + child +
         R"("/><origin xyz=")" + xyz + R"(" rpy="0 0.3 0"/><axis xyz=")" + axis +
         R"("/><limit lower="-2" upper="2" effort="10" velocity="1"/>)" + mimic + "</joint>";
}

/// A two-joint arm with a two-finger gripper; the right finger mimics the left (-1, +0.1), and
/// the wrist camera's tilt mimics the elbow (0.5): two mimic joints on two branches.
std::string gripper(bool with_mimic) {
  const std::string right = with_mimic ? R"(<mimic joint="left_finger" multiplier="-1" offset="0.1"/>)" : "";
  const std::string tilt = with_mimic ? R"(<mimic joint="elbow" multiplier="0.5"/>)" : "";
  return R"(<?xml version="1.0"?><robot name="g">)" + link("base", 50.0, 0.0) +
         joint("shoulder", "base", "upper", "0 0 0.5", "0 0 1") + link("upper", 3.0, 0.2) +
         joint("elbow", "upper", "fore", "0.4 0 0", "0 1 0") + link("fore", 2.0, 0.2) +
         joint("left_finger", "fore", "left", "0.4 0.05 0", "0 0 1") + link("left", 0.2, 0.05) +
         joint("right_finger", "fore", "right", "0.4 -0.05 0", "0 0 1", right) + link("right", 0.2, 0.05) +
         joint("camera_tilt", "upper", "camera", "0.1 0 0.1", "1 0 0", tilt) + link("camera", 0.5, 0.02) + "</robot>";
}

/// The coupling written out by hand from gripper()'s <mimic> elements: the free robot's joint
/// values are T q + o of the coupled coordinates (shoulder, elbow, left_finger).
struct Coupling {
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(5, 3);
  Eigen::VectorXd o = Eigen::VectorXd::Zero(5);
};

Coupling handCoupling(const FloatingModel& free) {
  Coupling c;
  const auto at = [&](const std::string& name) { return free.jointIndex(name); };
  c.T(at("shoulder"), 0) = 1.0;
  c.T(at("elbow"), 1) = 1.0;
  c.T(at("left_finger"), 2) = 1.0;
  c.T(at("right_finger"), 2) = -1.0;
  c.o(at("right_finger")) = 0.1;
  c.T(at("camera_tilt"), 1) = 0.5;
  return c;
}

/// A random state of the coupled robot and the same state of the free one.
void randomStates(std::mt19937& rng, const Coupling& c, State& coupled, State& free) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  coupled.world_T_base = free.world_T_base =
      KDL::Frame(KDL::Rotation::RPY(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
  for (int j = 0; j < 3; ++j) coupled.q(j) = u(rng);
  free.q.data = c.T * coupled.q.data + c.o;
}

TEST(Mimic, CoupledCoordinatesEqualTheHandCoupledModel) {
  const auto coupled = std::make_shared<const FloatingModel>(loadUrdfString(gripper(true), "mimic.urdf"));
  const auto free = std::make_shared<const FloatingModel>(loadUrdfString(gripper(false), "free.urdf"));
  ASSERT_EQ(coupled->jointNames(), (std::vector<std::string>{"shoulder", "elbow", "left_finger"}));
  ASSERT_EQ(free->nj(), 5u);
  const Coupling c = handCoupling(*free);
  const Eigen::MatrixXd& T = c.T;
  FreeFloatingSolver a(coupled), b(free);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    State sa(*coupled), sb(*free);
    randomStates(rng, c, sa, sb);
    ASSERT_EQ(a.compute(sa), 0);
    ASSERT_EQ(b.compute(sb), 0);
    const Eigen::MatrixXd H_star = T.transpose() * b.H_star().data * T;
    EXPECT_TRUE(a.H_star().data.isApprox(H_star, 1e-12)) << a.H_star().data << "\n\n" << H_star;
    EXPECT_TRUE(a.H().data.isApprox(T.transpose() * b.H().data * T, 1e-12));
    for (const std::string& tip : {"right", "camera", "fore"}) {
      const Contact ha = coupled->contact(tip, KDL::Vector(0.03, 0.0, 0.01));
      const Contact hb = free->contact(tip, KDL::Vector(0.03, 0.0, 0.01));
      KDL::Jacobian Ja(3), Jb(5);
      ASSERT_EQ(a.J_star(ha, Ja), 0);
      ASSERT_EQ(b.J_star(hb, Jb), 0);
      const Eigen::MatrixXd J_star = Jb.data * T;
      EXPECT_TRUE(Ja.data.isApprox(J_star, 1e-12)) << tip;
      // G* = J* H*^-1 J*^T + R_h M_a^-1 R_h^T (eq. 11) in the coupled coordinates.
      Matrix6d G_locked, Ga;
      ASSERT_EQ(b.G_locked(hb, G_locked), 0);
      const Eigen::MatrixXd G = J_star * H_star.ldlt().solve(J_star.transpose()) + G_locked;
      ASSERT_EQ(a.G_star(ha, Ga), 0);
      EXPECT_TRUE(Ga.isApprox(G, 1e-10)) << tip << "\n" << Ga << "\n\n" << G;
      // A capture side on the coupled model takes the dense route by itself, and its velocity
      // jump is H*^-1 J*^T F in the coupled coordinates (eq. 18).
      FloatingVelocity v{KDL::Twist::Zero(), KDL::JntArray(3)};
      FloatingSide side(coupled, sa, ha, v);
      EXPECT_TRUE(side.G().isApprox(G, 1e-10)) << tip;
      const Vector6d F = (Vector6d() << 1.0, -2.0, 0.5, 0.1, 0.2, -0.3).finished();
      ASSERT_EQ(side.applyImpulse(F), 0);
      const Eigen::VectorXd dq = H_star.ldlt().solve(J_star.transpose() * F);
      EXPECT_TRUE(side.after().qdot.data.isApprox(dq, 1e-10)) << tip;
    }
  }
}

/// A hand on an arm (issue 28): several mimic joints, one of which follows a mimic joint (the
/// distal phalanx follows the middle one, which follows the proximal one: the model composes the
/// chain down to a coordinate), on `fingers` fingers; the thumb's distal joint follows the wrist
/// (a leader on another branch, and one that is no finger's).
std::string hand(int fingers) {
  std::string xml = R"(<?xml version="1.0"?><robot name="h">)" + link("base", 80.0, 0.0) +
                    joint("shoulder", "base", "upper", "0 0 0.5", "0 0 1") + link("upper", 3.0, 0.2) +
                    joint("elbow", "upper", "fore", "0.4 0 0", "0 1 0") + link("fore", 2.0, 0.2) +
                    joint("wrist", "fore", "palm", "0.4 0 0", "1 0 0") + link("palm", 0.6, 0.05);
  for (int f = 0; f < fingers; ++f) {
    const std::string n = "f" + std::to_string(f), y = std::to_string(0.03 * f - 0.04);
    const std::string follow_middle = R"(<mimic joint=")" + n + R"(_proximal" multiplier="0.8" offset="0.05"/>)";
    const std::string follow_distal = f == 0 ? R"(<mimic joint="wrist" multiplier="-0.3"/>)"
                                             : R"(<mimic joint=")" + n + R"(_middle" multiplier="1.2" offset="-0.02"/>)";
    xml += joint(n + "_proximal", "palm", n + "_1", "0.08 " + y + " 0", "0 1 0") + link(n + "_1", 0.05, 0.02) +
           joint(n + "_middle", n + "_1", n + "_2", "0.04 0 0", "0 1 0", follow_middle) + link(n + "_2", 0.04, 0.015) +
           joint(n + "_distal", n + "_2", n + "_3", "0.03 0 0", "0 1 0", follow_distal) + link(n + "_3", 0.03, 0.01);
  }
  return xml + "</robot>";
}

/// The models of the O(n)-route tests: the gripper (two mimic joints on two branches) and a
/// three-finger hand (six, two of them mimics of mimics).
std::vector<std::shared_ptr<const FloatingModel>> coupledModels() {
  return {std::make_shared<const FloatingModel>(loadUrdfString(gripper(true), "mimic.urdf")),
          std::make_shared<const FloatingModel>(loadUrdfString(hand(3), "hand.urdf"))};
}

/// A random state of a model (base pose and joint values in [-1, 1]).
State randomState(std::mt19937& rng, const FloatingModel& model) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s(model);
  s.world_T_base = KDL::Frame(KDL::Rotation::RPY(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
  for (unsigned int j = 0; j < model.nj(); ++j) s.q(j) = u(rng);
  return s;
}

TEST(Mimic, TheHandComposesItsChainsOfMimicJoints) {
  const auto model = coupledModels()[1];
  EXPECT_EQ(model->nj(), 6u);  // shoulder, elbow, wrist and three proximal joints
  EXPECT_EQ(model->mimic().size(), 6u);
  // f1_distal = 1.2 (0.8 q + 0.05) - 0.02 of f1_proximal: the chain composed (model_build).
  for (const Body& b : model->bodies()) {
    if (b.name != "f1_3") continue;
    EXPECT_EQ(b.joint, model->jointIndex("f1_proximal"));
    EXPECT_NEAR(b.multiplier, 0.96, 1e-15);
    EXPECT_NEAR(b.offset, 0.04, 1e-15);
  }
}

TEST(Mimic, TheRecursiveExIITEqualsTheDenseRoute) {
  // G* (free-floating) and G (grounded) at contacts on every branch, and the velocity jumps, by
  // the O(n) recursion with the couplings as constraints against the dense T^T H T route; also
  // with a braked leader (its followers brake with it) and a braked non-leader.
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const auto& model : coupledModels()) {
    const unsigned int n = model->nj();
    for (int lock = 0; lock < 3; ++lock) {
      std::vector<bool> locked(n, false);
      if (lock == 1) locked[1] = true;      // the elbow: leads the gripper's camera tilt
      if (lock == 2) locked[n - 1] = true;  // the last coordinate: a finger leading the mimics
      RecursiveExIITSolver fast(model);
      FreeFloatingSolver dense(model);
      fast.setLocked(locked);
      dense.setLocked(locked);
      for (int trial = 0; trial < 4; ++trial) {
        const State s = randomState(rng, *model);
        ASSERT_EQ(fast.compute(s), 0);
        ASSERT_EQ(dense.compute(s), 0);
        for (std::size_t body = 1; body < model->bodies().size(); ++body) {
          const Contact h{static_cast<int>(body), KDL::Vector(u(rng) * 0.05, u(rng) * 0.05, u(rng) * 0.05)};
          for (Response response : {Response::FreeFloating, Response::Grounded}) {
            Matrix6d Gf, Gd;
            ASSERT_EQ(fast.G(h, response, Gf), 0);
            ASSERT_EQ(dense.G(h, response, Gd), 0);
            EXPECT_LT((Gf - Gd).norm(), 1e-10 * Gd.norm())
                << model->bodies()[body].name << " lock " << lock << "\n" << Gf << "\n\n" << Gd;
            const Vector6d F = (Vector6d() << u(rng), u(rng), u(rng), u(rng), u(rng), u(rng)).finished();
            Vector6d d_base, dPL_g;
            KDL::JntArray dq_fast(n), dq_dense(n);
            ASSERT_EQ(fast.velocityJump(h, response, F, d_base, dq_fast), 0);
            ASSERT_EQ(dense.velocityJump(h, response, F, dPL_g, dq_dense), 0);
            EXPECT_LT((dq_fast.data - dq_dense.data).norm(), 1e-10 * (1.0 + dq_dense.data.norm()))
                << model->bodies()[body].name << " " << dq_fast.data.transpose() << " vs " << dq_dense.data.transpose();
            for (unsigned int j = 0; j < n; ++j)
              if (locked[j]) EXPECT_EQ(dq_fast(j), 0.0);
            if (response == Response::Grounded) {
              EXPECT_EQ(d_base, Vector6d::Zero());
            } else {  // the dense route's momentum jump, as a base twist (both start from rest)
              KDL::Twist base;
              ASSERT_EQ(dense.baseTwist(dPL_g, dq_dense, base), 0);
              EXPECT_LT((d_base - toEigen(base)).norm(), 1e-10 * (1.0 + d_base.norm())) << d_base.transpose();
            }
          }
        }
      }
    }
  }
}

TEST(Mimic, TheArticulatedBodyForwardDynamicsEqualsTheDenseRoute) {
  // ForwardDynamicsSolver (the couplings as constraints) against DenseForwardDynamicsSolver
  // (checked against the hand-coupled robot below): velocities, torques, wrenches on every body,
  // gravity, a free-floating and a grounded base, a braked leader.
  std::mt19937 rng(280);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const auto& model : coupledModels()) {
    const unsigned int n = model->nj();
    const std::size_t nb = model->bodies().size();
    for (int variant = 0; variant < 3; ++variant) {
      const bool grounded = variant == 1;
      std::vector<bool> locked(n, false);
      if (variant == 2) locked[n - 1] = true;
      ForwardDynamicsSolver fast(model);
      DenseForwardDynamicsSolver dense(model);
      fast.setGravity(Vector3d(0.1, 0.0, -9.81));
      dense.setGravity(Vector3d(0.1, 0.0, -9.81));
      fast.setGrounded(grounded);
      dense.setGrounded(grounded);
      fast.setLocked(locked);
      dense.setLocked(locked);
      for (int trial = 0; trial < 5; ++trial) {
        const State s = randomState(rng, *model);
        FloatingVelocity v{grounded ? KDL::Twist::Zero()
                                    : KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng))),
                           KDL::JntArray(n)};
        KDL::JntArray tau(n);
        for (unsigned int j = 0; j < n; ++j) {
          v.qdot(j) = locked[j] ? 0.0 : 2.0 * u(rng);
          tau(j) = u(rng);
        }
        std::vector<KDL::Wrench> f_ext(nb);
        for (KDL::Wrench& w : f_ext) w = KDL::Wrench(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
        FloatingAcceleration af{Vector6d::Zero(), KDL::JntArray(n)}, ad{Vector6d::Zero(), KDL::JntArray(n)};
        ASSERT_EQ(fast.CartToJnt(s, v, tau, f_ext, af), 0);
        ASSERT_EQ(dense.CartToJnt(s, v, tau, f_ext, ad), 0);
        EXPECT_LT((af.qddot.data - ad.qddot.data).norm(), 1e-10 * (1.0 + ad.qddot.data.norm()))
            << "variant " << variant << ": " << af.qddot.data.transpose() << " vs " << ad.qddot.data.transpose();
        EXPECT_LT((af.base - ad.base).norm(), 1e-10 * (1.0 + ad.base.norm()))
            << af.base.transpose() << " vs " << ad.base.transpose();
        for (unsigned int j = 0; j < n; ++j)
          if (locked[j]) EXPECT_EQ(af.qddot(j), 0.0);
      }
    }
  }
}

TEST(Mimic, TheModelSaysHowTheRecursionsCoupleJoints) {
  const auto coupled = std::make_shared<const FloatingModel>(loadUrdfString(gripper(true), "mimic.urdf"));
  int notes = 0;
  for (const Diagnostic& d : coupled->diagnostics()) notes += d.kind == "mimic_joint" || d.kind == "dense_route";  // 2 coordinates, 2 mimic joints: dense
  EXPECT_EQ(notes, 3);
}

TEST(Mimic, DenseForwardDynamicsIsTheHandCoupledDynamics) {
  // M_c a_c + c_c = (0; tau_c) with M_c = T^T M T, c_c = T^T c (M, c: the robot without <mimic>,
  // at the coupled state: q = T q_c + o, qdot = T qdot_c), T = diag(E_6, T_joints).
  const auto coupled = std::make_shared<const FloatingModel>(loadUrdfString(gripper(true), "mimic.urdf"));
  const auto free = std::make_shared<const FloatingModel>(loadUrdfString(gripper(false), "free.urdf"));
  const Coupling c = handCoupling(*free);
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(11, 9);  // the base's six coordinates, then the joints'
  T.topLeftCorner<6, 6>().setIdentity();
  T.bottomRightCorner(5, 3) = c.T;
  DenseForwardDynamicsSolver a(coupled), b(free);
  a.setGravity(Vector3d(0.0, 0.0, -9.81));
  b.setGravity(Vector3d(0.0, 0.0, -9.81));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    State sa(*coupled), sb(*free);
    randomStates(rng, c, sa, sb);
    FloatingVelocity va{KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng))),
                        KDL::JntArray(3)};
    for (int j = 0; j < 3; ++j) va.qdot(j) = u(rng);
    FloatingVelocity vb{va.base_twist, KDL::JntArray(5)};
    vb.qdot.data = T.bottomRightCorner(5, 3) * va.qdot.data;
    KDL::JntArray tau(3), tau_free(5);
    for (int j = 0; j < 3; ++j) tau(j) = u(rng);
    FloatingAcceleration acc_a{Vector6d::Zero(), KDL::JntArray(3)}, acc_b{Vector6d::Zero(), KDL::JntArray(5)};
    ASSERT_EQ(a.CartToJnt(sa, va, tau, {}, acc_a), 0);
    ASSERT_EQ(b.CartToJnt(sb, vb, tau_free, {}, acc_b), 0);  // for M and c of the free robot
    FreeFloatingSolver& k = b.kinematics();
    Eigen::MatrixXd M(11, 11);
    M << k.M_a(), k.A_m(), k.A_m().transpose(), k.H().data;
    const Eigen::MatrixXd M_c = T.transpose() * M * T;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(9);
    rhs.tail(3) = tau.data;
    const Eigen::VectorXd a_c = M_c.ldlt().solve(rhs - T.transpose() * b.bias());
    EXPECT_TRUE(acc_a.qddot.data.isApprox(a_c.tail(3), 1e-10)) << acc_a.qddot.data.transpose() << " vs "
                                                               << a_c.tail(3).transpose();
    // The base's acceleration at its origin from a_g at the CoM (the same kinematic identity).
    const Vector3d P = k.r_g(), p_b = toEigen(sa.world_T_base.p);
    const Vector3d w = toEigen(va.base_twist.rot), v_b = toEigen(va.base_twist.vel);
    Vector6d base;
    base << a_c.head<3>() + Vector3d(a_c.segment<3>(3)).cross(p_b - P) + w.cross(v_b), a_c.segment<3>(3);
    EXPECT_TRUE(acc_a.base.isApprox(base, 1e-10)) << acc_a.base.transpose() << " vs " << base.transpose();
  }
}

TEST(Mimic, TheMotionOfACoupledRobotKeepsItsEnergyAndMomentum) {
  // In orbit, no torques: the coupled motion conserves energy and momentum (the simulation runs
  // the articulated-body recursion with the couplings as constraints; a constraint force that did
  // work, or a coupling that drifted, would show).
  for (const auto& coupled : coupledModels()) {
    Simulator simulator(coupled);
    SimulationState s{0.0, State(*coupled), FloatingVelocity{KDL::Twist(KDL::Vector(0.01, 0.0, -0.02),
                                                                        KDL::Vector(0.02, -0.01, 0.03)),
                                                             KDL::JntArray(coupled->nj())}};
    for (unsigned int j = 0; j < coupled->nj(); ++j) s.velocity.qdot(j) = 0.8 * std::sin(1.7 * j + 0.4);
    double T0 = 0.0, T1 = 0.0;
    Vector6d h0, h1;
    ASSERT_EQ(simulator.energyAndMomentum(s, T0, h0), 0);
    ASSERT_EQ(simulator.run(s, 2.0, 0.5, [](const SimulationState&) {}), 0);
    ASSERT_EQ(simulator.energyAndMomentum(s, T1, h1), 0);
    EXPECT_NEAR(T1, T0, 1e-8 * T0);
    EXPECT_LT((h1 - h0).norm(), 1e-8 * h0.norm());
    EXPECT_GT((s.state.q.data).norm(), 0.1);  // it moved
  }
}

TEST(Mimic, JointsThatFollowEachOtherAreRefused) {
  // left_finger follows right_finger, which follows left_finger: no coordinate moves them.
  std::string xml = gripper(true);
  const std::string left = R"(<joint name="left_finger" type="revolute">)";
  xml.insert(xml.find("</joint>", xml.find(left)), R"(<mimic joint="right_finger"/>)");
  try {
    loadUrdfString(xml, "cycle.urdf");
    ADD_FAILURE() << "a cycle of mimic joints loaded";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("its <mimic> joints form a cycle"), std::string::npos) << e.what();
  }
  // check says so too, for each joint of the cycle (one set of rules).
  const UrdfReport report = checkUrdfString(xml, "cycle.urdf");
  ASSERT_EQ(report.errors.size(), 2u);
  for (const Finding& f : report.errors) EXPECT_EQ(f.kind, "bad_mimic");
  try {
    loadUrdfString(xml, "cycle.urdf");
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), "cycle.urdf: " + describe(report.errors[0]));
  }
}

TEST(Mimic, ALeaderThatIsNoMovableJointIsRefusedByLoaderAndCheck) {
  std::string xml = gripper(true);
  xml.replace(xml.find(R"(mimic joint="elbow")"), 19, R"(mimic joint="elbo")");
  try {
    loadUrdfString(xml, "bad.urdf");
    ADD_FAILURE() << "a mimic of an unknown joint loaded";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("joint 'camera_tilt': mimics 'elbo', which is no movable joint"),
              std::string::npos) << e.what();
    const UrdfReport report = checkUrdfString(xml, "bad.urdf");
    ASSERT_EQ(report.errors.size(), 1u);
    EXPECT_EQ(report.errors[0].kind, "bad_mimic");
    EXPECT_EQ(std::string(e.what()), "bad.urdf: " + describe(report.errors[0]));
  }
}

// The capture's route for mimic models (issue 28): the recursion where few joints are mimic
// (4 k <= n, measured faster: docs/benchmarks.md), the dense route where many are.
TEST(Mimic, TheCaptureTakesTheRecursionForFewMimicJointsAndTheDenseRouteForMany) {
  EXPECT_TRUE(detail::mimicGStarTakesRecursion(16, 4));   // grippers N=20: 1.3x faster measured
  EXPECT_FALSE(detail::mimicGStarTakesRecursion(15, 4));  // just beyond the rule
  EXPECT_FALSE(detail::mimicGStarTakesRecursion(6, 4));   // grippers N=10: 0.88x
  EXPECT_FALSE(detail::mimicGStarTakesRecursion(68, 32)); // hands N=100: 0.7x
  EXPECT_TRUE(detail::mimicGStarTakesRecursion(7, 0));    // no mimic joint
  // The model's note says which route its capture takes, on both sides of the rule.
  const auto note = [](const std::string& urdf) {
    const FloatingModel model = loadUrdfString(urdf, "generated.urdf");
    for (const Diagnostic& d : model.diagnostics())
      if (d.kind == "mimic_constraints" || d.kind == "dense_route") return d.kind + ": " + d.message;
    return std::string();
  };
  EXPECT_EQ(note(bench::generatedGrippersUrdf(30)).rfind("mimic_constraints: ", 0), 0u);
  EXPECT_NE(note(bench::generatedGrippersUrdf(30)).find("take it too"), std::string::npos)
      << note(bench::generatedGrippersUrdf(30));
  EXPECT_EQ(note(bench::generatedGrippersUrdf(10)).rfind("dense_route: ", 0), 0u);  // the kind it always had
  EXPECT_NE(note(bench::generatedGrippersUrdf(10)).find("take the dense route"), std::string::npos);
  EXPECT_NE(note(bench::generatedHandsUrdf(50)).find("take the dense route"), std::string::npos);
}

TEST(Mimic, ACaptureOnTheRecursiveRouteEqualsTheDenseRoute) {
  const auto model = std::make_shared<const FloatingModel>(loadUrdfString(bench::generatedGrippersUrdf(30), "g.urdf"));
  const unsigned int n = model->nj();
  ASSERT_EQ(model->mimic().size(), 4u);
  ASSERT_TRUE(detail::mimicGStarTakesRecursion(n, 4));
  State state(*model);
  state.world_T_base = KDL::Frame(KDL::Rotation::RPY(0.1, -0.2, 0.3), KDL::Vector(0.3, -0.2, 0.1));
  FloatingVelocity v{KDL::Twist(KDL::Vector(0.01, -0.005, 0.002), KDL::Vector(0.003, 0.02, -0.01)), KDL::JntArray(n)};
  for (unsigned int j = 0; j < n; ++j) {
    state.q(j) = std::sin(1.3 * j + 0.2);
    v.qdot(j) = 0.1 - 0.02 * (j % 7);
  }
  const Contact h = model->contact("tip");
  Vector6d F;
  F << 3.0, -2.0, 1.5, 0.4, -0.3, 0.2;
  for (Response r : {Response::FreeFloating, Response::Grounded}) {
    SCOPED_TRACE(r == Response::FreeFloating ? "free" : "grounded");
    FloatingSide fast(model, state, h, v, r, ExIITMethod::Recursive), dense(model, state, h, v, r, ExIITMethod::Dense);
    EXPECT_LE((fast.G() - dense.G()).norm(), 1e-10 * dense.G().norm());
    ASSERT_EQ(fast.applyImpulse(F), 0);
    ASSERT_EQ(dense.applyImpulse(F), 0);
    EXPECT_LE((fast.after().qdot.data - dense.after().qdot.data).norm(), 1e-10 * (1.0 + dense.after().qdot.data.norm()));
    EXPECT_LE((toEigen(fast.after().base_twist) - toEigen(dense.after().base_twist)).norm(),
              1e-10 * (1.0 + toEigen(dense.after().base_twist).norm()));
    EXPECT_LE((fast.contactTwistAfter() - dense.contactTwistAfter()).norm(), 1e-10 * (1.0 + dense.contactTwistAfter().norm()));
  }
}

}  // namespace
}  // namespace kdl_space
