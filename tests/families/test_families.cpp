// Every public entry of the library over every kind of robot (issue 34): the contracts written once
// (as manif's MANIF_TEST writes a group's), instantiated for each model family of
// tests/support/model_families.hpp. Each entry is checked against an independent route (KDL's
// six-virtual-joint tree, with the mimic coupling written out from the URDF's <mimic> elements;
// conservation laws; the capture's own constraint) or refused with a message that says why,
// never a crash. A robot without joints is an ordinary case: J* is 6 x 0, G* is the body's
// inverse inertia at the point.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/inspection.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "kdl_space/study/study.hpp"
#include "model_families.hpp"
#include "grasp_route.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

std::string slurpFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The family's URDF read as written, and without its <mimic> elements (each joint its own
/// coordinate): the second is the independent route's robot.
std::shared_ptr<const FloatingModel> load(const ModelFamily& f) {
  return std::make_shared<const FloatingModel>(loadUrdfFile(familyUrdf(f.name)));
}
std::shared_ptr<const FloatingModel> loadUncoupled(const ModelFamily& f) {
  const std::string text = std::regex_replace(slurpFile(familyUrdf(f.name)), std::regex("<mimic[^>]*/>"), "");
  return std::make_shared<const FloatingModel>(loadUrdfString(text, f.name + "_uncoupled.urdf"));
}

/// The coupling from the URDF: the uncoupled robot's joint values are T q + o of the coupled
/// robot's coordinates q, read from the model's mimic list and matched by name.
struct Coupling {
  Eigen::MatrixXd T;
  Eigen::VectorXd o;
};
Coupling coupling(const FloatingModel& coupled, const FloatingModel& free) {
  Coupling c{Eigen::MatrixXd::Zero(free.nj(), coupled.nj()), Eigen::VectorXd::Zero(free.nj())};
  for (unsigned int j = 0; j < coupled.nj(); ++j) c.T(free.jointIndex(coupled.jointNames()[j]), j) = 1.0;
  for (const Mimic& m : coupled.mimic()) {
    c.T(free.jointIndex(m.joint), coupled.jointIndex(m.leader)) = m.multiplier;
    c.o(free.jointIndex(m.joint)) = m.offset;
  }
  return c;
}

/// A random state inside the joints' limits (continuous joints over a turn).
State randomStateInLimits(const FloatingModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0), pos(-1.0, 1.0);
  State s(model);
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const JointProperties& p = model.jointProperties()[j];
    const double lo = std::isfinite(p.lower) ? p.lower : -M_PI, hi = std::isfinite(p.upper) ? p.upper : M_PI;
    s.q(j) = lo + (0.1 + 0.8 * u(rng)) * (hi - lo);
  }
  s.world_T_base = basePose(KDL::Vector(pos(rng), pos(rng), pos(rng)), pos(rng), pos(rng) / 2, pos(rng));
  return s;
}

/// The same state of the uncoupled robot.
State uncoupledState(const State& s, const FloatingModel& free, const Coupling& c) {
  State u(free);
  u.world_T_base = s.world_T_base;
  u.q.data = c.T * s.q.data + c.o;
  return u;
}

/// The independent route: KDL's six-virtual-joint tree of the uncoupled robot, coupled by hand
/// (C = diag(1_6, T)). G* over several points, (J_full C) (C^T M_full C)^-1 (J_full C)^T, and the
/// grounded G at each from the joint blocks (J and H), or none where H is not positive definite.
struct IndependentInertia {
  Eigen::MatrixXd G_all;
  std::vector<std::optional<Eigen::MatrixXd>> G_grounded;
};
IndependentInertia independentInertia(const FloatingModel& free, const State& u, const Coupling& c,
                                      const std::vector<LinkPoint>& points) {
  const VirtualJointTree vt(free, u);
  const int n = static_cast<int>(c.T.cols()), m = static_cast<int>(c.T.rows());
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(6 + m, 6 + n);
  C.topLeftCorner(6, 6).setIdentity();
  C.bottomRightCorner(m, n) = c.T;
  const Eigen::MatrixXd M = C.transpose() * vt.M_full() * C;
  const Eigen::Index k = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd J(6 * k, 6 + n);
  for (Eigen::Index i = 0; i < k; ++i) J.middleRows(6 * i, 6) = vt.J_full(points[i]) * C;
  IndependentInertia out{J * M.llt().solve(J.transpose()), {}};
  const Eigen::LLT<Eigen::MatrixXd> H(M.bottomRightCorner(n, n));
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::MatrixXd Jq = J.block(6 * i, 6, 6, n);
    if (n > 0 && H.info() != Eigen::Success) out.G_grounded.emplace_back();
    else out.G_grounded.emplace_back(n == 0 ? Eigen::MatrixXd(Eigen::MatrixXd::Zero(6, 6)) : Eigen::MatrixXd(Jq * H.solve(Jq.transpose())));
  }
  return out;
}

/// G* at one point by the independent route.
Eigen::MatrixXd independentG(const FloatingModel& free, const State& u, const Coupling& c, const LinkPoint& h) {
  return independentInertia(free, u, c, {h}).G_all;
}

/// A scenario of the family with a rigid box at the contact, the law given, written into a folder
/// of this test; returns its path.
std::string writeScenario(const ModelFamily& f, const std::string& law, const std::string& extra = "") {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / ("families_" + f.name);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / ("scenario_" + std::to_string(std::hash<std::string>()(law + extra)) + ".yaml")).string();
  std::ofstream out(path);
  out << "robot:\n  urdf: " << familyUrdf(f.name) << "\n  contact: {link: " << f.contact << ", offset: [" << f.offset[0]
      << ", " << f.offset[1] << ", " << f.offset[2] << "]}\n"
      << "  base: {position: [0, 0, 0], rpy: [0.1, -0.2, 0.3], twist: [0.01, 0, 0.02, 0.001, -0.002, 0.003]}\n"
      << "target:\n  mass: 40\n  inertia: [[2, 0, 0], [0, 3, 0], [0, 0, 4]]\n"
      << "  pose: {position: [2.5, 0.5, 0.3], rpy: [0.2, 0.1, -0.3]}\n"
      << "  twist: [-0.05, 0.01, 0.02, 0.03, -0.02, 0.04]\n"
      << "law: " << law << "\n"
      << "simulation: {duration: 0.5, output_step: 0.1, integrator: dopri5, rtol: 1.0e-10, atol: 1.0e-12}\n" << extra;
  return path;
}

const std::vector<std::string>& laws() {
  static const std::vector<std::string> l{
      "{type: capture}", "{type: translational}", "{type: point, normal: [1, 0, 0], restitution: 0.5}",
      "{type: friction, normal: [1, 0, 0], restitution: 0.2, friction: 0.3}"};
  return l;
}

class Families : public ::testing::TestWithParam<ModelFamily> {};

// The model: its coordinates, and every quantity of every link against the independent route.
TEST_P(Families, GStarAtEveryLinkEqualsTheVirtualJointRoute) {
  const ModelFamily& f = GetParam();
  const auto model = load(f);
  ASSERT_EQ(model->nj(), f.joints);
  const auto free = loadUncoupled(f);
  const Coupling c = coupling(*model, *free);
  std::mt19937 rng(34);
  FreeFloatingSolver solver(model);
  RecursiveExIITSolver recursive(model);
  for (int trial = 0; trial < 3; ++trial) {
    const State s = randomStateInLimits(*model, rng);
    const State u = uncoupledState(s, *free, c);
    ASSERT_EQ(solver.compute(s), 0);
    ASSERT_EQ(recursive.compute(s), 0);
    for (std::size_t b = 0; b < model->bodies().size(); ++b) {
      const std::string& link = model->bodies()[b].name;
      const KDL::Vector offset(0.05, -0.02, 0.1);
      const Contact h = model->contact(link, offset);
      Matrix6d G_dense, G_rec;
      KDL::Jacobian J_star(model->nj()), J(model->nj());
      ASSERT_EQ(solver.G_star(h, G_dense), 0) << link;
      ASSERT_EQ(recursive.G_star(h, G_rec), 0) << link;
      ASSERT_EQ(solver.J_star(h, J_star), 0) << link;
      ASSERT_EQ(solver.J(h, J), 0) << link;
      const Eigen::MatrixXd G_ref = independentG(*free, u, c, LinkPoint{link, offset});
      const double scale = G_ref.norm();
      EXPECT_TRUE(near(G_dense, G_ref, 0, 1e-10 * scale, f.name + " G* (dense) at " + link));
      EXPECT_TRUE(near(G_rec, G_ref, 0, 1e-10 * scale, f.name + " G* (recursive) at " + link));
      EXPECT_EQ(J_star.data.cols(), static_cast<Eigen::Index>(f.joints));
      // conditioning() on a 6 x n J*: n = 0 has no singular values and no manipulability.
      const Conditioning k = conditioning(J_star.data, J.data);
      EXPECT_EQ(k.sigma_J_star.size(), static_cast<Eigen::Index>(std::min(6u, f.joints)));
      if (f.joints == 0) {
        EXPECT_EQ(k.manipulability_J_star, 0.0);
        EXPECT_TRUE(std::isinf(k.condition_number));
      }
      Conditioning k2;
      std::vector<Diagnostic> warnings;
      EXPECT_EQ(checkConfiguration(model, s, h, k2, warnings), 0);
    }
  }
}


// inspect's two routes (the dense one, and the O(n) one it takes above kDenseJoints, forced here
// by dense_joints = 0) against the virtual-joint route: G* over all points with its cross
// blocks, G* and the grounded G at each; J* and G_locked the same on both.
TEST_P(Families, InspectionByBothRoutesEqualsTheVirtualJointRoute) {
  const ModelFamily& f = GetParam();
  const auto model = load(f);
  const auto free = loadUncoupled(f);
  const Coupling c = coupling(*model, *free);
  std::mt19937 rng(35);
  const KDL::Vector offset(0.05, -0.02, 0.1);
  std::vector<std::string> links{f.contact, model->bodies()[0].name};
  if (!f.other_contact.empty()) links.push_back(f.other_contact);
  std::vector<Contact> contacts;
  std::vector<LinkPoint> points;
  for (const std::string& link : links) {
    contacts.push_back(model->contact(link, offset));
    points.push_back(LinkPoint{link, offset});
  }
  for (int trial = 0; trial < 3; ++trial) {
    const State s = randomStateInLimits(*model, rng);
    const IndependentInertia ref = independentInertia(*free, uncoupledState(s, *free, c), c, points);
    Inspection dense, linear;
    ASSERT_EQ(inspect(model, s, contacts, dense), 0) << f.name;
    ASSERT_EQ(inspect(model, s, contacts, linear, {}, 0), 0) << f.name;
    EXPECT_TRUE(dense.dense);
    EXPECT_EQ(linear.dense, model->nj() == 0);  // no joint: nothing n x n to avoid
    EXPECT_EQ(linear.H_star.size(), 0);
    EXPECT_EQ(dense.H_star.rows(), static_cast<Eigen::Index>(model->nj()));
    const double scale = ref.G_all.norm();
    for (const Inspection* in : {&dense, &linear}) {
      const std::string route = f.name + (in == &dense ? " dense" : " O(n)");
      EXPECT_TRUE(near(in->G_star_all, ref.G_all, 0, 1e-10 * scale, route + ": G* over all points"));
      ASSERT_EQ(in->contacts.size(), contacts.size());
      for (std::size_t i = 0; i < contacts.size(); ++i) {
        const ContactInspection& ci = in->contacts[i];
        EXPECT_TRUE(near(ci.G_star, ref.G_all.block(6 * i, 6 * i, 6, 6), 0, 1e-10 * scale, route + " G* at " + links[i]));
        ASSERT_EQ(ci.G_grounded.has_value(), ref.G_grounded[i].has_value()) << route << " at " << links[i];
        if (ci.G_grounded)
          EXPECT_TRUE(near(*ci.G_grounded, *ref.G_grounded[i], 0, 1e-10 * scale, route + " G grounded at " + links[i]));
        EXPECT_TRUE(near(ci.J_star, dense.contacts[i].J_star, 0, 1e-12 * (1.0 + ci.J_star.norm()), route + " J*"));
        EXPECT_TRUE(near(ci.G_locked, dense.contacts[i].G_locked, 0, 1e-14 * scale, route + " G locked"));
      }
    }
  }
}

// No joints: G* is the single rigid body's inverse inertia at the point, by hand.
TEST(FamiliesRigid, GStarOfARobotWithoutJointsIsTheBodysInverseInertia) {
  for (const std::string name : {"rigid_body", "rigid_bus"}) {
    const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(familyUrdf(name)));
    ASSERT_EQ(model->nj(), 0u);
    FreeFloatingSolver solver(model);
    State s(*model);
    s.world_T_base = basePose(KDL::Vector(0.3, -0.1, 0.2), 0.4, -0.3, 0.2);
    ASSERT_EQ(solver.compute(s), 0);
    const Contact h = model->contact(model->bodies().back().name, KDL::Vector(0.1, 0.2, -0.1));
    Vector3d p;
    Matrix6d G;
    ASSERT_EQ(solver.contactPoint(h, p), 0);
    ASSERT_EQ(solver.G_star(h, G), 0);
    // An impulse (f; n) at p: dv_g = f / w, dw = I_g^-1 (n + r x f), dv_p = dv_g + dw x r, r = p - r_g.
    const Vector3d r = p - solver.r_g();
    Eigen::Matrix3d rx;
    rx << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
    const Eigen::Matrix3d Ii = solver.I_g().inverse();
    Matrix6d G_hand;
    G_hand << Eigen::Matrix3d::Identity() / solver.w() - rx * Ii * rx, -rx * Ii, Ii * rx, Ii;
    EXPECT_TRUE(near(G, G_hand, 1e-12, 1e-15, name + " G*"));
  }
}

// Each impact law: momentum conserved; a capture leaves the hand moving with the target's point.
TEST_P(Families, CaptureWithEachLawConservesMomentum) {
  const ModelFamily& f = GetParam();
  for (const std::string& law : laws()) {
    const Scenario sc = loadScenario(writeScenario(f, law));
    const CaptureResult r = solveCapture(sc.capture);
    const double scale = r.momentum_before.norm() + 1.0;
    EXPECT_TRUE(near(r.momentum_after, r.momentum_before, 0, 1e-12 * scale, f.name + " " + law + ": momentum"));
    EXPECT_LE(r.energy_after, r.energy_before * (1 + 1e-12)) << f.name << " " << law;
    if (law != "{type: capture}") continue;
    // The rigid grasp: the hand moves with the target's point after it (the box's CoM at its pose).
    const Vector3d w = r.target_twist_after.tail<3>();
    const Vector3d v_point = r.target_twist_after.head<3>() + w.cross(r.contact_point - Vector3d(2.5, 0.5, 0.3));
    Vector6d target_point;
    target_point << v_point, w;
    EXPECT_TRUE(near(r.robot.contact_twist_after, target_point, 0, 1e-12 * (target_point.norm() + 1),
                     f.name + " capture: the hand moves with the target's point"));
  }
}

// simulate: the operation (capture, then 0.5 s of motion) keeps the momentum of both sides.
TEST_P(Families, TheOperationRunsAndConservesMomentum) {
  const ModelFamily& f = GetParam();
  const Scenario sc = loadScenario(writeScenario(f, "{type: capture}"));
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.capture);
  ASSERT_FALSE(r.samples.empty());
  const Vector6d h0 = r.samples.front().h;
  for (const MotionSample& x : r.samples)
    EXPECT_TRUE(near(x.h, h0, 0, 1e-9 * (h0.norm() + 1), f.name + " momentum at t = " + std::to_string(x.t)));
  EXPECT_NEAR(r.samples.back().t, 0.5, 1e-12);
  // The grasp's load (issue 39): what the hand needs to move the box it holds, against minus the
  // rate of the box's momentum (tests/support/grasp_route.hpp), at every sample.
  const std::optional<HeldTarget> held = heldTarget(r);
  ASSERT_TRUE(held) << f.name;
  for (const MotionSample& x : r.samples) {
    const Vector6d route = graspWrenchByMomentumRate(r.model, *held, x);
    EXPECT_TRUE(near(x.grasp_wrench, route, 0.0, 1e-7 * (route.norm() + 1e-3), f.name + " grasp load at t = " + std::to_string(x.t)));
  }
}

// simulate with reaction wheels holding the bus (robot.base_actuators; four wheels in a skewed
// cluster, weak enough to reach their torque limit and capacity): the momentum of the links with
// the wheels is the capture's momentum after, at every sample (1e-9, as without wheels); the
// links' own share moves into the wheels (L - R A h changes); no wheel passes its capacity; the
// work counted balances the bus's kinetic energy.
TEST_P(Families, ReactionWheelsTakeMomentumAndKeepTheTotal) {
  const ModelFamily& f = GetParam();
  const std::string path = writeScenario(f, "{type: capture}", "wheels");
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string wheels = "  base_actuators: {wheels: {axes: [[1, 0, 0], [0, 0.6, 0.8], [0, -0.8, 0.6], [1, 1, 1]], "
                             "torque_limit: 0.05, capacity: 0.01}}\n";
  text.insert(text.find("  contact:"), wheels);
  text.replace(text.find("simulation: {"), 13, "simulation: {base_control: {attitude: {kp: 5, kd: 40, set_point: hold}}, ");
  text.replace(text.rfind("wheels"), 6, "");  // the tag writeScenario appended
  std::ofstream(path) << text;
  const Scenario sc = loadScenario(path);
  const OperationResult r = runCaptureOperation(sc);
  ASSERT_TRUE(r.capture);
  ASSERT_FALSE(r.samples.empty());
  const Vector6d h0 = r.capture->momentum_after;
  double moved = 0.0;
  Eigen::Matrix<double, 3, 4> A;
  A << 1, 0, 0, 1, 0, 0.6, -0.8, 1, 0, 0.8, 0.6, 1;
  A.colwise().normalize();
  for (const MotionSample& x : r.samples) {
    EXPECT_TRUE(near(x.h, h0, 0, 1e-9 * (h0.norm() + 1), f.name + " momentum at t = " + std::to_string(x.t)));
    ASSERT_EQ(x.wheel_momentum.size(), 4);
    EXPECT_LE(x.wheel_momentum.cwiseAbs().maxCoeff(), 0.01 * (1 + 1e-6));
    const Eigen::Quaterniond q(x.quat(3), x.quat(0), x.quat(1), x.quat(2));
    moved = std::max(moved, (q.toRotationMatrix() * A * x.wheel_momentum).norm());
  }
  EXPECT_GT(moved, 1e-6) << f.name << ": the wheels took no momentum";
  const MotionSample& last = r.samples.back();
  EXPECT_NEAR(last.T - r.samples.front().T, last.work.sum(), 1e-9 * (r.samples.front().T + 1)) << f.name;
  EXPECT_GT(r.record.stats.wheel_saturation_time, 0.0) << f.name;
}

/// The family's capture under `law`, `robot_extra` lines in its robot section, and 0.5 s of motion
/// with servos holding the capture (kp 50, kd 20) and `simulation_extra`: the momentum is the
/// capture's at every sample (1e-9) and the work counted balances the energy. A robot without
/// joints has no servo for a post-capture law: refused, naming simulation.joints (none returned).
std::optional<OperationResult> runUnderLaw(const ModelFamily& f, const std::string& law, const std::string& robot_extra,
                                           const std::string& simulation_extra) {
  const std::string path = writeScenario(f, law, simulation_extra);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.resize(text.size() - simulation_extra.size());  // the tag writeScenario appended
  text.insert(text.find("  contact:"), robot_extra);
  text = std::regex_replace(text, std::regex("simulation: \\{[^\n]*\\}\n"),
                            "simulation:\n  duration: 0.5\n  output_step: 0.1\n  rtol: 1.0e-10\n  atol: 1.0e-12\n"
                            "  joints: {\"*\": {pd: {kp: 50, kd: 20, set_point: hold}}}\n" + simulation_extra);
  std::ofstream(path) << text;
  if (f.joints == 0) {
    try {
      loadScenario(path);
      ADD_FAILURE() << f.name << ": a robot without joints was given a law for its servos";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("simulation.joints"), std::string::npos) << e.what();
    }
    return std::nullopt;
  }
  OperationResult r = runCaptureOperation(loadScenario(path));
  EXPECT_TRUE(r.capture && !r.samples.empty()) << f.name;
  if (!r.capture || r.samples.empty()) return std::nullopt;
  const Vector6d h0 = r.capture->momentum_after;
  for (const MotionSample& x : r.samples)
    EXPECT_TRUE(near(x.h, h0, 0, 1e-9 * (h0.norm() + 1), f.name + " momentum at t = " + std::to_string(x.t)));
  const MotionSample& last = r.samples.back();
  EXPECT_NEAR(last.T - r.samples.front().T, last.work.sum(), 1e-9 * (r.samples.front().T + 1)) << f.name;
  return r;
}

// simulate under momentum_distribution (simulation.after_capture) with three wheels: the momentum
// of links and wheels is the capture's (1e-9), the work counted balances the energy, and the
// robot's joints run at the law's rates (none at rest: the stack's spin is in them). A robot
// without joints has no servo for the law: refused, naming the field.
TEST_P(Families, MomentumDistributionKeepsTheMomentumOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const std::optional<OperationResult> r = runUnderLaw(
      f, "{type: capture}", "  base_actuators: {wheels: {torque_limit: 10, capacity: 10}}\n",
      "  base_control: {attitude: {kp: 5, kd: 40, set_point: hold}}\n  after_capture: {law: momentum_distribution}\n");
  if (!r) return;  // no joints: refused
  EXPECT_GT(r->samples.back().qd.cwiseAbs().maxCoeff(), 0.0) << f.name;
}

// simulate under impedance (simulation.after_capture, issue 39) with a grasp limit: the momentum is
// the capture's (1e-9), the work counted balances the energy, the joints dissipate, and the grasp's
// load is the held box's momentum rate (tests/support/grasp_route.hpp) under the law's torques. A
// robot without joints has no servo for the law: refused, naming the field.
TEST_P(Families, ImpedanceKeepsTheMomentumOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const std::optional<OperationResult> run =
      runUnderLaw(f, "{type: capture, max_grasp_wrench: {force: 2, moment: 1}}", "",
                  "  after_capture: {law: impedance, stiffness: [20, 5], damping: [50, 10]}\n");
  if (!run) return;  // no joints: refused
  const OperationResult& r = *run;
  EXPECT_LE(r.samples.back().work(0), 0.0) << f.name << ": the law's work";
  const std::optional<HeldTarget> held = heldTarget(r);
  ASSERT_TRUE(held) << f.name;
  for (const MotionSample& x : r.samples) {
    const Vector6d route = graspWrenchByMomentumRate(r.model, *held, x);
    EXPECT_TRUE(near(x.grasp_wrench, route, 0.0, 1e-7 * (route.norm() + 1e-3), f.name + " grasp load at t = " + std::to_string(x.t)));
  }
}

// ik: a pose the contact frame had at another configuration is reached, as measured by KDL's
// virtual-joint tree of the uncoupled robot (its mimic joints where their leaders put them); a
// robot without joints on the chain is refused, saying so.
TEST_P(Families, InverseKinematicsReachesAPoseOfTheChainOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const auto model = load(f);
  const auto free = loadUncoupled(f);
  const Coupling c = coupling(*model, *free);
  std::mt19937 rng(3434);
  for (const std::string& link : {f.contact, f.other_contact}) {
    if (link.empty()) continue;
    const Contact h = model->contact(link, KDL::Vector(0.01, 0.02, 0.03));
    const State seed = randomStateInLimits(*model, rng);
    if (f.joints == 0) {
      try {
        solveInverseKinematics(*model, seed, h, KDL::Frame(KDL::Vector(1, 2, 3)));
        ADD_FAILURE() << f.name << ": ik of a robot without joints returned";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no movable joint"), std::string::npos) << e.what();
      }
      continue;
    }
    State truth = randomStateInLimits(*model, rng);
    truth.world_T_base = seed.world_T_base;
    const KDL::Frame goal =
        VirtualJointTree(*free, uncoupledState(truth, *free, c)).pose(link) * KDL::Frame(KDL::Vector(0.01, 0.02, 0.03));
    const IkResult r = solveInverseKinematics(*model, seed, h, goal);
    State reached = seed;
    reached.q = r.q;
    const KDL::Frame got =
        VirtualJointTree(*free, uncoupledState(reached, *free, c)).pose(link) * KDL::Frame(KDL::Vector(0.01, 0.02, 0.03));
    EXPECT_LE((got.p - goal.p).Norm(), 1e-9) << f.name << " at " << link;
    const KDL::Rotation dR = got.M.Inverse() * goal.M;
    EXPECT_LE(dR.GetRot().Norm(), 1e-9) << f.name << " at " << link;
    for (unsigned int j = 0; j < model->nj(); ++j) {
      EXPECT_GE(r.q(j), model->jointProperties()[j].lower) << model->jointNames()[j];
      EXPECT_LE(r.q(j), model->jointProperties()[j].upper) << model->jointNames()[j];
    }
  }
}

// plan: an optimum inside the limits, or a refusal that names what is missing.
TEST_P(Families, PlanFindsAnOptimumOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const Scenario sc = loadScenario(writeScenario(f, "{type: capture}"));
  PlanOptions o;
  o.scan = 5;
  try {
    const CapturePlan p = planCapture(sc, o);
    EXPECT_GT(f.joints, 0u) << f.name << ": a robot without joints has nothing to plan";
    EXPECT_TRUE(std::isfinite(p.optimum.objective));
    EXPECT_LE(p.optimum.objective, p.nominal.objective + 1e-12);
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_FALSE(what.empty());
    if (f.joints == 0) EXPECT_NE(what.find("no movable joint"), std::string::npos) << what;
  }
}

// plan over the operation: the motion after each capture measured (the servos holding), an
// optimum no worse than the nominal, or a refusal that names what is missing.
// plan with the detumble objective (issue 39 item 4): the optimum's objective is its measured
// time to detumble (or, not detumbled within the horizon, the horizon times its final rate over
// the threshold), no worse than the nominal's; a robot without joints is refused as before.
TEST_P(Families, PlanForTheTimeToDetumbleOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const Scenario sc = loadScenario(writeScenario(f, "{type: capture}"));
  PlanOptions o;
  o.weights = {{"time_to_detumble", 1.0}};
  o.horizon = 0.5;
  o.scan = 3;
  o.polish_starts = 1;
  o.polish_evaluations = 10;
  if (f.joints == 0) {
    EXPECT_THROW(planCapture(sc, o), InputError) << f.name;
    return;
  }
  const CapturePlan p = planCapture(sc, o);
  ASSERT_TRUE(p.optimum.motion) << f.name;
  const MotionMeasures& m = *p.optimum.motion;
  const double expected = std::isnan(m.time_to_detumble) ? 0.5 * m.final_base_rate / sc.simulation.detumble_rate
                                                         : m.time_to_detumble;
  EXPECT_NEAR(p.optimum.objective, expected, 1e-12 * std::max(1.0, expected)) << f.name;
  EXPECT_LE(p.optimum.objective, p.nominal.objective + 1e-12) << f.name;
  EXPECT_TRUE(std::isnan(m.wheel_momentum_fraction)) << f.name << ": no wheels";
}

TEST_P(Families, PlanOverTheOperationMeasuresTheMotionOrSaysWhyNot) {
  const ModelFamily& f = GetParam();
  const Scenario sc = loadScenario(writeScenario(f, "{type: capture}"));
  PlanOptions o;
  o.weights = {{"peak_base_rate", 1.0}, {"attitude_excursion", 0.1}, {"settling_time", 1e-3}};
  o.horizon = 0.5;
  o.scan = 3;
  o.polish_starts = 1;
  o.polish_evaluations = 10;
  try {
    const CapturePlan p = planCapture(sc, o);
    EXPECT_GT(f.joints, 0u) << f.name << ": a robot without joints has nothing to plan";
    ASSERT_TRUE(p.optimum.motion && p.nominal.motion) << f.name;
    const MotionMeasures& m = *p.optimum.motion;
    EXPECT_NEAR(p.optimum.objective, m.peak_base_rate + 0.1 * m.attitude_excursion + 1e-3 * m.settling_time,
                1e-12 * std::max(1e-300, p.optimum.objective)) << f.name;
    EXPECT_LE(p.optimum.objective, p.nominal.objective + 1e-12) << f.name;
    EXPECT_GE(m.peak_base_rate, m.final_base_rate) << f.name;
    EXPECT_TRUE(std::isfinite(m.momentum_rate)) << f.name;
    EXPECT_EQ(m.peak_torque.size(), f.joints) << f.name;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_FALSE(what.empty());
    EXPECT_EQ(f.joints, 0u) << f.name << " refused: " << what;  // every family with joints computes
    if (f.joints == 0) EXPECT_NE(what.find("no movable joint"), std::string::npos) << what;
  }
}

// approach from where the robot is, with a pre-grasp move: it reaches, or it stops and says why
// (the target is 2.5 m away: out of most families' reach), and no joint leaves its limits.
TEST_P(Families, AnApproachWithAPreGraspReachesOrSaysWhyInsideTheLimits) {
  const ModelFamily& f = GetParam();
  Scenario sc;
  try {
    sc = loadScenario(writeScenario(f, "{type: capture}",
                                    "approach: {grasp: {position: [-0.4, 0, 0]}, pre_grasp: {standoff: 0.1}, "
                                    "max_duration: 3}\n"));
  } catch (const InputError& e) {  // a robot without joints has no approach to run
    EXPECT_EQ(f.joints, 0u) << f.name << ": " << e.what();
    return;
  }
  OperationOptions o;
  o.motion = false;
  std::shared_ptr<const OperationResult> r;
  try {
    r = std::make_shared<const OperationResult>(runCaptureOperation(sc, o));
  } catch (const OperationError& e) {
    ASSERT_TRUE(e.partial() && e.partial()->approach) << f.name << ": " << e.what();
    r = e.partial();
    EXPECT_FALSE(r->approach->record.cause.empty()) << f.name << ": " << e.what();
  } catch (const InputError& e) {
    EXPECT_FALSE(std::string(e.what()).empty());
    return;
  }
  const FloatingModel& model = *sc.capture.robot.model;
  for (const MotionSample& x : r->approach_samples)
    for (unsigned int j = 0; j < model.nj(); ++j) {
      EXPECT_LE(x.q(j), model.jointProperties()[j].upper + 1e-9) << f.name << " " << model.jointNames()[j];
      EXPECT_GE(x.q(j), model.jointProperties()[j].lower - 1e-9) << f.name << " " << model.jointNames()[j];
    }
}

// a compliant grasp left compliant (law.lock: never, issue 39): the contact then the joined motion
// with the grasp's springs on, no lock impulse, the momentum of robot and target kept throughout.
TEST_P(Families, ACompliantGraspLeftCompliantMovesOnWithItsMomentum) {
  const ModelFamily& f = GetParam();
  const Scenario sc = loadScenario(writeScenario(
      f, "{type: compliant, lock: never, stiffness: [1e5, 1e5, 1e5, 1e3, 1e3, 1e3], max_duration: 0.05}"));
  const OperationResult r = runCaptureOperation(sc, OperationOptions{});
  ASSERT_TRUE(r.compliant && r.joined) << f.name;
  EXPECT_EQ(r.compliant->lock_impulse, Vector6d::Zero()) << f.name;
  EXPECT_EQ(r.compliant->lock_share.energy, 0.0) << f.name;
  ASSERT_FALSE(r.samples.empty()) << f.name;
  const Vector6d h0 = r.compliant->momentum_before;
  for (const std::vector<MotionSample>* rows : {&r.contact_samples, &r.samples})
    for (const MotionSample& x : *rows)
      EXPECT_LE((x.h - h0).norm(), 1e-12 * std::max(1.0, h0.norm())) << f.name << " t = " << x.t;
}

/// Six samples of a study of the family's capture scenario with these `inputs` (YAML lines): each computes.
void expectEverySampleComputes(const ModelFamily& f, const std::string& name, const std::string& inputs) {
  const std::string scenario = writeScenario(f, "{type: capture}");
  const std::string study_path = scenario + "." + name + ".yaml";
  std::ofstream(study_path) << "scenario: " << scenario << "\nsamples: 6\nseed: 34\ninputs:\n" << inputs;
  const auto study = std::make_shared<const Study>(loadStudy(study_path));
  StudyEvaluator eval(study);
  std::vector<double> row(eval.columns());
  for (std::uint64_t i = 0; i < 6; ++i) {
    eval.evaluate(i, row.data());
    EXPECT_EQ(row[1], 0.0) << f.name << " " << name << " sample " << i << ": " << eval.failure();
  }
}

// study: every sample of a small study computes.
TEST_P(Families, AStudyComputesEverySample) {
  expectEverySampleComputes(GetParam(), "study",
                            "  target.mass: {uniform: [20, 60]}\n  target.twist.wx: {normal: {mean: 0.03, std: 0.01}}\n");
}

// study: the target's shape and tumble as engineers state their uncertainty (principal moments by
// their own factors, the axes tilted, the tumble's axis in a cone) compute on every robot (each row
// against its target built by hand: tests/study/test_study_target_shape.cpp).
TEST_P(Families, AStudyOfTheTargetsShapeComputesEverySample) {
  expectEverySampleComputes(GetParam(), "shape",
                            "  target.inertia.I1: {uniform: [0.9, 1.1]}\n  target.inertia.I3: {uniform: [0.9, 1.1]}\n"
                            "  target.inertia.tilt: {deg: {uniform: [0, 10]}}\n"
                            "  target.tumble: {uniform: [0.01, 0.05]}\n  target.tumble_cone: {deg: {uniform: [0, 10]}}\n");
}

// check: the loader's and the checker's verdicts agree, and every family loads.
TEST_P(Families, CheckFindsNoError) {
  const ModelFamily& f = GetParam();
  const UrdfReport report = checkUrdfFile(familyUrdf(f.name));
  EXPECT_TRUE(report.errors.empty()) << f.name << ": " << (report.errors.empty() ? "" : report.errors.front().message);
}

std::string familyName(const ::testing::TestParamInfo<ModelFamily>& info) { return info.param.name; }
INSTANTIATE_TEST_SUITE_P(EveryKindOfRobot, Families, ::testing::ValuesIn(modelFamilies()), familyName);

}  // namespace
}  // namespace kdl_space::test
