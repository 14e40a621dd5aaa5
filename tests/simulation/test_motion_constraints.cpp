// The simulator's motion features against independent routes and closed forms, what holds the system:
//   1. the SpaceDyn two-link sample of an independent engine, every sample (dopri5 and RK4), and
//      the controller's work against the sample's kinetic energy and PD energies;
//   2. a grounded base against KDL's own fixed-base dynamics (ChainDynParam) integrated here;
//   3. braked joints against the same robot with those joints made fixed in the URDF;
//   4. hard stops: momentum kept, the joint held at the limit, the energy lost, the post-stop
//      velocity against the plastic impact computed here from H*, and the release;
//   5. the base control and a thruster: momentum change = external impulse, the torque limits
//      in base axes, the attitude set point reached.
// Forces (test_motion_forces.cpp): a single body under a scheduled force, friction, armature,
// the Rosenbrock method, effort limits.
// No expected value is the library's own output.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <kdl/chaindynparam.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

ModelPtr load(const std::string& path) { return std::make_shared<const FloatingModel>(loadUrdfFile(path)); }

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Eigen::VectorXd jvec(const nlohmann::json& j) {
  Eigen::VectorXd v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) v(i) = j[i].get<double>();
  return v;
}

SimulationState atRest(const FloatingModel& model) {
  SimulationState s;
  s.state = State(model);
  s.velocity.qdot = KDL::JntArray(model.nj());
  return s;
}

// ---- 1. The SpaceDyn sample, every sample -------------------------------------------------------

TEST(MotionFeatures, SpaceDynSampleEverySample) {
  std::ifstream in(dataDir() + "/reference/twolink_pd_motion.json");
  ASSERT_TRUE(in.good());
  const nlohmann::json ref = nlohmann::json::parse(in);
  const nlohmann::json& inputs = ref.at("inputs");
  const ModelPtr model = load(dataDir() + "/reference/" + inputs.at("urdf").get<std::string>());
  const unsigned int n = model->nj();
  std::vector<int> col;  // model index of the reference's joint k
  for (const auto& name : ref.at("joint_names")) col.push_back(model->jointIndex(name.get<std::string>()));
  ASSERT_EQ(col.size(), n);
  const nlohmann::json& samples = ref.at("samples");
  ASSERT_EQ(samples.size(), 11u);
  // The PD energies of the reference: V = 1/2 sum kp (q_des - q)^2 (checked against q here),
  // D = integral of kd qdot^2; the controller's work is then -(V - V0) - D.
  Eigen::VectorXd kp(n), q_des(n);

  for (int k = 0; k < 2; ++k) {
    SimulationOptions options;
    if (k == 0) {
      options.rtol = 1e-13;
      options.atol = 1e-15;
    } else {
      // RK4 at the reference's own step: its truncation error here is ~1e-12 (the reference
      // notes its values converged to that), far below 1e-8.
      options.integrator = Integrator::RK4;
      options.step = 2.5e-4;
    }
    SCOPED_TRACE(k == 0 ? "dopri5" : "RK4");
    Simulator sim(model, options);
    for (const auto& pd : inputs.at("pd")) {
      const int j = model->jointIndex(pd.at("joint").get<std::string>());
      ASSERT_GE(j, 0);
      kp(j) = pd.at("kp").get<double>();
      q_des(j) = pd.at("q_des").get<double>();
      sim.setJointControl(j, JointControl{JointControl::Mode::PD, kp(j), pd.at("kd").get<double>(), q_des(j)});
    }
    SimulationState s = atRest(*model);
    s.state.q = jointsByName(*model, inputs.at("q").get<std::map<std::string, double>>());
    const Eigen::VectorXd p0 = jvec(inputs.at("base_position")), rpy = jvec(inputs.at("base_rpy"));
    s.state.world_T_base = basePose(KDL::Vector(p0(0), p0(1), p0(2)), rpy(0), rpy(1), rpy(2));
    std::vector<SimulationState> out;
    ASSERT_EQ(sim.run(s, inputs.at("duration").get<double>(), 1.0,
                      [&](const SimulationState& x) { out.push_back(x); }),
              E_NOERROR);
    ASSERT_EQ(out.size(), samples.size());
    const double T_ref0 = samples[0].at("kinetic_energy").get<double>();
    const double V_ref0 = samples[0].at("pd_potential_energy").get<double>();
    for (std::size_t i = 0; i < out.size(); ++i) {
      const nlohmann::json& r = samples[i];
      const SimulationState& x = out[i];
      SCOPED_TRACE("t = " + std::to_string(x.t));
      EXPECT_NEAR(x.t, r.at("t").get<double>(), 1e-12);
      EXPECT_TRUE(near(toEigen(x.state.world_T_base.p), jvec(r.at("base_position")), 0.0, 1e-8, "base position"));
      Eigen::Vector4d quat;
      x.state.world_T_base.M.GetQuaternion(quat(0), quat(1), quat(2), quat(3));
      const Eigen::Vector4d quat_ref = jvec(r.at("base_quaternion"));
      if (quat.dot(quat_ref) < 0) quat = -quat;  // q and -q: the same rotation
      EXPECT_TRUE(near(quat, quat_ref, 0.0, 1e-8, "base quaternion"));
      EXPECT_TRUE(near(toEigen(x.velocity.base_twist), jvec(r.at("base_twist")), 0.0, 1e-8, "base twist"));
      Eigen::VectorXd q(n), qdot(n), tau(n);
      for (unsigned int c = 0; c < n; ++c) {
        q(c) = x.state.q(col[c]);
        qdot(c) = x.velocity.qdot(col[c]);
      }
      EXPECT_TRUE(near(q, jvec(r.at("q")), 0.0, 1e-8, "q"));
      EXPECT_TRUE(near(qdot, jvec(r.at("qdot")), 0.0, 1e-8, "qdot"));
      double T;
      Vector6d h;
      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
      EXPECT_TRUE(near(h.head<3>(), jvec(r.at("linear_momentum")), 0.0, 1e-8, "P"));
      EXPECT_TRUE(near(h.tail<3>(), jvec(r.at("angular_momentum_about_origin")), 0.0, 1e-8, "L"));
      const double T_ref = r.at("kinetic_energy").get<double>();
      EXPECT_NEAR(T, T_ref, 1e-8);
      // Work of the controller = kinetic energy gained (no other force acts).
      EXPECT_NEAR(x.work.controller, T_ref - T_ref0, 1e-8);
      EXPECT_NEAR(x.work.total(), T_ref - T_ref0, 1e-8);
      // ... and = the PD's potential released minus what its damper dissipated.
      const double V_ref = r.at("pd_potential_energy").get<double>(), D_ref = r.at("pd_dissipated_energy").get<double>();
      double V = 0.0;
      for (unsigned int j = 0; j < n; ++j) V += 0.5 * kp(j) * (q_des(j) - x.state.q(j)) * (q_des(j) - x.state.q(j));
      EXPECT_NEAR(V, V_ref, 1e-8) << "the reference's PD potential";
      EXPECT_NEAR(x.work.controller, -(V_ref - V_ref0) - D_ref, 1e-8);
      EXPECT_EQ(x.work.friction, 0.0);
      EXPECT_EQ(x.work.limits, 0.0);
    }
  }
}

// ---- 2. Grounded base = fixed-base KDL dynamics --------------------------------------------------

TEST(MotionFeatures, GroundedEqualsFixedBaseKdlDynamics) {
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  const unsigned int n = model->nj();
  ASSERT_EQ(n, 7u);
  KDL::Chain chain;
  ASSERT_TRUE(model->tree().getChain(model->bodies()[0].name, "link7", chain));
  ASSERT_EQ(chain.getNrOfJoints(), n);
  // chain joint k -> model joint perm[k]
  std::vector<int> perm;
  for (unsigned int i = 0; i < chain.getNrOfSegments(); ++i)
    if (chain.getSegment(i).getJoint().getType() != KDL::Joint::None)
      perm.push_back(model->jointIndex(chain.getSegment(i).getJoint().getName()));
  ASSERT_EQ(perm.size(), n);

  const KDL::Frame base = basePose(KDL::Vector(0.3, -1.0, 2.0), 0.4, -0.7, 1.1);
  const Vector3d g_world(0.0, 0.0, -9.81);
  const Vector3d g_base = toEigen(base.M).transpose() * g_world;  // ChainDynParam: chain-base axes
  KDL::ChainDynParam dyn(chain, toKDL(g_base));

  const double q0[7] = {0.3, -0.5, 0.8, 1.2, -0.4, 0.6, 0.2};
  const double qd0[7] = {0.2, -0.1, 0.3, 0.0, 0.4, -0.3, 0.5};
  // PD on joints 0, 2, 4 (model order); the others free.
  const double kp[7] = {200, 0, 150, 0, 40, 0, 0}, kd[7] = {60, 0, 40, 0, 8, 0, 0};
  const double sp[7] = {-0.2, 0, 0.1, 0, 0.5, 0, 0};

  SimulationOptions options;
  options.integrator = Integrator::RK4;
  options.step = 1e-3;
  options.gravity = g_world;
  options.grounded = true;
  options.effort_limits = false;
  options.joint_friction = false;
  Simulator sim(model, options);
  for (unsigned int j = 0; j < n; ++j)
    if (kp[j] > 0) sim.setJointControl(j, JointControl{JointControl::Mode::PD, kp[j], kd[j], sp[j]});
  SimulationState s = atRest(*model);
  s.state.world_T_base = base;
  for (unsigned int j = 0; j < n; ++j) {
    s.state.q(j) = q0[j];
    s.velocity.qdot(j) = qd0[j];
  }

  // Own RK4 on (q, qdot) in model order with qddot = H^-1 (tau - C qdot - G) from KDL.
  auto f = [&](const Eigen::VectorXd& y) {
    KDL::JntArray q(n), qd(n), C(n), G(n);
    KDL::JntSpaceInertiaMatrix H(n);
    for (unsigned int k = 0; k < n; ++k) {
      q(k) = y(perm[k]);
      qd(k) = y(n + perm[k]);
    }
    dyn.JntToMass(q, H);
    dyn.JntToCoriolis(q, qd, C);
    dyn.JntToGravity(q, G);
    Eigen::VectorXd tau(n);
    for (unsigned int k = 0; k < n; ++k) {
      const int j = perm[k];
      tau(k) = kp[j] * (sp[j] - y(j)) - kd[j] * y(n + j) - C(k) - G(k);
    }
    const Eigen::VectorXd qdd_chain = H.data.ldlt().solve(tau);
    Eigen::VectorXd dy(2 * n);
    dy.head(n) = y.tail(n);
    for (unsigned int k = 0; k < n; ++k) dy(n + perm[k]) = qdd_chain(k);
    return dy;
  };
  Eigen::VectorXd y(2 * n);
  y << s.state.q.data, s.velocity.qdot.data;
  double t_own = 0.0;
  const double h = 1e-3;
  double worst = 0.0;
  int outputs = 0;
  ASSERT_EQ(sim.run(s, 1.0, 0.1,
                    [&](const SimulationState& x) {
                      ++outputs;
                      while (t_own < x.t - 1e-9) {
                        const Eigen::VectorXd k1 = f(y), k2 = f(y + 0.5 * h * k1), k3 = f(y + 0.5 * h * k2),
                                              k4 = f(y + h * k3);
                        y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                        t_own += h;
                      }
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      // The same scheme and step on the same ODE: only round-off differs.
                      EXPECT_TRUE(near(x.state.q.data, y.head(n), 1e-9, 1e-11, "q"));
                      EXPECT_TRUE(near(x.velocity.qdot.data, y.tail(n), 1e-9, 1e-11, "qdot"));
                      worst = std::max({worst, (x.state.q.data - y.head(n)).cwiseAbs().maxCoeff(),
                                        (x.velocity.qdot.data - y.tail(n)).cwiseAbs().maxCoeff()});
                      EXPECT_TRUE(Equal(x.state.world_T_base, base, 1e-15)) << "the base moved";
                      EXPECT_EQ(toEigen(x.velocity.base_twist).norm(), 0.0);
                    }),
            E_NOERROR);
  EXPECT_EQ(outputs, 11);
  std::printf("[ info     ] grounded vs KDL ChainDynParam over 1 s: worst difference %.2e\n", worst);
  // The motion is not trivial: the joints travelled.
  EXPECT_GT((y.head(n) - Eigen::Map<const Eigen::VectorXd>(q0, n)).norm(), 0.1);
}

// ---- 3. Braked joints = fixed joints --------------------------------------------------------------

TEST(MotionFeatures, LockedArmEqualsFixedJointsInTheUrdf) {
  const std::string path = urdfDir() + "/dual_arm.urdf";
  const std::string text = readText(path);
  // The right arm's joints made fixed (at q = 0: the origin needs no composition).
  const std::regex right_joint(R"re((<joint name="right_joint\d+" type=")revolute")re");
  const std::string fixed_text = std::regex_replace(text, right_joint, "$1fixed\"");
  ASSERT_NE(fixed_text, text);
  const ModelPtr full = std::make_shared<const FloatingModel>(loadUrdfString(text, "dual_arm"));
  const ModelPtr fixed = std::make_shared<const FloatingModel>(loadUrdfString(fixed_text, "dual_arm_fixed"));
  ASSERT_GT(full->nj(), fixed->nj());
  for (const std::string& name : fixed->jointNames()) ASSERT_EQ(name.rfind("left_", 0), 0u) << name;

  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim_full(full, options), sim_fixed(fixed, options);
  SimulationState a = atRest(*full), b = atRest(*fixed);
  a.state.world_T_base = b.state.world_T_base = basePose(KDL::Vector(0.5, 0.2, -0.3), 0.1, 0.2, -0.3);
  a.velocity.base_twist = b.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, -0.02, 0.03), KDL::Vector(0.02, 0.01, -0.015));
  for (unsigned int jf = 0; jf < fixed->nj(); ++jf) {
    const int j = full->jointIndex(fixed->jointNames()[jf]);
    ASSERT_GE(j, 0);
    a.state.q(j) = b.state.q(jf) = 0.3 * std::sin(1.0 + jf);
    a.velocity.qdot(j) = b.velocity.qdot(jf) = 0.2 * std::cos(2.0 + jf);
    const JointControl pd{JointControl::Mode::PD, 30.0, 8.0, -0.4 + 0.15 * jf};
    sim_full.setJointControl(j, pd);
    sim_fixed.setJointControl(jf, pd);
  }
  for (unsigned int j = 0; j < full->nj(); ++j)
    if (full->jointNames()[j].rfind("right_", 0) == 0) sim_full.setJointControl(j, JointControl{JointControl::Mode::Locked});

  std::vector<SimulationState> out_full, out_fixed;
  ASSERT_EQ(sim_full.run(a, 3.0, 0.5, [&](const SimulationState& x) { out_full.push_back(x); }), E_NOERROR);
  ASSERT_EQ(sim_fixed.run(b, 3.0, 0.5, [&](const SimulationState& x) { out_fixed.push_back(x); }), E_NOERROR);
  ASSERT_EQ(out_full.size(), out_fixed.size());
  for (std::size_t i = 0; i < out_full.size(); ++i) {
    const SimulationState &x = out_full[i], &y = out_fixed[i];
    SCOPED_TRACE("t = " + std::to_string(x.t));
    // Both integrated to rtol 1e-12: their difference is the integration error, ~1e-11.
    EXPECT_TRUE(near(toEigen(x.state.world_T_base.p), toEigen(y.state.world_T_base.p), 0.0, 1e-9, "base position"));
    EXPECT_TRUE(near(toEigen(x.state.world_T_base.M), toEigen(y.state.world_T_base.M), 0.0, 1e-9, "base rotation"));
    EXPECT_TRUE(near(toEigen(x.velocity.base_twist), toEigen(y.velocity.base_twist), 0.0, 1e-9, "base twist"));
    for (unsigned int jf = 0; jf < fixed->nj(); ++jf) {
      const int j = full->jointIndex(fixed->jointNames()[jf]);
      EXPECT_NEAR(x.state.q(j), y.state.q(jf), 1e-9) << fixed->jointNames()[jf];
      EXPECT_NEAR(x.velocity.qdot(j), y.velocity.qdot(jf), 1e-9) << fixed->jointNames()[jf];
    }
    for (unsigned int j = 0; j < full->nj(); ++j)
      if (full->jointNames()[j].rfind("right_", 0) == 0) {
        EXPECT_EQ(x.state.q(j), 0.0);
        EXPECT_EQ(x.velocity.qdot(j), 0.0);
      }
  }
  // The base turned: the comparison has something to compare.
  EXPECT_GT((toEigen(out_full.back().state.world_T_base.M) - toEigen(out_full.front().state.world_T_base.M)).norm(), 1e-3);
}

// ---- 4. Hard stops --------------------------------------------------------------------------------

struct StopCase {
  ModelPtr model;
  double upper = 0.6;
  static constexpr unsigned int kJoint = 1;
  StopCase() {
    const FloatingModel base = loadUrdfFile(urdfDir() + "/spacedyn_twolink.urdf");
    JointProperties p;
    p.lower = -1.0;
    p.upper = upper;
    model = std::make_shared<const FloatingModel>(base.withJointProperties({{"joint2", p}}));
  }
  SimulationState initial() const {
    SimulationState s = atRest(*model);
    s.state.q(0) = 0.2;
    s.velocity.qdot(0) = 0.3;
    s.velocity.qdot(1) = 0.5;
    s.velocity.base_twist = KDL::Twist(KDL::Vector(0.05, -0.02, 0.0), KDL::Vector(0.0, 0.0, 0.1));
    return s;
  }
  void controls(Simulator& sim, double set_point) const {
    sim.setJointControl(kJoint, JointControl{JointControl::Mode::PD, 20.0, 2.0, set_point});
  }
  static SimulationOptions options() {
    SimulationOptions o;
    o.rtol = 1e-12;
    o.atol = 1e-14;
    return o;
  }
};

TEST(MotionFeatures, HardStopKeepsMomentumAndHolds) {
  const StopCase c;
  ASSERT_EQ(c.model->jointProperties()[StopCase::kJoint].upper, c.upper);
  Simulator sim(c.model, StopCase::options());
  c.controls(sim, 1.2);  // beyond the limit
  sim.setLimitMode(StopCase::kJoint, LimitMode::Stop);
  SimulationState s = c.initial();
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  double max_q = -1e9;
  bool held = false;
  ASSERT_EQ(sim.run(s, 4.0, 0.05,
                    [&](const SimulationState& x) {
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      // The stop's impulse is internal.
                      EXPECT_TRUE(near(h, h0, 0.0, 1e-10 * h0.norm(), "momentum"));
                      max_q = std::max(max_q, x.state.q(StopCase::kJoint));
                      EXPECT_LE(x.state.q(StopCase::kJoint), c.upper + 1e-9);
                      // T - T0 = the work of everything (an integral carried at the state's
                      // tolerance; the stop's loss exactly at the impact).
                      EXPECT_NEAR(T - T0, x.work.total(), 1e-8 * std::max(1.0, T0));
                      if (std::abs(x.state.q(StopCase::kJoint) - c.upper) < 1e-9) held = true;
                      if (held) EXPECT_EQ(x.velocity.qdot(StopCase::kJoint), 0.0) << "held at the stop";
                    }),
            E_NOERROR);
  EXPECT_TRUE(held);
  EXPECT_GE(sim.stats().joints[StopCase::kJoint].stops, 1);
  EXPECT_LT(s.work.limits, 0.0);
  EXPECT_GT(max_q, c.upper - 1e-9);
  // Released when the set point goes back inside the range.
  c.controls(sim, 0.0);
  ASSERT_EQ(sim.run(s, 6.0, 0.5, nullptr), E_NOERROR);
  EXPECT_LT(s.state.q(StopCase::kJoint), c.upper - 0.05) << "the joint should have left the stop";
}

// A torque that pushes the joint into its stop and pulls it away, again and again (a square wave
// by callback): every hit is an impact at the limit, every pull a release, the run goes on (a
// joint is never stopped and released in the same step), the momentum is kept throughout.
TEST(MotionFeatures, RepeatedStopsAndReleasesKeepTheMomentum) {
  const StopCase c;
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54, Integrator::Rosenbrock}) {
    SCOPED_TRACE(static_cast<int>(integrator));
    SimulationOptions o = StopCase::options();
    o.integrator = integrator;
    o.step = 1e-3;
    if (integrator == Integrator::Rosenbrock) o.rtol = 1e-9, o.atol = 1e-11;
    Simulator sim(c.model, o);
    sim.setLimitMode(StopCase::kJoint, LimitMode::Stop);
    sim.setTorqueCallback([](const SimulationState& x, KDL::JntArray& tau) {
      tau(StopCase::kJoint) = std::fmod(x.t, 1.0) < 0.5 ? 30.0 : -30.0;
    });
    SimulationState s = c.initial();
    double T0;
    Vector6d h0;
    ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
    ASSERT_EQ(sim.run(s, 4.0, 0.01,
                      [&](const SimulationState& x) {
                        double T;
                        Vector6d h;
                        ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                        EXPECT_TRUE(near(h, h0, 0.0, 1e-10 * h0.norm(), "momentum"));
                        EXPECT_LE(x.state.q(StopCase::kJoint), c.upper + 1e-9);
                      }),
              E_NOERROR);
    EXPECT_GE(sim.stats().joints[StopCase::kJoint].stops, 3) << "a hit in each push";
    EXPECT_LT(sim.stats().accepted_steps, 100000);
  }
}

TEST(MotionFeatures, HardStopVelocityIsThePlasticImpact) {
  // The state at the impact found with the limit ignored (the same motion until then), by
  // bisection on q_j = upper; the plastic impact computed here: H* dqdot = e_j lambda (an internal
  // impulse on joint j only), qdot_j' = 0, the momentum kept; then the motion continued with the
  // joint braked (JointControl::Locked), and compared with the hard-stop run after the impact.
  const StopCase c;
  const unsigned int j = StopCase::kJoint;
  Simulator free_sim(c.model, StopCase::options());
  c.controls(free_sim, 1.2);
  free_sim.setLimitMode(j, LimitMode::Ignore);
  SimulationState s = c.initial(), before;
  bool crossed = false;
  ASSERT_EQ(free_sim.run(s, 4.0, 0.01,
                         [&](const SimulationState& x) {
                           if (!crossed && x.state.q(j) < c.upper) before = x;
                           if (x.state.q(j) >= c.upper) crossed = true;
                         }),
            E_NOERROR);
  ASSERT_TRUE(crossed);
  double lo = before.t, hi = before.t + 0.01;
  SimulationState at = before;
  for (int it = 0; it < 60 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    SimulationState x = before;
    ASSERT_EQ(free_sim.run(x, mid, mid - before.t, nullptr), E_NOERROR);
    if (x.state.q(j) < c.upper) lo = mid; else hi = mid;
    at = x;
  }
  ASSERT_NEAR(at.state.q(j), c.upper, 1e-12);
  ASSERT_GT(at.velocity.qdot(j), 0.05) << "it hits the stop moving";
  FreeFloatingSolver solver(c.model);
  ASSERT_EQ(solver.compute(at.state), E_NOERROR);
  const Eigen::MatrixXd Hinv = solver.H_star().data.inverse();
  SimulationState post = at;
  post.velocity.qdot.data = at.velocity.qdot.data - Hinv.col(j) * (at.velocity.qdot(j) / Hinv(j, j));
  Vector6d PL_g;
  ASSERT_EQ(solver.momentum(at.velocity.base_twist, at.velocity.qdot, PL_g), E_NOERROR);
  ASSERT_EQ(solver.baseTwist(PL_g, post.velocity.qdot, post.velocity.base_twist), E_NOERROR);
  EXPECT_NEAR(post.velocity.qdot(j), 0.0, 1e-14);
  const double t_check = at.t + 0.2;
  Simulator locked_sim(c.model, StopCase::options());
  locked_sim.setJointControl(j, JointControl{JointControl::Mode::Locked});
  locked_sim.setLimitMode(j, LimitMode::Ignore);
  SimulationState expected = post;
  ASSERT_EQ(locked_sim.run(expected, t_check, t_check - at.t, nullptr), E_NOERROR);

  Simulator stop_sim(c.model, StopCase::options());
  c.controls(stop_sim, 1.2);
  stop_sim.setLimitMode(j, LimitMode::Stop);
  SimulationState got = c.initial();
  ASSERT_EQ(stop_sim.run(got, t_check, t_check, nullptr), E_NOERROR);
  ASSERT_EQ(stop_sim.stats().joints[j].stops, 1);
  // The stop is located within 1e-10 of the limit, so in time within ~1e-10 / qdot_j; both runs
  // are integrated to 1e-12: agreement to 1e-8.
  EXPECT_EQ(got.velocity.qdot(j), 0.0);
  EXPECT_NEAR(got.state.q(j), c.upper, 1e-9);
  EXPECT_TRUE(near(got.velocity.qdot.data, expected.velocity.qdot.data, 0.0, 1e-8, "qdot after the stop"));
  EXPECT_TRUE(near(toEigen(got.velocity.base_twist), toEigen(expected.velocity.base_twist), 0.0, 1e-8, "base twist"));
  EXPECT_TRUE(near(got.state.q.data, expected.state.q.data, 0.0, 1e-8, "q"));
  EXPECT_TRUE(near(toEigen(got.state.world_T_base.p), toEigen(expected.state.world_T_base.p), 0.0, 1e-8, "base"));
  // Energy lost at the impact: 1/2 qdot_j^2 / (H*^-1)_jj (the plastic impact's closed form).
  double T_at, T_post;
  Vector6d h;
  ASSERT_EQ(stop_sim.energyAndMomentum(at, T_at, h), E_NOERROR);
  ASSERT_EQ(stop_sim.energyAndMomentum(post, T_post, h), E_NOERROR);
  EXPECT_NEAR(T_at - T_post, 0.5 * at.velocity.qdot(j) * at.velocity.qdot(j) / Hinv(j, j), 1e-12 * T_at);
  EXPECT_NEAR(got.work.limits, T_post - T_at, 1e-8);
}

// ---- 5. Base control and scheduled wrenches -------------------------------------------------------

TEST(MotionFeatures, BaseControlAndThrusterImpulseBalance) {
  const ModelPtr model = load(urdfDir() + "/space_arm7.urdf");
  const unsigned int n = model->nj();
  SimulationOptions options;
  options.rtol = 1e-12;
  options.atol = 1e-14;
  Simulator sim(model, options);
  BaseControl bc;
  bc.attitude.on = true;
  bc.attitude.set_point = KDL::Rotation::Identity();
  bc.attitude.kp = 100.0;
  bc.attitude.kd = 400.0;
  const double limit = 3.0;
  bc.attitude.torque_limit = Vector3d::Constant(limit);
  sim.setBaseControl(bc);
  ScheduledWrench thruster;
  thruster.body = model->bodyIndex("link3");
  thruster.point = Vector3d(0.1, 0.0, 0.05);
  thruster.wrench << 5.0, 0.0, -2.0, 0.0, 1.0, 0.0;
  thruster.start = 1.0;
  thruster.end = 3.0;
  sim.addWrench(thruster);
  for (unsigned int j = 0; j < n; ++j) {
    JointControl pd{JointControl::Mode::PD, 50.0, 20.0};
    pd.hold = true;
    sim.setJointControl(j, pd);
  }
  SimulationState s = atRest(*model);
  for (unsigned int j = 0; j < n; ++j) s.state.q(j) = 0.2 * std::cos(j + 0.5);
  s.state.world_T_base = basePose(KDL::Vector(0.2, 0.1, -0.4), 0.2, -0.1, 0.3);
  s.velocity.base_twist = KDL::Twist(KDL::Vector(0.01, 0.0, -0.01), KDL::Vector(0.01, 0.02, -0.01));
  double T0;
  Vector6d h0;
  ASSERT_EQ(sim.energyAndMomentum(s, T0, h0), E_NOERROR);
  double worst = 0.0, scale_max = 0.0;
  ASSERT_EQ(sim.run(s, 60.0, 1.0,
                    [&](const SimulationState& x) {
                      SCOPED_TRACE("t = " + std::to_string(x.t));
                      double T;
                      Vector6d h;
                      ASSERT_EQ(sim.energyAndMomentum(x, T, h), E_NOERROR);
                      const double scale = x.impulse.norm() + h0.norm() + 1e-3;
                      scale_max = std::max(scale_max, x.impulse.norm());
                      const double e = (h - h0 - x.impulse).norm();
                      worst = std::max(worst, e / scale);
                      EXPECT_LE(e, 1e-10 * scale) << "momentum change vs external impulse";
                      // The wheel torques in the base's axes within their limits.
                      const Vector3d n_base = toEigen(x.state.world_T_base.M).transpose() * x.base_wrench.tail<3>();
                      EXPECT_LE(n_base.cwiseAbs().maxCoeff(), limit * (1.0 + 1e-12));
                      EXPECT_EQ(x.base_wrench.head<3>().norm(), 0.0) << "attitude control only: no force";
                      EXPECT_NEAR(T - T0, x.work.total(), 1e-8 * std::max(1.0, T));
                    }),
            E_NOERROR);
  std::printf("[ info     ] base control: worst momentum balance %.2e (impulse up to %.2e)\n", worst, scale_max);
  EXPECT_GT(scale_max, 1.0) << "the impulse must be substantial";
  EXPECT_GT(sim.stats().base_saturation_time, 0.0) << "the torque limit must be reached";
  // Attitude reached.
  const KDL::Rotation error = s.state.world_T_base.M;
  EXPECT_LT(error.GetRot().Norm(), 1e-3);
  EXPECT_LT(s.velocity.base_twist.rot.Norm(), 1e-3);
}

}  // namespace
}  // namespace kdl_space::test
