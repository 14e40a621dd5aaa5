// Every compute call of every solver allocates nothing on the heap after construction.
// Counting: this executable replaces operator new/delete and interposes malloc, calloc, realloc,
// posix_memalign, aligned_alloc and memalign (glibc's __libc_* do the work), so allocations made
// inside libkdl_space, KDL and Eigen are all seen. EIGEN_RUNTIME_NO_MALLOC also arms Eigen's own
// check for the Eigen code compiled in this file (active when assertions are).
// Not built under the sanitizers (tests/CMakeLists.txt): they replace the allocator, and what this
// proves is the optimized build's; the other suites run the same calls there for memory errors.
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <new>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "kdl_space/simulation/sampled_control.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "simulation/rosenbrock.hpp"
#include "generated_chain.hpp"
#include "test_util.hpp"

namespace {
// volatile: malloc and free are builtins that the compiler knows read no global, so it could drop
// the stores to a plain flag around an inlined malloc/free pair.
volatile long g_allocations = 0;
volatile bool g_counting = false;
inline void count() {
  if (g_counting) ++g_allocations;
}
}  // namespace

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

extern "C" {
void* malloc(size_t n) {
  count();
  return __libc_malloc(n);
}
void* calloc(size_t k, size_t n) {
  count();
  return __libc_calloc(k, n);
}
void* realloc(void* p, size_t n) {
  count();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
int posix_memalign(void** p, size_t alignment, size_t n) {
  count();
  *p = __libc_memalign(alignment, n);
  return *p ? 0 : ENOMEM;
}
void* aligned_alloc(size_t alignment, size_t n) {
  count();
  return __libc_memalign(alignment, n);
}
void* memalign(size_t alignment, size_t n) {
  count();
  return __libc_memalign(alignment, n);
}
}

void* operator new(std::size_t n) {
  count();
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  count();
  if (void* p = __libc_memalign(static_cast<size_t>(a), n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }

namespace kdl_space::test {
namespace {

/// Heap allocations made while `f` runs (Eigen's own check armed too).
template <typename F>
long allocationsDuring(F&& f) {
  g_allocations = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  g_counting = true;
  f();
  g_counting = false;
  Eigen::internal::set_is_malloc_allowed(true);
  return g_allocations;
}

TEST(NoAllocation, TheCounterSeesAllocations) {
  // The counting can fail: an allocation in this file, and one inside a library (KDL).
  EXPECT_GE(allocationsDuring([] { int* volatile p = new int(3); delete p; }), 1);  // volatile: clang elides `delete new`
  EXPECT_GE(allocationsDuring([] { KDL::JntArray q(7); }), 1);
  EXPECT_GE(allocationsDuring([] { void* volatile p = std::malloc(16); std::free(p); }), 1);
}

TEST(NoAllocation, RosenbrockStep) {
  // The stiff integrator's step (Jacobian, LU of the iteration matrix, four stages) and its
  // spectral radius estimate, at sizes below and above Eigen's blocked LU (a simulator state of a
  // 7-joint arm has 27 numbers, of a 50-link chain 113).
  for (int n : {1, 27, 113}) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n) - 5.0 * Eigen::MatrixXd::Identity(n, n);
    // A nonlinear, non-autonomous f written without temporaries: dx = A x - x^3 / 10 + sin t.
    const detail::RosenbrockStepper::Rhs f = [&A](double t, const Eigen::VectorXd& x, Eigen::VectorXd& dx) {
      dx.noalias() = A * x;
      dx.array() -= 0.1 * x.array().cube();
      dx.array() += std::sin(t);
      return 0;
    };
    detail::RosenbrockStepper stepper(n);
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0), x_new(n);
    double error = 0.0, radius = 0.0;
    ASSERT_EQ(stepper.step(f, 0.0, 0.01, x, x_new, error, 1e-6, 1e-9), E_NOERROR);  // warm-up
    EXPECT_EQ(allocationsDuring([&] {
                for (int k = 0; k < 3; ++k) {
                  EXPECT_EQ(stepper.step(f, 0.01 * k, 0.01, x, x_new, error, 1e-6, 1e-9), E_NOERROR);
                  x = x_new;  // same size: a copy, no allocation
                }
                radius = stepper.spectralRadiusEstimate();
              }),
              0)
        << "n = " << n;
    EXPECT_GT(radius, 0.0);
  }
}

class EveryComputeCall : public ::testing::TestWithParam<std::string> {};

/// A bundled model, or "chainN": a generated N-link chain (large n exercises Eigen's blocked paths),
/// or a generated humanoid with mimic finger joints, N movable joints: "handsN" (a third of them
/// mimic) or "grippersN" (four mimic).
std::shared_ptr<const FloatingModel> load(const std::string& name) {
  if (name.rfind("chain", 0) == 0)
    return std::make_shared<const FloatingModel>(loadUrdfString(bench::generatedChainUrdf(std::stoi(name.substr(5))), name));
  for (const auto& [prefix, urdf] : {std::pair{std::string("hands"), &bench::generatedHandsUrdf},
                                     std::pair{std::string("grippers"), &bench::generatedGrippersUrdf}})
    if (name.rfind(prefix, 0) == 0) {
      auto model = std::make_shared<const FloatingModel>(loadUrdfString(urdf(std::stoi(name.substr(prefix.size()))), name));
      if (model->mimic().empty()) ADD_FAILURE() << name << ": no mimic joints, nothing of mimic_coupling.hpp is run";
      return model;
    }
  return std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/" + name));
}

TEST_P(EveryComputeCall, AllocatesNothing) {
  const auto model = load(GetParam());
  const unsigned int n = model->nj();
  std::mt19937 rng(5);
  const State state = randomState(*model, rng), other = randomState(*model, rng);
  const Contact h = model->contact(model->bodies().back().name, KDL::Vector(0.05, -0.02, 0.1));
  const Contact h2 = model->contact(model->bodies()[model->bodies().size() / 2].name);
  const std::vector<Contact> contacts{h, h2};

  // Everything constructed (and warmed up once) before counting.
  FreeFloatingSolver solver(model);
  RecursiveExIITSolver recursive(model);
  ForwardDynamicsSolver fd(model);
  fd.setGravity(Vector3d(0, 0, -9.81));
  ForwardDynamicsSolver locked_fd(model);
  std::vector<bool> locked(n, false);
  locked[n / 2] = true;
  locked_fd.setLocked(locked);
  // The impact solvers with braked joints (set up before counting).
  FreeFloatingSolver locked_solver(model);
  RecursiveExIITSolver locked_recursive(model);
  locked_solver.setLocked(locked);
  locked_recursive.setLocked(locked);
  Kinematics kin(*model);
  MomentumSolver momentum(model);
  KDL::JntArray qdot(n), tau(n), dqdot(n);
  for (unsigned int j = 0; j < n; ++j) qdot(j) = 0.1 * j, tau(j) = 0.5 - 0.1 * j;
  const KDL::Twist base_twist(KDL::Vector(0.01, 0.02, -0.01), KDL::Vector(0.03, -0.01, 0.02));
  KDL::Jacobian J(n);
  Matrix6d G;
  Eigen::MatrixXd G_all(12, 12);
  Vector6d PL, dPL, d_base, F;
  F << 1, -2, 0.5, 0.1, 0.2, -0.3;
  Vector3d p;
  KDL::Twist t;
  double T = 0.0;
  FloatingVelocity v{base_twist, qdot};
  FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(n)};
  const std::vector<KDL::Wrench> no_wrenches, wrenches(model->bodies().size(), KDL::Wrench(KDL::Vector(1, 0, 0), KDL::Vector(0, 0.1, 0)));
  ASSERT_EQ(solver.compute(state), E_NOERROR);
  ASSERT_EQ(recursive.compute(state), E_NOERROR);
  const RigidBody box{50.0, Matrix3d::Identity() * 2.0, Vector3d(1.0, 0.5, 0.2), Vector6d::Constant(0.01)};
  Vector3d p_h;
  solver.contactPoint(h, p_h);
  FloatingSide robot(solver.sharedModel(), solver.state(), h, v);
  FloatingSide robot_dense(solver.sharedModel(), solver.state(), h, v, Response::FreeFloating, ExIITMethod::Dense);
  FloatingSide robot_grounded(solver.sharedModel(), solver.state(), h, v, Response::Grounded);
  FloatingSide robot_locked(solver.sharedModel(), solver.state(), h, v, Response::JointsLocked);
  FloatingVelocity braked_v = v;
  for (unsigned int j = 0; j < n; ++j)
    if (locked[j]) braked_v.qdot(j) = 0.0;  // a braked joint does not move
  FloatingSide robot_braked(solver.sharedModel(), solver.state(), h, braked_v, Response::FreeFloating,
                            ExIITMethod::Recursive, locked);
  FloatingSide robot_braked_dense(solver.sharedModel(), solver.state(), h, braked_v, Response::Grounded,
                                  ExIITMethod::Dense, locked);
  RigidBodySide target(box, p_h);
  const Matrix6d G_B = target.G();

  // Each call twice: the first may not allocate either (everything is sized at construction),
  // the second proves it. A failure names the call.
#define NO_ALLOCATION(call)                                                                  \
  do {                                                                                       \
    call;                                                                                    \
    EXPECT_EQ(allocationsDuring([&] { call; }), 0) << "allocates: " #call;                  \
  } while (false)
  for (const State* s : {&state, &other}) {
    NO_ALLOCATION(EXPECT_EQ(solver.compute(*s), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(recursive.compute(*s), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(forwardKinematics(*model, *s, kin), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(solver.compute(kin), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(recursive.compute(kin), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(momentum.compute(kin, v), E_NOERROR));
  }
  NO_ALLOCATION(EXPECT_EQ(momentum.contactTwist(h, PL), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(momentum.G_locked(h, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(momentum.baseTwist(kin, momentum.momentum(), qdot, t), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.momentum(base_twist, qdot, PL), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.baseTwist(PL, qdot, t), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.kineticEnergy(base_twist, qdot, T), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.contactPoint(h, p), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.R_h(h, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.J(h, J), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.J_star(h, J), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.G_star(h, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.G_grounded(h, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.G_locked(h, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.handTwist(h, qdot, PL, t), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(solver.G_star(contacts, G_all), E_NOERROR));
  for (Response r : {Response::FreeFloating, Response::Grounded, Response::JointsLocked}) {
    NO_ALLOCATION(EXPECT_EQ(solver.G(h, r, G), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(solver.velocityJump(h, r, F, dPL, dqdot), E_NOERROR));
  }
  NO_ALLOCATION(EXPECT_EQ(recursive.G_star(h, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(recursive.velocityJump(h, F, d_base, dqdot), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(recursive.G(h, Response::Grounded, G), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(recursive.velocityJump(h, Response::Grounded, F, d_base, dqdot), E_NOERROR));
  for (const State* s : {&state, &other}) {
    NO_ALLOCATION(EXPECT_EQ(locked_solver.compute(*s), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(locked_recursive.compute(*s), E_NOERROR));
  }
  NO_ALLOCATION(EXPECT_EQ(locked_solver.G_star(contacts, G_all), E_NOERROR));
  for (Response r : {Response::FreeFloating, Response::Grounded}) {
    NO_ALLOCATION(EXPECT_EQ(locked_solver.G(h, r, G), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(locked_solver.velocityJump(h, r, F, dPL, dqdot), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(locked_recursive.G(h, r, G), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(locked_recursive.velocityJump(h, r, F, d_base, dqdot), E_NOERROR));
  }
  NO_ALLOCATION(EXPECT_EQ(fd.CartToJnt(state, v, tau, no_wrenches, a), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(fd.CartToJnt(other, v, tau, wrenches, a), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(forwardKinematics(*model, other, kin), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(fd.CartToJnt(kin, v, tau, wrenches, a), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(locked_fd.CartToJnt(kin, v, tau, no_wrenches, a), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(momentum.compute(kin, v), E_NOERROR));
  NO_ALLOCATION(EXPECT_EQ(momentum.baseTwist(kin, momentum.momentum(), qdot, t), E_NOERROR));
  NO_ALLOCATION(G = rigidBodyG(20.0, Matrix3d::Identity(), Vector3d(0.1, 0.2, 0.3)));
  NO_ALLOCATION(EXPECT_GT(spectralFigures(G).rank, 0));
  NO_ALLOCATION(EXPECT_GT(virtualMass(G, Vector3d::UnitX()), 0.0));
  for (ImpactKind kind : {ImpactKind::Capture, ImpactKind::PointImpact, ImpactKind::FrictionalImpact,
                          ImpactKind::TranslationalCapture}) {
    const ImpactLaw law{kind, Vector3d(0.6, 0.0, 0.8), 0.5, 0.4};
    Impulse impulse;
    NO_ALLOCATION(impulse = solveImpact(robot.G(), G_B, robot.contactTwistBefore(), target.contactTwistBefore(), law));
    EXPECT_TRUE(impulse.F.allFinite());
    for (FloatingSide* side : {&robot, &robot_dense, &robot_grounded, &robot_locked}) {
      NO_ALLOCATION(EXPECT_EQ(side->reset(other, v), E_NOERROR));
      NO_ALLOCATION(EXPECT_EQ(side->reset(state, v), E_NOERROR));
    }
    for (FloatingSide* side : {&robot_braked, &robot_braked_dense}) {
      NO_ALLOCATION(EXPECT_EQ(side->reset(other, braked_v), E_NOERROR));
      NO_ALLOCATION(EXPECT_EQ(side->reset(state, braked_v), E_NOERROR));
    }
    for (FloatingSide* side : {&robot, &robot_dense, &robot_grounded, &robot_locked, &robot_braked, &robot_braked_dense})
      NO_ALLOCATION(EXPECT_EQ(side->applyImpulse(impulse.F), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(target.applyImpulse(-impulse.F), E_NOERROR));
    NO_ALLOCATION(EXPECT_EQ(collide(robot, target, law, impulse), E_NOERROR));
  }
#undef NO_ALLOCATION
}

TEST_P(EveryComputeCall, SimulatorRunAllocatesNothing) {
  const auto model = load(GetParam());
  std::mt19937 rng(6);
  for (bool grounded : {false, true})
    for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54, Integrator::Rosenbrock}) {
      SCOPED_TRACE(std::string(grounded ? "grounded, " : "free, ") + std::to_string(static_cast<int>(integrator)));
      SimulationOptions options;
      options.integrator = integrator;
      // RK4's fixed step: under the callback's damping c = 0.1 N m s, stable for h < 2.785 lambda / c,
      // lambda the least eigenvalue of H; the generated fingers' lambda, down to 1.1e-4 kg m^2 (grippers14,
      // hands12, hands24 at random states) asks for h < 3.1e-3 s (at 0.01 s grippers14 and hands24
      // end in E_NOT_FINITE).
      options.step = model->mimic().empty() ? 0.01 : 1e-3;
      options.grounded = grounded;
      Simulator sim(model, options);
      JointControl hold{JointControl::Mode::PD, 10.0, 5.0, 0.2};
      hold.hold = true;
      sim.setJointControl(0, hold);
      if (model->nj() > 2) sim.setJointControl(1, {JointControl::Mode::Locked});
      sim.setTorqueCallback([](const SimulationState& s, KDL::JntArray& tau) { tau.data = -0.1 * s.velocity.qdot.data; });
      if (!grounded) {  // the base's own control and a thruster firing inside the counted run
        BaseControl c;
        c.attitude.on = c.attitude.hold = c.position.on = c.position.hold = true;
        c.attitude.kp = c.attitude.kd = c.position.kp = c.position.kd = 1.0;
        c.attitude.torque_limit = Vector3d::Constant(0.5);
        sim.setBaseControl(c);
      }
      ScheduledWrench w;
      w.body = static_cast<unsigned int>(model->bodies().size() - 1);
      w.wrench << 1.0, 0.0, 0.0, 0.0, 0.0, 0.1;
      w.start = 0.1;
      w.end = 0.2;
      sim.addWrench(w);
      SimulationState s;
      s.state = randomState(*model, rng);
      s.velocity.qdot = KDL::JntArray(model->nj());
      ASSERT_EQ(sim.engageBrakes(s), E_NOERROR);  // a set-up call, outside the count
      sim.setCancelPoll([] { return false; });  // polled before every step: allocates nothing either
      const auto observer = [&](const SimulationState& x) { EXPECT_TRUE(x.state.q.data.allFinite()); };
      const std::function<void(const SimulationState&)> watch = observer;  // constructed before counting
      ASSERT_EQ(sim.run(s, 0.05, 0.01, watch), E_NOERROR);                  // warm-up
      EXPECT_EQ(allocationsDuring([&] { EXPECT_EQ(sim.run(s, s.t + 0.2, 0.05, watch), E_NOERROR); }), 0);
    }
}

TEST_P(EveryComputeCall, SimulatorStopEventAllocatesNothing) {
  // The stop event located inside a step (retaken steps, the Illinois iterations): nothing allocated.
  const auto model = load(GetParam());
  std::mt19937 rng(8);
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54, Integrator::Rosenbrock}) {
    SCOPED_TRACE(static_cast<int>(integrator));
    SimulationOptions options;
    options.integrator = integrator;
    options.step = 0.01;
    Simulator sim(model, options);
    sim.setJointControl(0, JointControl{JointControl::Mode::PD, 10.0, 5.0, 0.2});
    SimulationState s;
    s.state = randomState(*model, rng);
    s.velocity.qdot = KDL::JntArray(model->nj());
    const std::function<void(const SimulationState&)> watch = [](const SimulationState&) {};
    // Crossed at 0.0334 s, between the outputs; not linear in time (several iterations).
    sim.setStopEvent([](const SimulationState& x) { return std::cos(50.0 * x.t) - std::cos(1.67); });
    SimulationState warm = s;
    ASSERT_EQ(sim.run(warm, 0.5, 0.01, watch), E_NOERROR);  // warm-up
    EXPECT_EQ(allocationsDuring([&] { EXPECT_EQ(sim.run(warm, 0.5, 0.01, nullptr), E_NOERROR); }), 0) << "at the start";
    EXPECT_EQ(warm.t, sim.stats().event_time);
    s.tau = warm.tau;  // run() sizes its output once
    EXPECT_EQ(allocationsDuring([&] { EXPECT_EQ(sim.run(s, 0.5, 0.01, watch), E_NOERROR); }), 0);
    EXPECT_NEAR(sim.stats().event_time, 0.0334, 1e-9);
  }
}

TEST_P(EveryComputeCall, SampledControllerCallsAllocateNothing) {
  // runSampled sets itself up (its callbacks, the controller's torque) once per run: a run with ten
  // times as many controller calls allocates no more.
  const auto model = load(GetParam());
  std::mt19937 rng(7);
  SimulationOptions options;
  options.integrator = Integrator::RK4;
  options.step = 0.005;
  Simulator sim(model, options);
  SimulationState start;
  start.state = randomState(*model, rng);
  start.velocity.qdot = KDL::JntArray(model->nj());
  const SampledController controller = [](const SimulationState& s, Eigen::VectorXd& tau) {
    tau = -0.1 * s.velocity.qdot.data;
  };
  const std::function<void(const SimulationState&)> watch = [](const SimulationState&) {};
  SimulationState s = start;
  ASSERT_EQ(runSampled(sim, s, 0.02, 0.01, controller, 200.0, watch), E_NOERROR);  // warm-up
  const auto allocations = [&](double duration) {
    SimulationState x = start;
    return allocationsDuring([&] { EXPECT_EQ(runSampled(sim, x, duration, 0.01, controller, 200.0, watch), E_NOERROR); });
  };
  EXPECT_EQ(allocations(0.2), allocations(0.02)) << "40 controller calls against 4";
}

INSTANTIATE_TEST_SUITE_P(Models, EveryComputeCall,
                         ::testing::Values("space_arm7.urdf", "dual_arm.urdf", "chain50", "chain100"));
// Mimic joints: RecursiveExIITSolver's and ForwardDynamicsSolver's compute run the couplings'
// constraint passes (src/algorithm/mimic_coupling.hpp: k x k Cholesky, 6 x k blocks per body) and
// Simulator::run runs them at every derivative; k = 4 (grippers14, hands12: 6 x 4 blocks, Eigen's
// coefficient-based products) and k = 8 (hands24: 6 x 6 by 6 x 8, Eigen's blocked product, taken
// from 6 + 6 + k = 20 on).
INSTANTIATE_TEST_SUITE_P(MimicModels, EveryComputeCall, ::testing::Values("grippers14", "hands12", "hands24"));

}  // namespace
}  // namespace kdl_space::test
