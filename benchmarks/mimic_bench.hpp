// kdl_space_bench's mimic section (issue 28): G* and forward dynamics of a humanoid's upper body
// whose fingers are coupled (generatedHandsUrdf: a third of the joints are mimic joints;
// generatedGrippersUrdf: two two-finger grippers, four mimic joints at every size), by the
// O(n) recursions with the couplings as constraints against the dense route (T^T H T, O(n^3)),
// side by side in one run. Checked equal to 1e-9 before timing.
#pragma once

#include <benchmark/benchmark.h>

#include <iomanip>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "generated_chain.hpp"
#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

namespace kdl_space::bench {

struct MimicCase {
  std::string name;  ///< "hands N=..." or "grippers N=..." (N: movable joints of the URDF, mimic ones included)
  std::shared_ptr<const FloatingModel> model;
  State state[2];    ///< calls alternate between two configurations
  Contact contact;
  FloatingVelocity velocity;
  KDL::JntArray tau;
};

inline std::vector<MimicCase>& mimicCases() {
  static std::vector<MimicCase> all;
  return all;
}

/// \param grippers the "grippers" family (k = 4 mimic joints at every N), else the "hands" one
/// (k = N / 3).
inline MimicCase makeMimicCase(int N, bool grippers = false) {
  MimicCase c;
  c.name = (grippers ? "grippers N=" : "hands N=") + std::to_string(N);
  c.model = std::make_shared<const FloatingModel>(
      loadUrdfString(grippers ? generatedGrippersUrdf(N) : generatedHandsUrdf(N), c.name));
  const unsigned int n = c.model->nj();
  for (int k = 0; k < 2; ++k) {
    c.state[k] = State(*c.model);
    c.state[k].world_T_base = KDL::Frame(KDL::Rotation::RPY(0.1, -0.2, 0.3), KDL::Vector(0.3, -0.2, 0.1));
    for (unsigned int j = 0; j < n; ++j) c.state[k].q(j) = std::sin(1.3 * j + 0.2) + 0.01 * k;
  }
  c.contact = c.model->contact("tip");
  c.velocity = FloatingVelocity{KDL::Twist(KDL::Vector(0.01, -0.005, 0.002), KDL::Vector(0.003, 0.02, -0.01)),
                                KDL::JntArray(n)};
  c.tau = KDL::JntArray(n);
  for (unsigned int j = 0; j < n; ++j) {
    c.velocity.qdot(j) = 0.1 - 0.02 * (j % 7);
    c.tau(j) = 0.5 * std::sin(1.0 + j);
  }
  return c;
}

/// Both routes agree (G* and forward dynamics, relative 1e-9) on every case: else nothing is timed.
inline bool checkMimicRoutes() {
  for (const MimicCase& c : mimicCases()) {
    RecursiveExIITSolver fast(c.model);
    FreeFloatingSolver dense(c.model);
    Matrix6d Gf, Gd;
    if (fast.compute(c.state[0]) || fast.G_star(c.contact, Gf) || dense.compute(c.state[0]) ||
        dense.G_star(c.contact, Gd) || (Gf - Gd).norm() > 1e-9 * Gd.norm()) {
      std::cerr << "kdl_space_bench: " << c.name << ": G* of the two routes differ\n";
      return false;
    }
    ForwardDynamicsSolver aba(c.model);
    DenseForwardDynamicsSolver crb(c.model);
    FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(c.model->nj())}, b = a;
    if (aba.CartToJnt(c.state[0], c.velocity, c.tau, {}, a) || crb.CartToJnt(c.state[0], c.velocity, c.tau, {}, b) ||
        (a.qddot.data - b.qddot.data).norm() > 1e-9 * (1.0 + b.qddot.data.norm()) ||
        (a.base - b.base).norm() > 1e-9 * (1.0 + b.base.norm())) {
      std::cerr << "kdl_space_bench: " << c.name << ": the forward dynamics of the two routes differ\n";
      return false;
    }
  }
  return true;
}

/// \brief Registers `<case>/<method>`: a `Solver` built from the case's model, then per iteration
/// `step(solver, case, state, out)`, alternating between the case's two configurations; `out` a
/// copy of `out0`, made before the timing. The four routes of a case differ only in `Solver`
/// and in what they compute (G* or the forward dynamics).
template <class Solver, class Out, class Step>
void registerMimicRoute(const MimicCase& c, const std::string& method, const Out& out0, Step step) {
  const MimicCase* cp = &c;
  benchmark::RegisterBenchmark((c.name + "/" + method).c_str(), [cp, out0, step](benchmark::State& st) {
    Solver solver(cp->model);
    Out out = out0;
    std::size_t i = 0;
    for (auto _ : st) step(solver, *cp, cp->state[i++ & 1], out);
  });
}

inline void registerMimicCase(const MimicCase& c) {
  const auto G_star = [](auto& solver, const MimicCase& mc, const State& s, Matrix6d& G) {
    solver.compute(s);
    solver.G_star(mc.contact, G);
    benchmark::DoNotOptimize(G.data());
  };
  const auto forward_dynamics = [](auto& solver, const MimicCase& mc, const State& s, FloatingAcceleration& a) {
    solver.CartToJnt(s, mc.velocity, mc.tau, {}, a);
    benchmark::DoNotOptimize(a.qddot.data.data());
  };
  const Matrix6d G = Matrix6d::Zero();
  const FloatingAcceleration a{Vector6d::Zero(), KDL::JntArray(c.model->nj())};
  registerMimicRoute<RecursiveExIITSolver>(c, "mimic_recursive_G_star", G, G_star);
  registerMimicRoute<FreeFloatingSolver>(c, "mimic_dense_G_star", G, G_star);
  registerMimicRoute<ForwardDynamicsSolver>(c, "mimic_recursive_forward_dynamics", a, forward_dynamics);
  registerMimicRoute<DenseForwardDynamicsSolver>(c, "mimic_dense_forward_dynamics", a, forward_dynamics);
}

/// The section's table from the medians (time(case, method) in ns, < 0 if not run).
template <class Time, class Fmt>
std::string mimicTable(Time time, Fmt fmt) {
  std::ostringstream t;
  if (mimicCases().empty()) return "";
  t << "\n### Mimic joints: the O(n) recursions with the couplings as constraints vs the dense route "
       "(generated humanoid upper body: hands, a third of the joints mimic finger joints; grippers, "
       "four mimic joints)\n\n"
       "| model | joints (coordinates + mimic) | G* O(n) | G* dense | dense / O(n) | forward dynamics O(n) | "
       "dense | dense / O(n) |\n|---|---|---|---|---|---|---|---|\n";
  const auto ratio = [](double a, double b) {
    std::ostringstream r;
    if (a < 0.0 || b < 0.0) return std::string("–");
    r << std::setprecision(3) << a / b << "×";
    return r.str();
  };
  for (const MimicCase& c : mimicCases()) {
    const double g = time(c.name, "mimic_recursive_G_star"), gd = time(c.name, "mimic_dense_G_star");
    const double f = time(c.name, "mimic_recursive_forward_dynamics"), fd = time(c.name, "mimic_dense_forward_dynamics");
    if (g < 0.0 || gd < 0.0) continue;
    t << "| " << c.name << " | " << c.model->nj() + c.model->mimic().size() << " (" << c.model->nj() << " + "
      << c.model->mimic().size() << ") | " << fmt(g) << " | " << fmt(gd) << " | " << ratio(gd, g) << " | "
      << (f < 0.0 ? std::string("–") : fmt(f)) << " | " << (fd < 0.0 ? std::string("–") : fmt(fd)) << " | "
      << ratio(fd, f) << " |\n";
  }
  return t.str();
}

}  // namespace kdl_space::bench
