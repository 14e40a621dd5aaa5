// Free-floating forward dynamics (ForwardDynamicsSolver::CartToJnt, the articulated-body
// algorithm; test_articulated_body.cpp compares it with the composite-rigid-body route) against
// the INDEPENDENT virtual-joint route (virtual_joint_route.hpp): the floating system as a
// grounded KDL tree with six virtual joints TransX, TransY, TransZ, RotX, RotY, RotZ in front of
// the base, evaluated by KDL's solvers only:
//   M_full  from VirtualJointTree (TreeIdSolver_RNE, unit accelerations),
//   c       from KDL::TreeIdSolver_RNE with the virtual joint rates, zero accelerations, the
//           gravity vector and the external wrenches (KDL's WrenchMap),
//   theta_dd = M_full^-1 (tau_full - c), tau_full = (0 on the virtual joints; tau).
//
// The map between the virtual coordinates and the base (derived here, and checked against KDL's
// forward kinematics by VirtualJointMap.*): the virtual tree gives
//   world_T_base = Trans(p0 + (x, y, z)) Rx(a) Ry(b) Rz(c) R0,
// so the base ORIGIN is p0 + (x, y, z) for any angles (the rotation axes pass through it):
//   v_base_origin = (x_d, y_d, z_d),   a_base_origin = (x_dd, y_dd, z_dd).
// The world angular velocity is w = a_d e_x + b_d Rx(a) e_y + c_d Rx(a) Ry(b) e_z; at zero angles
// w = (a_d, b_d, c_d) and, differentiating (d/dt Rx(a) u = a_d e_x x Rx(a) u, and so on),
//   w_dot = (a_dd, b_dd, c_dd) + a_d b_d (e_x x e_y) + c_d (a_d e_x x e_z + b_d e_y x e_z)
//         = (a_dd + b_d c_d, b_dd - a_d c_d, c_dd + a_d b_d).
//
// KDL's external wrenches (treeidsolver_recursive_newton_euler.cpp: f = I a + v x* I v - f_ext,
// all in segment coordinates) are per segment, in the segment's (tip) frame, moment about its
// origin; kdl_space's are world axes, moment about the body frame's origin: the same wrench
// rotated by world_R_body^T.
//
// Tolerance: 1e-9 relative per element, with an absolute floor of 1e-12 times the norm of the
// compared vector (elements that are zero in exact arithmetic come out of either route as
// round-off of order eps * cond(M) * ||.||). A wrong term (velocity product, gravity, lever arm,
// frame of a wrench) gives errors of order 1.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <memory>
#include <random>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

constexpr double kRel = 1e-9;
constexpr double kFloor = 1e-12;
constexpr int kStates = 20;

::testing::AssertionResult close(const Eigen::VectorXd& a, const Eigen::VectorXd& ref, const std::string& what) {
  return near(a, ref, kRel, kFloor * ref.norm(), what);
}

struct ModelCase {
  std::string name;
  std::string path;
};

std::vector<ModelCase> modelCases() {
  return {{"space_arm7", urdfDir() + "/space_arm7.urdf"},
          {"dual_arm", urdfDir() + "/dual_arm.urdf"},
          {"spacedyn_twolink", urdfDir() + "/spacedyn_twolink.urdf"},
          {"arm6_public", dataDir() + "/reference/models/arm6_public.urdf"}};
}

inline void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.name; }
std::string caseName(const ::testing::TestParamInfo<ModelCase>& info) { return info.param.name; }

ModelPtr load(const std::string& path) { return std::make_shared<const FloatingModel>(loadUrdfFile(path)); }

Vector3d randomVec(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return Vector3d(u(rng), u(rng), u(rng));
}

Eigen::VectorXd randomVector(int n, std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

FloatingVelocity randomVelocity(const FloatingModel& model, std::mt19937& rng) {
  FloatingVelocity v;
  v.base_twist = toTwist((Vector6d() << randomVec(rng, 0.5), randomVec(rng, 0.5)).finished());
  v.qdot = KDL::JntArray(model.nj());
  v.qdot.data = randomVector(static_cast<int>(model.nj()), rng, 1.5);
  return v;
}

/// The virtual coordinate rates of a floating velocity at zero virtual angles: (v_base_origin; w; qdot).
Eigen::VectorXd virtualRates(const FloatingVelocity& v) {
  Eigen::VectorXd theta_d(6 + v.qdot.rows());
  theta_d << toEigen(v.base_twist), v.qdot.data;
  return theta_d;
}

/// The base acceleration (a of the base origin; angular acceleration) from the virtual rates and
/// accelerations at zero virtual angles (header comment).
Vector6d baseAcceleration(const Eigen::VectorXd& theta_d, const Eigen::VectorXd& theta_dd) {
  const double ad = theta_d(3), bd = theta_d(4), cd = theta_d(5);
  const Vector3d ex = Vector3d::UnitX(), ey = Vector3d::UnitY(), ez = Vector3d::UnitZ();
  Vector6d a;
  a.head<3>() = theta_dd.head<3>();
  a.tail<3>() = theta_dd.segment<3>(3) + ad * bd * ex.cross(ey) + cd * (ad * ex.cross(ez) + bd * ey.cross(ez));
  return a;
}

/// Random world-frame wrenches (moment about the body frame's origin) on every other body, the
/// base included; empty bodies get zero.
std::vector<KDL::Wrench> randomWrenches(const FloatingModel& model, std::mt19937& rng) {
  std::vector<KDL::Wrench> f(model.bodies().size(), KDL::Wrench::Zero());
  for (std::size_t i = 0; i < f.size(); i += 2)
    f[i] = KDL::Wrench(toKDL(randomVec(rng, 20.0)), toKDL(randomVec(rng, 10.0)));
  return f;
}

/// The same wrenches in KDL's convention: per segment name, in the segment's frame.
KDL::WrenchMap toKdlWrenches(const FloatingModel& model, const VirtualJointTree& route,
                             const std::vector<KDL::Wrench>& f) {
  KDL::WrenchMap map;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const std::string& link = model.bodies()[i].name;
    map[link] = route.pose(link).M.Inverse(f[i]);
  }
  return map;
}

/// What the dynamics test is given besides the state and velocity.
struct Loads {
  bool gravity = false;
  bool wrenches = false;
  bool armature = false;
};

// ---- The virtual-joint map itself ---------------------------------------------------------------

/// World angular velocity of Rx(a) Ry(b) Rz(c) R0 (header comment), for any angles.
Vector3d angularVelocity(const Eigen::Vector3d& abc, const Eigen::Vector3d& abc_d) {
  const Matrix3d Rx = Eigen::AngleAxisd(abc(0), Vector3d::UnitX()).toRotationMatrix();
  const Matrix3d Ry = Eigen::AngleAxisd(abc(1), Vector3d::UnitY()).toRotationMatrix();
  return abc_d(0) * Vector3d::UnitX() + abc_d(1) * Rx * Vector3d::UnitY() + abc_d(2) * Rx * Ry * Vector3d::UnitZ();
}

TEST(VirtualJointMap, BasePoseAndAngularVelocityAgreeWithKdlForwardKinematics) {
  // The route's own base pose at nonzero virtual coordinates is Trans(p0 + xyz) Rx Ry Rz R0, and
  // the angular velocity formula is the derivative of that rotation (central differences of
  // KDL's forward kinematics).
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  std::mt19937 rng(31);
  const std::string base = model->bodies()[0].name;
  for (int trial = 0; trial < 5; ++trial) {
    const KDL::Frame offset = basePose(toKDL(randomVec(rng, 1.0)), 0.3 * trial, -0.2, 1.1 - 0.4 * trial);
    const VirtualJointDynamics route(*model, offset);
    Eigen::VectorXd theta = randomVector(route.size(), rng, 1.0), theta_d = randomVector(route.size(), rng, 1.0);
    const KDL::Frame T = route.pose(theta, base);
    const Matrix3d R_expected = Eigen::AngleAxisd(theta(3), Vector3d::UnitX()).toRotationMatrix() *
                                Eigen::AngleAxisd(theta(4), Vector3d::UnitY()).toRotationMatrix() *
                                Eigen::AngleAxisd(theta(5), Vector3d::UnitZ()).toRotationMatrix() *
                                toEigen(offset.M);
    EXPECT_TRUE(near(toEigen(T.M), R_expected, 0.0, 1e-14, "base rotation"));
    EXPECT_TRUE(near(toEigen(T.p), toEigen(offset.p) + theta.head<3>(), 0.0, 1e-14, "base origin"));

    const double d = 1e-6;
    const Matrix3d Rp = toEigen(route.pose(theta + d * theta_d, base).M);
    const Matrix3d Rm = toEigen(route.pose(theta - d * theta_d, base).M);
    const Eigen::AngleAxisd delta(Rp * Rm.transpose());
    const Vector3d w_fd = delta.angle() * delta.axis() / (2 * d);
    const Vector3d w = angularVelocity(theta.segment<3>(3), theta_d.segment<3>(3));
    EXPECT_TRUE(near(w_fd, w, 0.0, 1e-8 * w.norm(), "angular velocity"));
  }
}

TEST(VirtualJointMap, AngularAccelerationFormulaAtZeroAngles) {
  // w_dot at zero virtual angles against a central difference of w along
  // angles(t) = t rates + t^2/2 accelerations, rates(t) = rates + t accelerations.
  std::mt19937 rng(32);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::VectorXd theta_d = randomVector(6, rng, 2.0), theta_dd = randomVector(6, rng, 2.0);
    const Vector3d r = theta_d.tail<3>(), a = theta_dd.tail<3>();
    const double t = 1e-5;
    const Vector3d w_dot_fd = (angularVelocity(t * r + 0.5 * t * t * a, r + t * a) -
                               angularVelocity(-t * r + 0.5 * t * t * a, r - t * a)) / (2 * t);
    const Vector3d w_dot = baseAcceleration(theta_d, theta_dd).tail<3>();
    EXPECT_TRUE(near(w_dot, w_dot_fd, 0.0, 1e-8 * w_dot_fd.norm(), "angular acceleration"));
    // The same in components, written out.
    const Vector3d explicit_form(a(0) + r(1) * r(2), a(1) - r(0) * r(2), a(2) + r(0) * r(1));
    EXPECT_TRUE(near(w_dot, explicit_form, 0.0, 1e-15, "components"));
  }
}

// ---- 1. Forward dynamics against the virtual-joint route ------------------------------------------

class ForwardDynamics : public ::testing::TestWithParam<ModelCase> {
 protected:
  void check(const Loads& loads, unsigned seed) {
    ModelPtr model = load(GetParam().path);
    std::mt19937 rng(seed);
    if (loads.armature) {
      std::uniform_real_distribution<double> u(0.0, 2.0);
      std::vector<double> armature(model->nj());
      for (double& a : armature) a = u(rng);
      model = std::make_shared<const FloatingModel>(model->withArmature(armature));
    }
    const int n = static_cast<int>(model->nj());
    ForwardDynamicsSolver solver(model);
    const Vector3d g = loads.gravity ? Vector3d(0.3, -1.2, -9.81) : Vector3d::Zero();
    solver.setGravity(g);
    double worst = 0.0;
    for (int s = 0; s < kStates; ++s) {
      SCOPED_TRACE("state " + std::to_string(s));
      const State state = randomState(*model, rng);
      const FloatingVelocity v = randomVelocity(*model, rng);
      KDL::JntArray tau(n);
      tau.data = randomVector(n, rng, 5.0);
      const std::vector<KDL::Wrench> f = loads.wrenches ? randomWrenches(*model, rng) : std::vector<KDL::Wrench>{};

      FloatingAcceleration acc;
      acc.qddot = KDL::JntArray(n);
      ASSERT_EQ(solver.CartToJnt(state, v, tau, f, acc), E_NOERROR);

      // Independent route.
      const VirtualJointTree tree(*model, state);
      const VirtualJointDynamics route(*model, state.world_T_base);
      Eigen::VectorXd theta = Eigen::VectorXd::Zero(6 + n);
      theta.tail(n) = state.q.data;
      const Eigen::VectorXd theta_d = virtualRates(v);
      const KDL::WrenchMap f_kdl = loads.wrenches ? toKdlWrenches(*model, tree, f) : KDL::WrenchMap();
      const Eigen::VectorXd c = route.inverseDynamics(theta, theta_d, Eigen::VectorXd::Zero(6 + n), toKDL(g), f_kdl);
      Eigen::VectorXd tau_full = Eigen::VectorXd::Zero(6 + n);
      tau_full.tail(n) = tau.data;
      const Eigen::VectorXd theta_dd = tree.M_full().ldlt().solve(tau_full - c);

      const Eigen::VectorXd qdd_ref = theta_dd.tail(n);
      const Vector6d base_ref = baseAcceleration(theta_d, theta_dd);
      EXPECT_TRUE(close(acc.qddot.data, qdd_ref, "qddot"));
      EXPECT_TRUE(close(acc.base.head<3>(), base_ref.head<3>(), "base origin acceleration"));
      EXPECT_TRUE(close(acc.base.tail<3>(), base_ref.tail<3>(), "base angular acceleration"));
      worst = std::max({worst, (acc.qddot.data - qdd_ref).norm() / qdd_ref.norm(),
                        (acc.base - base_ref).norm() / base_ref.norm()});
    }
    std::printf("[ info     ] %s: worst relative difference (2-norm) %.2e\n", GetParam().name.c_str(), worst);
  }
};

TEST_P(ForwardDynamics, VelocityProductsOnly) { check({}, 101); }
TEST_P(ForwardDynamics, WithGravity) { check({true, false, false}, 102); }
TEST_P(ForwardDynamics, WithExternalWrenches) { check({false, true, false}, 103); }
TEST_P(ForwardDynamics, WithGravityWrenchesAndArmature) { check({true, true, true}, 104); }

INSTANTIATE_TEST_SUITE_P(BundledModels, ForwardDynamics, ::testing::ValuesIn(modelCases()), caseName);

// ---- 2. Locked joints: the model with those joints fixed -----------------------------------------

class LockedDynamics : public ::testing::TestWithParam<ModelCase> {};

TEST_P(LockedDynamics, EqualsTheModelWithThoseJointsFixed) {
  const ModelPtr model = load(GetParam().path);
  const int n = static_cast<int>(model->nj());
  ForwardDynamicsSolver solver(model);
  const Vector3d g(0.0, 2.0, -9.81);
  solver.setGravity(g);
  std::mt19937 rng(201);
  std::bernoulli_distribution coin(0.5);
  for (int s = 0; s < 10; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    // Locked subset: random, at least one joint; the last state locks them all.
    std::vector<bool> locked(n);
    int count = 0;
    for (int j = 0; j < n; ++j) count += (locked[j] = s == 9 || coin(rng)) ? 1 : 0;
    if (count == 0) locked[s % n] = true, count = 1;
    solver.setLocked(locked);

    const State state = randomState(*model, rng);
    FloatingVelocity v = randomVelocity(*model, rng);
    KDL::JntArray tau(n);
    tau.data = randomVector(n, rng, 5.0);  // including torques on the locked joints: the brakes take them
    for (int j = 0; j < n; ++j)
      if (locked[j]) v.qdot(j) = 0.0;  // a braked joint does not move
    const std::vector<KDL::Wrench> f = randomWrenches(*model, rng);
    FloatingAcceleration acc;
    acc.qddot = KDL::JntArray(n);
    ASSERT_EQ(solver.CartToJnt(state, v, tau, f, acc), E_NOERROR);
    for (int j = 0; j < n; ++j)
      if (locked[j]) EXPECT_EQ(acc.qddot(j), 0.0) << "locked joint " << model->jointNames()[j];

    // The reduced model: a KDL tree copy with the locked joints fixed at the current q.
    std::map<std::string, double> lock_at;
    for (int j = 0; j < n; ++j)
      if (locked[j]) lock_at[model->jointNames()[j]] = state.q(j);
    const FloatingModel reduced(lockJoints(model->tree(), lock_at), baseInertia(*model));
    const int m = static_cast<int>(reduced.nj());
    ASSERT_EQ(m, n - count);
    State reduced_state(reduced);
    reduced_state.world_T_base = state.world_T_base;
    FloatingVelocity reduced_v;
    reduced_v.base_twist = v.base_twist;
    reduced_v.qdot = KDL::JntArray(m);
    Eigen::VectorXd reduced_tau(m);
    std::vector<int> full_index(m);
    for (int k = 0; k < m; ++k) {
      const int j = model->jointIndex(reduced.jointNames()[k]);
      ASSERT_GE(j, 0);
      full_index[k] = j;
      reduced_state.q(k) = state.q(j);
      reduced_v.qdot(k) = v.qdot(j);
      reduced_tau(k) = tau(j);
    }
    const VirtualJointTree tree(reduced, reduced_state);
    const VirtualJointDynamics route(reduced, reduced_state.world_T_base);
    Eigen::VectorXd theta = Eigen::VectorXd::Zero(6 + m);
    theta.tail(m) = reduced_state.q.data;
    const Eigen::VectorXd theta_d = virtualRates(reduced_v);
    // Same segment names in both trees: the wrenches map by name.
    const KDL::WrenchMap f_kdl = toKdlWrenches(*model, tree, f);
    const Eigen::VectorXd c = route.inverseDynamics(theta, theta_d, Eigen::VectorXd::Zero(6 + m), toKDL(g), f_kdl);
    Eigen::VectorXd tau_full = Eigen::VectorXd::Zero(6 + m);
    tau_full.tail(m) = reduced_tau;
    const Eigen::VectorXd theta_dd = tree.M_full().ldlt().solve(tau_full - c);

    Eigen::VectorXd qdd_free(m);
    for (int k = 0; k < m; ++k) qdd_free(k) = acc.qddot(full_index[k]);
    EXPECT_TRUE(close(qdd_free, theta_dd.tail(m), "free joints' qddot"));
    const Vector6d base_ref = baseAcceleration(theta_d, theta_dd);
    EXPECT_TRUE(close(acc.base.head<3>(), base_ref.head<3>(), "base origin acceleration"));
    EXPECT_TRUE(close(acc.base.tail<3>(), base_ref.tail<3>(), "base angular acceleration"));
  }
}

INSTANTIATE_TEST_SUITE_P(BundledModels, LockedDynamics, ::testing::ValuesIn(modelCases()), caseName);

}  // namespace
}  // namespace kdl_space::test
