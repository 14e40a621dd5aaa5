// kdl_space_bench: times our G*, J*, H*, the full post-impact state of a capture and forward
// dynamics side by side with the naive KDL route (six virtual base joints + ChainDynParam +
// ChainJntToJacSolver + an Eigen factorisation) and, when built with DART, DART's J M^-1 J^T on
// the same URDF with a free root joint. Prints the ratios; --markdown FILE writes the table.
//
//   kdl_space_bench [--model FILE.urdf --tip LINK [--offset X Y Z]] [--sizes 7,14,...]
//                   [--markdown FILE] [Google Benchmark flags, e.g. --benchmark_repetitions=5]
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <map>
#include <random>
#include <sstream>

#include "generated_chain.hpp"
#include "kdl_space/collision.hpp"
#include "kdl_space/forward_dynamics.hpp"
#include "kdl_space/recursive_ex_iit.hpp"
#include "kdl_space/urdf_loader.hpp"

#ifdef KDL_SPACE_WITH_DART
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/DegreeOfFreedom.hpp>
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
  const State& at(std::size_t i) const { return i & 1 ? other : state; }
};

Case makeCase(const std::string& name, const std::string& urdf, const std::string& tip, const KDL::Vector& offset) {
  Case c{name, urdf, tip, offset, std::make_shared<const FloatingModel>(loadUrdfString(urdf, name)), {}, {}, {}};
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
  benchmark::RegisterBenchmark((n + "/ours_forward_dynamics").c_str(), [cp](benchmark::State& st) {
    ForwardDynamicsSolver fd(cp->model);
    FloatingVelocity v{KDL::Twist(KDL::Vector(0.01, 0, 0), KDL::Vector(0, 0.02, 0)), KDL::JntArray(cp->model->nj())};
    v.qdot.data.setConstant(0.1);
    KDL::JntArray tau(cp->model->nj());
    FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(cp->model->nj())};
    const std::vector<KDL::Wrench> none;
    std::size_t i = 0;
    for (auto _ : st) {
      fd.CartToJnt(cp->at(i++), v, tau, none, a);
      benchmark::DoNotOptimize(a.qddot.data.data());
    }
  });
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
      ns[name] = r.GetAdjustedCPUTime() * (r.time_unit == benchmark::kNanosecond ? 1.0
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
  std::string model, tip, markdown;
  KDL::Vector offset = KDL::Vector::Zero();
  std::vector<int> sizes{7, 14, 28, 50, 100};
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
    else if (a == "--offset") {
      need(3);
      offset = KDL::Vector(std::stod(argv[i + 1]), std::stod(argv[i + 2]), std::stod(argv[i + 3]));
      i += 3;
    } else if (a == "--sizes") {
      need(1);
      sizes.clear();
      std::stringstream s(argv[++i]);
      for (std::string n; std::getline(s, n, ',');) sizes.push_back(std::stoi(n));
    } else {
      std::cerr << "kdl_space_bench: unknown argument " << a << "\n";
      return 2;
    }
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
      for (int n : sizes) cases().push_back(makeCase("N=" + std::to_string(n), bench::generatedChainUrdf(n), "tip", offset));
    }
  } catch (const ModelError& e) {
    std::cerr << "kdl_space_bench: " << e.what() << "\n";
    return 3;
  }
  for (const Case& c : cases()) registerCase(c);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  // Side-by-side table: median time per call and the ratio to our G*.
  const std::vector<std::string> methods{"ours_G_star", "ours_J_star", "ours_H_star", "ours_capture_state",
                                         "ours_capture_solve", "ours_forward_dynamics", "naive_KDL_G_star", "DART_G_star"};
  std::ostringstream table;
  table << "| model | method | CPU time per call | ratio to our G* |\n|---|---|---|---|\n";
  for (const Case& c : cases()) {
    const auto ours = reporter.ns.find(c.name + "/ours_G_star");
    for (const std::string& m : methods) {
      const auto it = reporter.ns.find(c.name + "/" + m);
      if (it == reporter.ns.end() || ours == reporter.ns.end()) continue;
      table << "| " << c.name << " (" << c.model->nj() << " joints) | " << m << " | " << fmt(it->second) << " | "
            << std::setprecision(3) << it->second / ours->second << "× |\n";
    }
  }
  if (sizes.size() > 1 && model.empty()) {
    const auto t50 = reporter.ns.find("N=50/ours_G_star"), t100 = reporter.ns.find("N=100/ours_G_star");
    if (t50 != reporter.ns.end() && t100 != reporter.ns.end())
      table << "\nGrowth of our G*: t(100) / t(50) = " << std::setprecision(3) << t100->second / t50->second << "\n";
  }
  std::cout << "\n" << table.str();
  if (!markdown.empty()) {
    std::ofstream md(markdown);
    md << table.str();
  }
  return 0;
}
