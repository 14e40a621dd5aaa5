// kdl_space_bench: times our G*, J*, H*, the full post-impact state of a capture, forward
// dynamics and a simulation side by side with the naive KDL route (six virtual base joints +
// ChainDynParam + ChainJntToJacSolver + an Eigen factorisation), with the library's previous
// dense forward dynamics (the composite-rigid-body route of tests/support, compiled in) and,
// when built with DART, with DART's J M^-1 J^T and computeForwardDynamics on the same URDF with a
// free root joint. Before timing, the forward dynamics of every route are checked equal to 1e-9
// (and the two simulations to each other); the benchmark aborts if they are not. Prints the
// ratios; --markdown FILE writes the tables.
//
//   kdl_space_bench [--model FILE.urdf --tip LINK [--offset X Y Z]] [--sizes 7,14,...]
//                   [--simulate 7,100] [--mimic-sizes 10,30,50,100] [--markdown FILE]
//                   [Google Benchmark flags, e.g. --benchmark_repetitions=5]
//   kdl_space_bench --plan SCENARIO.yaml [Google Benchmark flags]   (planCapture alone: plan_bench.hpp)
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <map>
#include <random>
#include <sstream>

#include "crb_forward_dynamics.hpp"
#include "generated_chain.hpp"
#include "mimic_bench.hpp"
#include "plan_bench.hpp"
#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/study/study.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

#ifdef KDL_SPACE_WITH_DART
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/DegreeOfFreedom.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/utils/urdf/DartLoader.hpp>
#endif

using namespace kdl_space;

namespace {

/// One robot under test: its URDF text, contact link and offset, and a state.
struct Case {
  std::string name, urdf, tip;
  KDL::Vector offset;
  std::shared_ptr<const FloatingModel> model;
  State state;      ///< the configuration timed
  State other;      ///< a second one: calls alternate so that no library can reuse a cached result
  Contact contact;
  FloatingVelocity velocity;  ///< forward dynamics and simulation: base twist and joint rates
  KDL::JntArray tau;          ///< forward dynamics: joint torques
  bool simulate = false;      ///< whether the 10 s simulation is timed on this case
  const State& at(std::size_t i) const { return i & 1 ? other : state; }
};

Case makeCase(const std::string& name, const std::string& urdf, const std::string& tip, const KDL::Vector& offset) {
  Case c{name, urdf, tip, offset, std::make_shared<const FloatingModel>(loadUrdfString(urdf, name)), {}, {}, {}, {}, {}};
  const unsigned int n = c.model->nj();
  c.velocity = FloatingVelocity(KDL::Twist(KDL::Vector(0.01, -0.005, 0.002), KDL::Vector(0.003, 0.02, -0.01)),
                                KDL::JntArray(n));
  c.tau = KDL::JntArray(n);
  for (unsigned int j = 0; j < n; ++j) {
    c.velocity.qdot(j) = 0.1 - 0.02 * (j % 7);
    c.tau(j) = 0.5 * std::sin(1.0 + j);
  }
  c.state = State(*c.model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-1.0, 1.0);
  for (unsigned int j = 0; j < c.model->nj(); ++j) c.state.q(j) = angle(rng);
  c.state.world_T_base = basePose(KDL::Vector(0.3, -0.2, 0.1), 0.1, -0.2, 0.3);
  c.other = c.state;
  for (unsigned int j = 0; j < c.model->nj(); ++j) c.other.q(j) += 0.01;
  c.contact = c.model->contact(tip, offset);
  return c;
}

/// The naive KDL route for G*: a chain with six virtual base joints, its full mass matrix from
/// ChainDynParam, its Jacobian from ChainJntToJacSolver, and an Eigen Cholesky.
struct NaiveKdl {
  KDL::Chain chain;
  KDL::JntArray q;
  std::unique_ptr<KDL::ChainDynParam> dyn;
  std::unique_ptr<KDL::ChainJntToJacSolver> jac;
  KDL::JntSpaceInertiaMatrix M;
  KDL::Jacobian J;

  explicit NaiveKdl(const Case& c) {
    const FloatingModel& m = *c.model;
    const Body& base = m.bodies()[0];
    const Matrix3d& I = base.I_com;
    const KDL::Frame& T = c.state.world_T_base;
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::TransX), KDL::Frame(T.p)));
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::TransY)));
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::TransZ)));
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotX)));
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotY)));
    chain.addSegment(KDL::Segment(base.name, KDL::Joint(KDL::Joint::RotZ), KDL::Frame(T.M),
                                  KDL::RigidBodyInertia(base.mass, toKDL(base.com),
                                                        KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1),
                                                                               I(0, 2), I(1, 2)))));
    KDL::Chain arm;
    m.tree().getChain(base.name, c.tip, arm);
    chain.addChain(arm);
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::None), KDL::Frame(c.offset)));
    q = KDL::JntArray(chain.getNrOfJoints());
    for (unsigned int j = 0; j < arm.getNrOfJoints(); ++j) q(6 + j) = c.state.q(j);  // a chain: same order
    dyn = std::make_unique<KDL::ChainDynParam>(chain, KDL::Vector::Zero());
    jac = std::make_unique<KDL::ChainJntToJacSolver>(chain);
    M = KDL::JntSpaceInertiaMatrix(chain.getNrOfJoints());
    J = KDL::Jacobian(chain.getNrOfJoints());
  }
  void G_star(Matrix6d& G, std::size_t i) {
    q(6) = (i & 1) ? 1e-3 : 0.0;  // alternate the configuration, as for the others
    dyn->JntToMass(q, M);
    jac->JntToJac(q, J);
    const Eigen::LLT<Eigen::MatrixXd> llt(M.data);
    G.noalias() = J.data * llt.solve(J.data.transpose());
  }
};

std::vector<Case>& cases() {
  static std::vector<Case> all;
  return all;
}

#ifdef KDL_SPACE_WITH_DART
/// DART's skeleton of a case's URDF (a free root joint, massless links given zero inertia as our
/// loader does), with the case's two states, velocity and torques as DART coordinates. DART's
/// free joint takes the base's twist in base axes, angular part first.
struct DartRoute {
  dart::dynamics::SkeletonPtr skel;
  std::vector<std::size_t> dof;  ///< per model joint: its DART degree of freedom
  Eigen::VectorXd q[2], dq[2], forces;

  explicit DartRoute(const Case& c) {
    dart::utils::DartLoader::Options options;
    options.mDefaultRootJointType = dart::utils::DartLoader::RootJointType::FLOATING;
    options.mDefaultInertia = dart::dynamics::Inertia(0.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
    dart::utils::DartLoader loader(options);
    skel = loader.parseSkeletonString(c.urdf, "");
    if (!skel) return;
    skel->setGravity(Eigen::Vector3d::Zero());
    const unsigned int n = c.model->nj();
    forces = Eigen::VectorXd::Zero(skel->getNumDofs());
    for (unsigned int j = 0; j < n; ++j) {
      const auto* d = skel->getDof(c.model->jointNames()[j]);
      if (!d) throw ModelError("DART has no joint " + c.model->jointNames()[j]);
      dof.push_back(d->getIndexInSkeleton());
      forces(dof.back()) = c.tau(j);
    }
    for (std::size_t k = 0; k < 2; ++k) {
      const State& s = c.at(k);
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = toEigen(s.world_T_base.M);
      T.translation() = toEigen(s.world_T_base.p);
      q[k] = dq[k] = Eigen::VectorXd::Zero(skel->getNumDofs());
      q[k].head<6>() = dart::dynamics::FreeJoint::convertToPositions(T);
      dq[k].head<3>() = T.linear().transpose() * toEigen(c.velocity.base_twist.rot);
      dq[k].segment<3>(3) = T.linear().transpose() * toEigen(c.velocity.base_twist.vel);
      for (unsigned int j = 0; j < n; ++j) {
        q[k](dof[j]) = s.q(j);
        dq[k](dof[j]) = c.velocity.qdot(j);
      }
    }
  }
  void forwardDynamics(std::size_t k) {
    skel->setPositions(q[k]);
    skel->setVelocities(dq[k]);
    skel->setForces(forces);
    skel->computeForwardDynamics();
  }
  /// DART's accelerations of the last forwardDynamics(k) in our terms: the base origin's
  /// classical acceleration R (v_b' + w_b x v_b) and R w_b' (world), and the joints'.
  void acceleration(const Case& c, std::size_t k, FloatingAcceleration& a) const {
    const Eigen::VectorXd& ddq = skel->getAccelerations();
    const Matrix3d R = toEigen(c.at(k).world_T_base.M);
    const Vector3d w_b = dq[k].head<3>(), v_b = dq[k].segment<3>(3);
    a.base.head<3>() = R * (ddq.segment<3>(3) + w_b.cross(v_b));
    a.base.tail<3>() = R * ddq.head<3>();
    for (std::size_t j = 0; j < dof.size(); ++j) a.qddot(j) = ddq(dof[j]);
  }
};
#endif

/// ||x - y|| / ||y||
double relative(const Eigen::VectorXd& x, const Eigen::VectorXd& y) { return (x - y).norm() / y.norm(); }

/// Two accelerations apart: max over the base origin's acceleration, the base's angular
/// acceleration and qddot of ||a - b|| / ||b|| (each block relative to its own size: the heavy
/// base's accelerations are far smaller than the joints').
double mismatch(const FloatingAcceleration& a, const FloatingAcceleration& b) {
  return std::max({relative(a.base.head<3>(), b.base.head<3>()), relative(a.base.tail<3>(), b.base.tail<3>()),
                   relative(a.qddot.data, b.qddot.data)});
}

/// Two simulated states apart: the same over base position, base twist, q and qdot.
double mismatch(const SimulationState& a, const SimulationState& b) {
  return std::max({relative(toEigen(a.state.world_T_base.p), toEigen(b.state.world_T_base.p)),
                   relative(toEigen(a.velocity.base_twist), toEigen(b.velocity.base_twist)),
                   relative(a.state.q.data, b.state.q.data), relative(a.velocity.qdot.data, b.velocity.qdot.data)});
}

/// A 10 s simulation of a case (dopri5, rtol 1e-10, free joints), as `kdl_space simulate` after
/// a capture: the start state, and the end state of each route from the set-up run.
struct SimulationCase {
  SimulationState start, ours_end, dense_end;
  SimulationStats ours_stats, dense_stats;
  double difference_1s = 0.0, difference = 0.0;  ///< mismatch of the end states after 1 s and 10 s
  static constexpr double kDuration = 10.0;
};

SimulationState startOf(const Case& c) {
  SimulationState s;
  s.state = c.state;
  s.velocity = c.velocity;
  return s;
}

/// s = from, without allocating (same sizes).
void reset(SimulationState& s, const SimulationState& from) {
  s.t = from.t;
  s.state.world_T_base = from.state.world_T_base;
  s.state.q.data = from.state.q.data;
  s.velocity.base_twist = from.velocity.base_twist;
  s.velocity.qdot.data = from.velocity.qdot.data;
}

std::map<std::string, SimulationCase>& simulations() {
  static std::map<std::string, SimulationCase> all;
  return all;
}

/// The set-up check: every forward dynamics route equal to 1e-9 at both states of every case,
/// and the two simulations equal to each other; false (with the figures on stderr) if not.
bool checkRoutes() {
  bool ok = true;
  for (const Case& c : cases()) {
    const unsigned int n = c.model->nj();
    ForwardDynamicsSolver aba(c.model);
    test::CrbForwardDynamics crb(c.model);
    const std::vector<KDL::Wrench> none;
    for (std::size_t k = 0; k < 2; ++k) {
      FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(n)}, b = a;
      if (aba.CartToJnt(c.at(k), c.velocity, c.tau, none, a) || crb.CartToJnt(c.at(k), c.velocity, c.tau, none, b)) {
        std::cerr << "kdl_space_bench: " << c.name << ": forward dynamics failed\n";
        return false;
      }
      const double e = mismatch(a, b);
      std::cerr << "check " << c.name << " state " << k << ": ABA vs composite-rigid-body route " << e;
      ok = ok && e <= 1e-9;
#ifdef KDL_SPACE_WITH_DART
      DartRoute dart(c);
      if (!dart.skel) {
        std::cerr << "\nkdl_space_bench: DART could not load " << c.name << "\n";
        return false;
      }
      dart.forwardDynamics(k);
      FloatingAcceleration d = a;
      dart.acceleration(c, k, d);
      const double e_dart = mismatch(a, d);
      std::cerr << ", vs DART " << e_dart;
      ok = ok && e_dart <= 1e-9;
#endif
      std::cerr << "\n";
    }
    if (!c.simulate) continue;
    // The simulations: after 1 s equal to 1e-9; after 10 s in the same steps, the states apart by
    // the round-off of the derivatives (~1e-13) as the motion amplifies it (a folded 100-link
    // chain: ~1e-12 after 1 s, ~1e-6 after 10 s; each run's own error grows alike).
    SimulationCase& sim = simulations()[c.name];
    sim.start = startOf(c);
    for (const double T : {1.0, SimulationCase::kDuration}) {
      sim.ours_end = sim.dense_end = sim.start;
      Simulator ours(c.model);
      test::CrbSimulator dense(c.model);
      if (ours.run(sim.ours_end, T, T, {}) || dense.run(sim.dense_end, T)) {
        std::cerr << "kdl_space_bench: " << c.name << ": a simulation failed\n";
        return false;
      }
      sim.ours_stats = ours.stats();
      sim.dense_stats = dense.stats();
      const double e = mismatch(sim.ours_end, sim.dense_end);
      (T == 1.0 ? sim.difference_1s : sim.difference) = e;
      std::cerr << "check " << c.name << " simulation of " << T << " s: " << sim.ours_stats.accepted_steps << " and "
                << sim.dense_stats.accepted_steps << " steps, end states differ by " << e << "\n";
      ok = ok && e <= (T == 1.0 ? 1e-9 : 1e-6) && sim.ours_stats.accepted_steps == sim.dense_stats.accepted_steps;
    }
  }
  return ok;
}

/// Samples per runStudy call of the study benchmarks.
constexpr std::uint64_t kStudyBatch = 4096;

/// The study of the benchmark's capture: the robot at its state, the 50 kg box of
/// ours_capture_end_to_end at the hand, tumbling at 0.05 to 0.2 rad/s about a random axis, its CoM
/// drifting at -0.05 to 0.05 m/s along x.
Study captureStudy(const Case& c) {
  Study st;
  st.file = "benchmark";
  st.samples = Study::max_samples;
  st.seed = 1;
  FloatingSystem& robot = st.scenario.capture.robot;
  robot.model = c.model;
  robot.state = c.state;
  robot.velocity = c.velocity;
  robot.contact = c.contact;
  Kinematics kin(*c.model);
  forwardKinematics(*c.model, c.state, kin);
  RigidTarget box;
  box.mass = 50.0;
  box.inertia = Matrix3d::Identity() * 2.0;
  box.pose = KDL::Frame(toKDL(Vector3d(kin.point(c.contact) + Vector3d(0.2, 0.1, -0.1))));
  st.scenario.capture.target = box;
  StudyInput tumble, drift;
  tumble.name = "target.tumble", tumble.field = StudyInput::Field::TargetTumble;
  tumble.distribution = {Distribution::Kind::Uniform, 0.05, 0.2, 0};
  drift.name = "target.twist.vx", drift.field = StudyInput::Field::TargetTwist, drift.index = 0;
  drift.distribution = {Distribution::Kind::Uniform, -0.05, 0.05, 0};
  st.inputs = {tumble, drift};
  return st;
}

/// Registers `name`: the forward dynamics of the case by `Solver` (ours or the dense route; they
/// differ in nothing else), alternating between the case's states.
template <class Solver>
void registerForwardDynamics(const std::string& name, const Case* cp) {
  benchmark::RegisterBenchmark(name.c_str(), [cp](benchmark::State& st) {
    Solver fd(cp->model);
    FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(cp->model->nj())};
    const std::vector<KDL::Wrench> none;
    std::size_t i = 0;
    for (auto _ : st) {
      fd.CartToJnt(cp->at(i++), cp->velocity, cp->tau, none, a);
      benchmark::DoNotOptimize(a.qddot.data.data());
    }
  });
}

void registerCase(const Case& c) {
  const std::string n = c.name;
  const Case* cp = &c;
  benchmark::RegisterBenchmark((n + "/ours_G_star").c_str(), [cp](benchmark::State& st) {
    RecursiveExIITSolver solver(cp->model);
    Matrix6d G;
    std::size_t i = 0;
    for (auto _ : st) {
      solver.compute(cp->at(i++));
      solver.G_star(cp->contact, G);
      benchmark::DoNotOptimize(G.data());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_J_star").c_str(), [cp](benchmark::State& st) {
    FreeFloatingSolver solver(cp->model);
    KDL::Jacobian J(cp->model->nj());
    std::size_t i = 0;
    for (auto _ : st) {
      solver.compute(cp->at(i++));
      solver.J_star(cp->contact, J);
      benchmark::DoNotOptimize(J.data.data());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_H_star").c_str(), [cp](benchmark::State& st) {
    FreeFloatingSolver solver(cp->model);
    std::size_t i = 0;
    for (auto _ : st) {
      solver.compute(cp->at(i++));
      benchmark::DoNotOptimize(solver.H_star().data.data());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_capture_state").c_str(), [cp](benchmark::State& st) {
    // The whole robot after grasping a 50 kg box: G*, the target's G_B, the capture impulse,
    // and the base and joint velocity jumps.
    RecursiveExIITSolver solver(cp->model);
    Matrix6d G;
    const Matrix6d G_B = rigidBodyG(50.0, Matrix3d::Identity() * 2.0, Vector3d(0.2, 0.1, -0.1));
    Vector6d t_h = Vector6d::Constant(0.01), t_c = Vector6d::Constant(-0.02), d_base;
    KDL::JntArray dqdot(cp->model->nj());
    std::size_t i = 0;
    for (auto _ : st) {
      solver.compute(cp->at(i++));
      solver.G_star(cp->contact, G);
      const Impulse imp = solveImpact(G, G_B, t_h, t_c, ImpactLaw{});
      solver.velocityJump(cp->contact, imp.F, d_base, dqdot);
      benchmark::DoNotOptimize(dqdot.data.data());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_capture_solve").c_str(), [cp](benchmark::State& st) {
    // The capture impulse alone, for a given G* and target (eq. 24): a 6x6 Cholesky solve.
    RecursiveExIITSolver solver(cp->model);
    Matrix6d G;
    solver.compute(cp->state);
    solver.G_star(cp->contact, G);
    const Matrix6d G_B = rigidBodyG(50.0, Matrix3d::Identity() * 2.0, Vector3d(0.2, 0.1, -0.1));
    Vector6d t_h = Vector6d::Constant(0.01);
    const Vector6d t_c = Vector6d::Constant(-0.02);
    for (auto _ : st) {
      benchmark::DoNotOptimize(t_h.data());
      const Impulse imp = solveImpact(G, G_B, t_h, t_c, ImpactLaw{});
      benchmark::DoNotOptimize(imp.F.data());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_capture_end_to_end").c_str(), [cp](benchmark::State& st) {
    // The library's capture path from a state, as a user calls it: the robot side (its
    // kinematics, momentum, energy and G* by the O(n) recursion), the target's side, the
    // capture impulse and the whole state after, of both (collide).
    // The side is built once (a set-up call, like loading the model) and reset to each state.
    const ImpactLaw capture{};
    std::size_t i = 0;
    FloatingSide robot(cp->model, cp->at(0), cp->contact, cp->velocity);
    for (auto _ : st) {
      robot.reset(cp->at(i++), cp->velocity);
      const RigidBody box{50.0, Matrix3d::Identity() * 2.0, robot.contactPoint() + Vector3d(0.2, 0.1, -0.1),
                          (Vector6d() << -0.02, 0.01, 0.0, 0.0, 0.01, 0.02).finished()};
      RigidBodySide target(box, robot.contactPoint());
      Impulse impulse;
      collide(robot, target, capture, impulse);
      benchmark::DoNotOptimize(robot.after().qdot.data.data());
      benchmark::DoNotOptimize(target.twistAfter().data());
    }
  });
  // The capture's stages one by one, each alone in its loop (what ours_capture_end_to_end spends
  // where): forward kinematics, the momentum sweep, the articulated-body pass, G* along the contact
  // path, the velocity jump of an impulse.
  benchmark::RegisterBenchmark((n + "/ours_stage_kinematics").c_str(), [cp](benchmark::State& st) {
    Kinematics kin(*cp->model);
    std::size_t i = 0;
    for (auto _ : st) {
      forwardKinematics(*cp->model, cp->at(i++), kin);
      benchmark::DoNotOptimize(kin.I_com.back().data());
    }
  });
  const auto stageKinematics = [cp] {
    std::vector<Kinematics> kin(2, Kinematics(*cp->model));
    for (std::size_t i = 0; i < 2; ++i) forwardKinematics(*cp->model, cp->at(i), kin[i]);
    return kin;
  };
  benchmark::RegisterBenchmark((n + "/ours_stage_momentum").c_str(), [cp, stageKinematics](benchmark::State& st) {
    const std::vector<Kinematics> kin = stageKinematics();
    MomentumSolver momentum(cp->model);
    std::size_t i = 0;
    for (auto _ : st) {
      momentum.compute(kin[i++ & 1], cp->velocity);
      benchmark::DoNotOptimize(momentum.kineticEnergy());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_stage_articulated_body").c_str(), [cp, stageKinematics](benchmark::State& st) {
    const std::vector<Kinematics> kin = stageKinematics();
    RecursiveExIITSolver solver(cp->model);
    std::size_t i = 0;
    for (auto _ : st) benchmark::DoNotOptimize(solver.compute(kin[i++ & 1]));
  });
  benchmark::RegisterBenchmark((n + "/ours_stage_G_path").c_str(), [cp](benchmark::State& st) {
    RecursiveExIITSolver solver(cp->model);
    solver.compute(cp->state);
    Matrix6d G;
    for (auto _ : st) {
      solver.G_star(cp->contact, G);
      benchmark::DoNotOptimize(G.data());
    }
  });
  benchmark::RegisterBenchmark((n + "/ours_stage_velocity_jump").c_str(), [cp](benchmark::State& st) {
    RecursiveExIITSolver solver(cp->model);
    solver.compute(cp->state);
    const Vector6d F = (Vector6d() << 3.0, -1.0, 2.0, 0.2, 0.1, -0.3).finished();
    Vector6d d_base;
    KDL::JntArray dqdot(cp->model->nj());
    for (auto _ : st) {
      solver.velocityJump(cp->contact, F, d_base, dqdot);
      benchmark::DoNotOptimize(dqdot.data.data());
    }
  });
  // A study of captures of this robot (the box of ours_capture_end_to_end tumbling about a random
  // axis, its speed drawn too): the time per sample, drawing and the whole row included, on one
  // core; and the wall time per sample of runStudy on 1 and 2 threads (chunks of 256).
  const auto study = std::make_shared<const Study>(captureStudy(*cp));
  benchmark::RegisterBenchmark((n + "/ours_study_sample").c_str(), [study](benchmark::State& st) {
    StudyEvaluator evaluator(study);
    std::vector<double> row(evaluator.columns());
    std::uint64_t i = 0;
    for (auto _ : st) {
      evaluator.evaluate(i++, row.data());
      benchmark::DoNotOptimize(row.data());
    }
  });
  for (const unsigned threads : {1u, 2u})
    benchmark::RegisterBenchmark((n + "/ours_study_" + std::to_string(threads) + "_threads_wall").c_str(),
                                 [study, threads](benchmark::State& st) {
                                   const std::vector<StudyChunk> chunks = studyChunks(0, kStudyBatch, 256);
                                   for (auto _ : st)
                                     runStudy(study, chunks, threads, [](const StudyChunk&, const std::vector<double>& rows) {
                                       benchmark::DoNotOptimize(rows.data());
                                     });
                                 })
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  // Forward dynamics: base and joint accelerations from state, velocity and torques, forward
  // kinematics included, by three routes (checked equal in checkRoutes()).
  registerForwardDynamics<ForwardDynamicsSolver>(n + "/ours_forward_dynamics", cp);
  registerForwardDynamics<test::CrbForwardDynamics>(n + "/crb_forward_dynamics", cp);
#ifdef KDL_SPACE_WITH_DART
  benchmark::RegisterBenchmark((n + "/DART_forward_dynamics").c_str(), [cp](benchmark::State& st) {
    DartRoute dart(*cp);
    if (!dart.skel) {
      st.SkipWithError("DART could not load the URDF");
      return;
    }
    std::size_t i = 0;
    for (auto _ : st) {
      dart.forwardDynamics(i++ & 1);
      benchmark::DoNotOptimize(dart.skel->getAccelerations().data());
    }
  });
#endif
  if (c.simulate) {
    // `kdl_space simulate` of 10 s from the case's state (free joints, dopri5, rtol 1e-10): the
    // Simulator, and its loop on the previous dense route. One call = the whole run.
    const SimulationCase* sc = &simulations().at(n);
    benchmark::RegisterBenchmark((n + "/ours_simulate_10s").c_str(), [cp, sc](benchmark::State& st) {
      Simulator sim(cp->model);
      SimulationState s = sc->start;
      for (auto _ : st) {
        reset(s, sc->start);
        sim.run(s, SimulationCase::kDuration, SimulationCase::kDuration, {});
        benchmark::DoNotOptimize(s.state.q.data.data());
      }
    })->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark((n + "/crb_simulate_10s").c_str(), [cp, sc](benchmark::State& st) {
      test::CrbSimulator sim(cp->model);
      SimulationState s = sc->start;
      for (auto _ : st) {
        reset(s, sc->start);
        sim.run(s, SimulationCase::kDuration);
        benchmark::DoNotOptimize(s.state.q.data.data());
      }
    })->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark((n + "/naive_KDL_G_star").c_str(), [cp](benchmark::State& st) {
    NaiveKdl naive(*cp);
    Matrix6d G;
    std::size_t i = 0;
    for (auto _ : st) {
      naive.G_star(G, i++);
      benchmark::DoNotOptimize(G.data());
    }
  });
#ifdef KDL_SPACE_WITH_DART
  benchmark::RegisterBenchmark((n + "/DART_G_star").c_str(), [cp](benchmark::State& st) {
    dart::utils::DartLoader::Options options;
    options.mDefaultRootJointType = dart::utils::DartLoader::RootJointType::FLOATING;
    options.mDefaultInertia = dart::dynamics::Inertia(0.0, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
    dart::utils::DartLoader loader(options);
    const dart::dynamics::SkeletonPtr skel = loader.parseSkeletonString(cp->urdf, "");
    if (!skel) {
      st.SkipWithError("DART could not load the URDF");
      return;
    }
    Eigen::VectorXd q[2] = {skel->getPositions(), skel->getPositions()};
    for (unsigned int j = 0; j < cp->model->nj(); ++j) {
      const auto* dof = skel->getDof(cp->model->jointNames()[j]);
      if (!dof) continue;
      q[0](dof->getIndexInSkeleton()) = cp->state.q(j);
      q[1](dof->getIndexInSkeleton()) = cp->other.q(j);
    }
    std::size_t i = 0;
    dart::dynamics::BodyNode* tip = skel->getBodyNode(cp->tip);
    const Eigen::Vector3d offset(cp->offset.x(), cp->offset.y(), cp->offset.z());
    Eigen::Matrix<double, 6, 6> G;
    for (auto _ : st) {
      skel->setPositions(q[i++ & 1]);  // DART skips its update when the positions do not change
      const dart::math::Jacobian J = skel->getWorldJacobian(tip, offset);
      G.noalias() = J * skel->getInvMassMatrix() * J.transpose();
      benchmark::DoNotOptimize(G.data());
    }
  });
#endif
}

/// Collects each benchmark's CPU time per iteration (the median when repetitions are asked for).
/// CPU time, not wall time: every call is single-threaded, and CPU time is what other processes
/// on a busy machine disturb least.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, double> ns;  // "case/method" -> ns per iteration
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      std::string name = r.benchmark_name();
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      if (r.run_type == Run::RT_Aggregate && !median) continue;
      if (median) name = name.substr(0, name.rfind('_'));
      if (r.run_type == Run::RT_Iteration && ns.count(name) && repetitions_) continue;
      // A study on several threads: wall time (the CPU time of the main thread is a share of it).
      const double t = name.find("_wall") != std::string::npos ? r.GetAdjustedRealTime() : r.GetAdjustedCPUTime();
      ns[name] = t * (r.time_unit == benchmark::kNanosecond ? 1.0
                                            : r.time_unit == benchmark::kMicrosecond ? 1e3
                                            : r.time_unit == benchmark::kMillisecond ? 1e6 : 1e9);
      if (median) repetitions_ = true;
    }
  }

 private:
  bool repetitions_ = false;
};

std::string fmt(double ns) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(ns < 1e4 ? 2 : 1);
  if (ns < 1e3) s << ns << " ns";
  else if (ns < 1e6) s << ns / 1e3 << " µs";
  else s << ns / 1e6 << " ms";
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::string model, tip, markdown, plan;
  KDL::Vector offset = KDL::Vector::Zero();
  std::vector<int> sizes{7, 14, 28, 50, 100}, simulate{7, 100};
  std::vector<int> mimic_sizes{10, 20, 30, 50, 100};  // the mimic section (mimic_bench.hpp); "" for none
  const auto list = [](const std::string& text) {
    std::vector<int> out;
    std::stringstream s(text);
    for (std::string n; std::getline(s, n, ',');) out.push_back(std::stoi(n));
    return out;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto need = [&](int k) {
      if (i + k >= argc) {
        std::cerr << "kdl_space_bench: " << a << " needs " << k << " value(s)\n";
        std::exit(2);
      }
    };
    if (a == "--model") need(1), model = argv[++i];
    else if (a == "--tip") need(1), tip = argv[++i];
    else if (a == "--markdown") need(1), markdown = argv[++i];
    else if (a == "--plan") need(1), plan = argv[++i];
    else if (a == "--offset") {
      need(3);
      offset = KDL::Vector(std::stod(argv[i + 1]), std::stod(argv[i + 2]), std::stod(argv[i + 3]));
      i += 3;
    } else if (a == "--sizes") {
      need(1);
      sizes = list(argv[++i]);
    } else if (a == "--mimic-sizes") {
      need(1);
      mimic_sizes = list(argv[++i]);
    } else if (a == "--simulate") {
      need(1);
      simulate = list(argv[++i]);
    } else {
      std::cerr << "kdl_space_bench: unknown argument " << a << "\n";
      return 2;
    }
  }
  if (!plan.empty()) {  // the plan alone (plan_bench.hpp)
    try {
      bench::registerPlan(plan);
    } catch (const Error& e) {
      std::cerr << "kdl_space_bench: " << e.what() << "\n";
      return 3;
    }
    benchmark::RunSpecifiedBenchmarks();
    return 0;
  }
  try {
    if (!model.empty()) {
      if (tip.empty()) {
        std::cerr << "kdl_space_bench: --model needs --tip\n";
        return 2;
      }
      std::ifstream in(model);
      if (!in) {
        std::cerr << "kdl_space_bench: cannot open " << model << "\n";
        return 3;
      }
      std::stringstream text;
      text << in.rdbuf();
      cases().push_back(makeCase(model, text.str(), tip, offset));
    } else {
      cases().reserve(sizes.size());
      for (int n : sizes) {
        cases().push_back(makeCase("N=" + std::to_string(n), bench::generatedChainUrdf(n), "tip", offset));
        cases().back().simulate = std::find(simulate.begin(), simulate.end(), n) != simulate.end();
      }
    }
    if (model.empty())
      for (bool grippers : {false, true})
        for (int n : mimic_sizes) bench::mimicCases().push_back(bench::makeMimicCase(n, grippers));
  } catch (const ModelError& e) {
    std::cerr << "kdl_space_bench: " << e.what() << "\n";
    return 3;
  }
  if (!checkRoutes() || !bench::checkMimicRoutes()) {
    std::cerr << "kdl_space_bench: the routes disagree: not timing them\n";
    return 4;
  }
  for (const Case& c : cases()) registerCase(c);
  for (const bench::MimicCase& c : bench::mimicCases()) bench::registerMimicCase(c);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  // Side-by-side table: median time per call and the ratio to our G*.
  const std::vector<std::string> methods{"ours_G_star",          "ours_J_star",           "ours_H_star",
                                         "ours_capture_state",   "ours_capture_end_to_end", "ours_capture_solve",
                                         "ours_forward_dynamics", "crb_forward_dynamics",  "naive_KDL_G_star",
                                         "DART_G_star",          "DART_forward_dynamics"};
  const auto time = [&](const std::string& c, const std::string& m) {
    const auto it = reporter.ns.find(c + "/" + m);
    return it == reporter.ns.end() ? -1.0 : it->second;
  };
  const auto cell = [&](double ns) { return ns < 0.0 ? std::string("–") : fmt(ns); };
  const auto ratio = [](double a, double b) {
    std::ostringstream r;
    if (a < 0.0 || b < 0.0) return std::string("–");
    r << std::setprecision(3) << a / b << "×";
    return r.str();
  };
  std::ostringstream table;
  table << "| model | method | CPU time per call | ratio to our G* |\n|---|---|---|---|\n";
  for (const Case& c : cases())
    for (const std::string& m : methods) {
      const double t = time(c.name, m), ours = time(c.name, "ours_G_star");
      if (t < 0.0 || ours < 0.0) continue;
      table << "| " << c.name << " (" << c.model->nj() << " joints) | " << m << " | " << fmt(t) << " | "
            << ratio(t, ours) << " |\n";
    }
  const auto growth = [&](const std::string& m) {
    const double t50 = time("N=50", m), t100 = time("N=100", m);
    std::ostringstream g;
    if (t50 > 0.0 && t100 > 0.0) g << std::setprecision(3) << t100 / t50;
    return g.str();
  };
  if (!growth("ours_G_star").empty()) table << "\nGrowth of our G*: t(100) / t(50) = " << growth("ours_G_star") << "\n";

  // Forward dynamics, the three routes side by side.
  table << "\n### Forward dynamics (state, velocities and torques to base and joint accelerations)\n\n"
        << "| model | ours (articulated body, O(n)) | previous dense route (CRB) | DART | dense / ours | DART / ours |\n"
        << "|---|---|---|---|---|---|\n";
  for (const Case& c : cases()) {
    const double ours = time(c.name, "ours_forward_dynamics"), crb = time(c.name, "crb_forward_dynamics"),
                 dart = time(c.name, "DART_forward_dynamics");
    if (ours < 0.0) continue;
    table << "| " << c.name << " (" << c.model->nj() << " joints) | " << cell(ours) << " | " << cell(crb) << " | "
          << cell(dart) << " | " << ratio(crb, ours) << " | " << ratio(dart, ours) << " |\n";
  }
  if (!growth("ours_forward_dynamics").empty())
    table << "\nGrowth t(100) / t(50): ours " << growth("ours_forward_dynamics") << ", previous dense route "
          << growth("crb_forward_dynamics") << (growth("DART_forward_dynamics").empty() ? "" : ", DART ")
          << growth("DART_forward_dynamics") << "\n";

  // The capture path end to end, and its stages each timed alone.
  const std::vector<std::string> stages{"ours_stage_kinematics", "ours_stage_momentum", "ours_stage_articulated_body",
                                        "ours_stage_G_path", "ours_stage_velocity_jump"};
  table << "\n### Capture end to end (state to G*, impulse and the whole state after; FloatingSide + "
           "RigidBodySide + collide)\n\nIts stages, each timed alone: forward kinematics, the momentum sweep, the "
           "articulated-body pass, G* along the contact path, the velocity jump. The rest (the impulse, the "
           "target's side, the bookkeeping of the state after) is the difference, as noisy as the six medians it "
           "is made of.\n\n"
           "| model | CPU time per call | kinematics | momentum | articulated body | G* path | velocity jump | the rest |\n"
           "|---|---|---|---|---|---|---|---|\n";
  for (const Case& c : cases()) {
    const double whole = time(c.name, "ours_capture_end_to_end");
    if (whole < 0.0) continue;
    table << "| " << c.name << " (" << c.model->nj() << " joints) | " << fmt(whole);
    double rest = whole;
    for (const std::string& m : stages) {
      const double t = time(c.name, m);
      table << " | " << cell(t);
      rest = t < 0.0 || rest < 0.0 ? -1.0 : rest - t;
    }
    table << " | " << cell(rest) << " |\n";
  }

  // Studies.
  table << "\n### Capture studies (per sample: the draws, the capture and the row; a study of the box above "
           "tumbling about a random axis)\n\n| model | one sample, one core | / capture end to end | runStudy 1 thread "
           "(wall, per sample) | 2 threads | captures per second on 2 threads | scaling |\n|---|---|---|---|---|---|---|\n";
  for (const Case& c : cases()) {
    const double one = time(c.name, "ours_study_sample"), capture = time(c.name, "ours_capture_end_to_end");
    const double t1 = time(c.name, "ours_study_1_threads_wall/real_time") / kStudyBatch,
                 t2 = time(c.name, "ours_study_2_threads_wall/real_time") / kStudyBatch;
    if (one < 0.0 || t1 < 0.0 || t2 < 0.0) continue;
    std::ostringstream rate;
    rate << std::fixed << std::setprecision(0) << 1e9 / t2;
    table << "| " << c.name << " (" << c.model->nj() << " joints) | " << fmt(one) << " | " << ratio(one, capture)
          << " | " << fmt(t1) << " | " << fmt(t2) << " | " << rate.str() << " | " << ratio(t1, t2) << " |\n";
  }

  // The simulations.
  if (!simulations().empty()) {
    table << "\n### Simulation: " << SimulationCase::kDuration
          << " s, dopri5, rtol 1e-10, free joints (as `kdl_space simulate`)\n\n"
          << "| model | ours (Simulator) | the same loop on the dense route | dense / ours | steps accepted (rejected) |"
             " end states differ by (after 1 s / 10 s) |\n|---|---|---|---|---|---|\n";
    for (const Case& c : cases()) {
      const auto it = simulations().find(c.name);
      if (it == simulations().end()) continue;
      const double ours = time(c.name, "ours_simulate_10s"), dense = time(c.name, "crb_simulate_10s");
      std::ostringstream diff;
      diff << std::setprecision(2) << it->second.difference_1s << " / " << it->second.difference;
      table << "| " << c.name << " (" << c.model->nj() << " joints) | " << cell(ours) << " | " << cell(dense) << " | "
            << ratio(dense, ours) << " | " << it->second.ours_stats.accepted_steps << " ("
            << it->second.ours_stats.rejected_steps << ") | " << diff.str() << " |\n";
    }
  }
  table << bench::mimicTable(time, fmt);
  std::cout << "\n" << table.str();
  if (!markdown.empty()) {
    std::ofstream md(markdown);
    md << table.str();
  }
  return 0;
}
