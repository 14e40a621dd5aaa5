// The O(n) articulated-body route (RecursiveExIITSolver) against two other routes:
//   * the paper's dense route (FreeFloatingSolver: G* = J* H*^-1 J*^T + R_h M_a^-1 R_h^T, eq. 11;
//     velocity jump dqdot = H*^-1 J*^T F, d(P_g; L_g) = R_h^T F, base twist from the momenta);
//   * the INDEPENDENT virtual-joint route (virtual_joint_route.hpp: KDL's own solvers on the
//     grounded tree with six virtual joints): G = J_full M_full^-1 J_full^T and the velocity jump
//     (d base twist; dqdot) = M_full^-1 J_full^T F.
// On every bundled model and on random KDL trees (several arms, branches hanging off mid-arm
// segments, revolute / prismatic / fixed joints with random origins and axes, random segment
// poses, full inertia tensors, massless intermediate links and frame-only leaves), at random
// states, at every link (the base included) with and without a random offset.
//
// Tolerance: 1e-10 relative per element, plus an absolute floor of 1e-13 times the norm of the
// reference matrix (G*; also the contact twist jump G* F). The floor is needed because many elements are zero in exact
// arithmetic (out-of-plane terms of the planar models, decoupled blocks, joints whose motion
// does not reach a direction) or are small differences of large terms (H* = H - A_m^T M_a^-1 A_m
// cancels heavily when the base weighs hundreds of kilograms): each route then returns round-off
// of order eps * ||G|| times a modest condition factor, summed in a different order, which a
// purely relative test would reject. 1e-13 * ||G|| is ~450 eps; a wrong term (a lever arm, a
// missing child, an armature on the wrong joint, a transposed rotation) gives errors of order
// ||G||.
// The velocity jump (d base twist; dqdot) is one linear solve with H* (or M_full), whose
// round-off is of order eps * cond(H*) * ||whole jump||: cond(H*) reaches 3.5e4 on dual_arm
// (light wrist links on a 100+ kg base), i.e. ~8e-12, and ~3e-12 is observed between ANY two of
// the three routes. Its floor is therefore 1e-12 times the norm of the WHOLE generalized jump
// (not of the compared part alone: a heavy base makes the base twist jump far smaller than the
// joint rate jumps, yet it carries the same absolute round-off). A wrong term still gives errors
// of order 1 relative.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <kdl/rigidbodyinertia.hpp>

#include "spatial/symmetric6d.hpp"
#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "random_tree.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-10;
constexpr double kFloor = 1e-13;      ///< G*: absolute floor per unit of ||G||
constexpr double kJumpFloor = 1e-12;  ///< velocity jump: absolute floor per unit of ||(d base; dqdot)||
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Worst discrepancies seen by a test, printed at its end (for the report; the assertions are
/// the near() checks themselves).
struct Worst {
  double tolerance_fraction = 0.0;  ///< max over elements of |a - b| / (kRel |b| + floor)
  double relative = 0.0;            ///< max over elements of |a - b| / |b| (elements above the floor)
  int comparisons = 0;
  void record(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor) {
    if (a.rows() != b.rows() || a.cols() != b.cols()) return;
    for (Eigen::Index i = 0; i < a.rows(); ++i)
      for (Eigen::Index j = 0; j < a.cols(); ++j) {
        const double e = std::abs(a(i, j) - b(i, j)), t = kRel * std::abs(b(i, j)) + floor;
        if (t > 0.0) tolerance_fraction = std::max(tolerance_fraction, e / t);
        if (std::abs(b(i, j)) > 1e3 * floor && b(i, j) != 0.0) relative = std::max(relative, e / std::abs(b(i, j)));
      }
    ++comparisons;
  }
  void print(const std::string& what) const {
    std::printf("[ worst    ] %s: %d comparisons, worst %.3g of the tolerance; worst relative %.3g\n",
                what.c_str(), comparisons, tolerance_fraction, relative);
  }
};

/// |a - ref| <= kRel |ref| + floor per element, floor = kFloor ||ref||.
::testing::AssertionResult close(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref, const std::string& what,
                                 Worst& worst) {
  worst.record(a, ref, kFloor * ref.norm());
  return near(a, ref, kRel, kFloor * ref.norm(), what);
}
/// The same for a part of a velocity jump: floor = kJumpFloor * ||whole jump||.
::testing::AssertionResult closeJump(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref, double jump_norm,
                                     const std::string& what, Worst& worst) {
  worst.record(a, ref, kJumpFloor * jump_norm);
  return near(a, ref, kRel, kJumpFloor * jump_norm, what);
}

// --- The comparison at one state -------------------------------------------------------------

struct Worsts {
  Worst G_dense, G_virtual, dq_dense, base_dense, dq_virtual, base_virtual, consistency;
  void print(const std::string& what) const {
    G_dense.print(what + " G* recursive vs dense");
    G_virtual.print(what + " G* recursive vs virtual-joint route");
    dq_dense.print(what + " dqdot recursive vs dense");
    base_dense.print(what + " base twist jump recursive vs dense (baseTwist of dPL, dqdot)");
    dq_virtual.print(what + " dqdot recursive vs M_full^-1 J_full^T F");
    base_virtual.print(what + " base twist jump recursive vs M_full^-1 J_full^T F");
    consistency.print(what + " G* F vs J_full (d base; dqdot), recursive");
  }
};

/// A random impulse wrench (force [N s]; moment [N m s]).
Vector6d randomImpulse(std::mt19937& rng) {
  std::uniform_real_distribution<double> f(-10.0, 10.0), n(-3.0, 3.0);
  Vector6d F;
  F << f(rng), f(rng), f(rng), n(rng), n(rng), n(rng);
  return F;
}

/// Both solvers at `state`, every body (base included) at its origin and at a random offset:
/// G* and the velocity jump of a random impulse, against the dense route and the virtual-joint
/// route.
void compareAtState(const FloatingModel& model, RecursiveExIITSolver& rec, FreeFloatingSolver& dense,
                    const State& state, std::mt19937& rng, Worsts& worst) {
  const int n = static_cast<int>(model.nj());
  ASSERT_EQ(rec.compute(state), E_NOERROR);
  ASSERT_EQ(dense.compute(state), E_NOERROR);
  const VirtualJointTree route(model, state);
  const Eigen::LDLT<Eigen::MatrixXd> M_ldlt(route.M_full());
  ASSERT_EQ(M_ldlt.info(), Eigen::Success);
  // Visit the bodies in a shuffled order, so that each query follows an unrelated one (the
  // solver's path scratch must not leak between contacts).
  std::vector<int> order(model.bodies().size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), rng);
  for (const int body : order) {
    for (const KDL::Vector& offset : {KDL::Vector::Zero(), randomVector(rng, 0.5)}) {
      const std::string& link = model.bodies()[body].name;
      SCOPED_TRACE("contact " + link + (offset == KDL::Vector::Zero() ? " at origin" : " with offset"));
      const Contact h{body, offset};

      Matrix6d G_rec, G_dense;
      G_rec.setConstant(kNaN);
      ASSERT_EQ(rec.G_star(h, G_rec), E_NOERROR);
      ASSERT_EQ(dense.G_star(h, G_dense), E_NOERROR);
      EXPECT_TRUE(close(G_rec, G_dense, "G* recursive vs dense", worst.G_dense));

      const Vector6d F = randomImpulse(rng);
      Vector6d d_base;
      d_base.setConstant(kNaN);
      KDL::JntArray dq_rec(n), dq_dense(n);
      dq_rec.data.setConstant(kNaN);  // every joint's entry must be written
      ASSERT_EQ(rec.velocityJump(h, F, d_base, dq_rec), E_NOERROR);
      Vector6d dPL;
      ASSERT_EQ(dense.velocityJump(h, Response::FreeFloating, F, dPL, dq_dense), E_NOERROR);
      // baseTwist is linear in (momentum, rates): the jump of the base twist is baseTwist(dPL, dqdot).
      KDL::Twist d_base_dense;
      ASSERT_EQ(dense.baseTwist(dPL, dq_dense, d_base_dense), E_NOERROR);
      const double jump_norm = std::hypot(dq_dense.data.norm(), toEigen(d_base_dense).norm());
      EXPECT_TRUE(closeJump(dq_rec.data, dq_dense.data, jump_norm, "dqdot recursive vs dense", worst.dq_dense));
      EXPECT_TRUE(closeJump(d_base, toEigen(d_base_dense), jump_norm, "base twist jump recursive vs dense",
                            worst.base_dense));

      const LinkPoint p{link, offset};
      EXPECT_TRUE(close(G_rec, route.G(p), "G* recursive vs virtual-joint route", worst.G_virtual));
      const Eigen::MatrixXd J_full = route.J_full(p);
      const Eigen::VectorXd jump = M_ldlt.solve(J_full.transpose() * F);  // (d base twist; dqdot)
      EXPECT_TRUE(closeJump(d_base, jump.head(6), jump.norm(), "base twist jump recursive vs virtual-joint route",
                            worst.base_virtual));
      EXPECT_TRUE(closeJump(dq_rec.data, jump.tail(n), jump.norm(), "dqdot recursive vs virtual-joint route",
                            worst.dq_virtual));
      // The recursive solver's two queries agree with each other: the contact twist jump G* F
      // equals J_full times the generalized velocity jump it reports.
      Eigen::VectorXd v(6 + n);
      v << d_base, dq_rec.data;
      const Eigen::VectorXd t_ref = J_full * jump;
      EXPECT_TRUE(close(G_rec * F, t_ref, "G* F vs J_full * jump (recursive)", worst.consistency));
      EXPECT_TRUE(close(J_full * v, t_ref, "J_full * recursive jump vs J_full * jump", worst.consistency));
    }
  }
}

// --- Bundled models --------------------------------------------------------------------------

struct BundledModel {
  std::string name;
  std::string path;
};

std::vector<BundledModel> bundledModels() {
  return {
      {"space_arm7", urdfDir() + "/space_arm7.urdf"},
      {"dual_arm", urdfDir() + "/dual_arm.urdf"},
      {"spacedyn_twolink", urdfDir() + "/spacedyn_twolink.urdf"},
      {"arm6_public", dataDir() + "/reference/models/arm6_public.urdf"},
  };
}

class RecursiveBundled : public ::testing::TestWithParam<BundledModel> {};
inline void PrintTo(const BundledModel& c, std::ostream* os) { *os << c.name; }

TEST_P(RecursiveBundled, AgreesWithDenseAndVirtualJointRoutes) {
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(GetParam().path));
  RecursiveExIITSolver rec(model);
  FreeFloatingSolver dense(model);
  std::mt19937 rng(4242);
  Worsts worst;
  for (int s = 0; s < 8; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    compareAtState(*model, rec, dense, randomState(*model, rng), rng, worst);
    if (HasFatalFailure()) return;
  }
  worst.print(GetParam().name);
}

TEST_P(RecursiveBundled, ArmatureAgreesWithDenseAndVirtualJointRoutes) {
  const FloatingModel plain = loadUrdfFile(GetParam().path);
  std::mt19937 rng(515);
  std::uniform_real_distribution<double> rotor(0.01, 5.0);
  std::vector<double> armature(plain.nj());
  for (double& a : armature) a = rotor(rng);
  const auto model = std::make_shared<const FloatingModel>(plain.withArmature(armature));
  RecursiveExIITSolver rec(model), rec_plain(std::make_shared<const FloatingModel>(plain));
  FreeFloatingSolver dense(model);
  Worsts worst;
  for (int s = 0; s < 4; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    const State state = randomState(*model, rng);
    compareAtState(*model, rec, dense, state, rng, worst);
    if (HasFatalFailure()) return;
    // The armature must matter (else this test would not test it): the tip's G* changes.
    ASSERT_EQ(rec_plain.compute(state), E_NOERROR);
    const Contact tip{static_cast<int>(model->bodies().size()) - 1, KDL::Vector::Zero()};
    Matrix6d G_arm, G_plain;
    ASSERT_EQ(rec.G_star(tip, G_arm), E_NOERROR);
    ASSERT_EQ(rec_plain.G_star(tip, G_plain), E_NOERROR);
    EXPECT_GT((G_arm - G_plain).norm(), 1e-6 * G_plain.norm());
  }
  worst.print(GetParam().name + " + armature");
}

INSTANTIATE_TEST_SUITE_P(RecursiveModels, RecursiveBundled, ::testing::ValuesIn(bundledModels()),
                         [](const ::testing::TestParamInfo<BundledModel>& info) { return info.param.name; });

// --- Random trees ----------------------------------------------------------------------------

// The packed symmetric 6x6 of the recursions against the dense spatial algebra it replaces.
TEST(Symmetric6d, AgreesWithDenseAlgebra) {  // also what the forward dynamics uses: setRigidBody, solve
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double m = 1.0 + 10.0 * std::abs(U(rng));
    const Vector3d c(U(rng), U(rng), U(rng));
    Matrix3d B = Matrix3d::NullaryExpr([&] { return U(rng); });
    const Matrix3d I_c = B * B.transpose() + Matrix3d::Identity();
    Vector6d u, v, x;
    for (int k = 0; k < 6; ++k) u(k) = U(rng), v(k) = U(rng), x(k) = U(rng);
    const double alpha = U(rng);

    detail::Symmetric6d S;
    S.setZero();
    S.addRigidBody(m, c, I_c);
    // Independently: KDL's rigid-body inertia about the reference point, [m E, -m c^; m c^, I_o].
    KDL::RotationalInertia I_kdl(I_c(0, 0), I_c(1, 1), I_c(2, 2), I_c(0, 1), I_c(0, 2), I_c(1, 2));
    const KDL::RigidBodyInertia rb(m, toKDL(c), I_kdl);
    Matrix6d D = Matrix6d::Zero();
    D.topLeftCorner<3, 3>() = m * Matrix3d::Identity();
    D.bottomLeftCorner<3, 3>() = skew(toEigen(rb.getCOG() * m));
    D.topRightCorner<3, 3>() = -D.bottomLeftCorner<3, 3>();
    D.bottomRightCorner<3, 3>() = Eigen::Map<const Matrix3d>(rb.getRotationalInertia().data);
    EXPECT_LT((S.toDense() - D).norm(), 1e-14 * D.norm()) << "addRigidBody";
    EXPECT_LT((S * x - D * x).norm(), 1e-14 * D.norm() * x.norm()) << "product";
    detail::Symmetric6d set;
    for (double& a : set.a) a = std::nan("");  // every number replaced
    set.setRigidBody(m, c, I_c);
    for (int k = 0; k < 21; ++k) EXPECT_EQ(set.a[k], S.a[k]) << "setRigidBody, packed element " << k;
    S += S;
    D += D;
    detail::Symmetric6d other;  // another rigid body
    other.setZero();
    other.addRigidBody(m, v.head<3>(), I_c);
    D += other.toDense() - alpha * u * u.transpose();
    S.addMinusRank1(other, u, alpha);
    EXPECT_LT((S.toDense() - D).norm(), 1e-14 * D.norm()) << "+= and the rank-1 update";
    for (int r = 0; r < 6; ++r)
      for (int k = 0; k < 6; ++k) EXPECT_EQ(S(r, k), S(k, r));

    // The inverse of a rigid body's inertia (positive definite), and of one made indefinite.
    detail::Symmetric6d P, P_inv;
    P.setZero();
    P.addRigidBody(m, c, I_c);
    const Matrix6d P_dense = P.toDense();
    ASSERT_TRUE(P.invert(P_inv));
    const Eigen::LDLT<Matrix6d> ldlt(P_dense);  // Eigen's pivoting factorisation, not ours
    const Matrix6d expected = ldlt.solve(Matrix6d::Identity());
    EXPECT_LT((P_inv.toDense() - expected).norm(), 1e-12 * expected.norm()) << "invert";
    EXPECT_LT((P_dense * P_inv.toDense() - Matrix6d::Identity()).norm(), 1e-12 * P_dense.norm() * expected.norm());
    Vector6d solution;
    ASSERT_TRUE(P.solve(x, solution));
    EXPECT_LT((solution - ldlt.solve(x)).norm(), 1e-12 * expected.norm() * x.norm()) << "solve";
    const Vector6d e = Vector6d::Unit(trial % 6);
    detail::Symmetric6d zero;
    zero.setZero();
    P.addMinusRank1(zero, e, 2.0 / expected(trial % 6, trial % 6));  // e^T P^-1 e = 1/(that): crosses zero
    EXPECT_FALSE(P.invert(P_inv)) << "not positive definite";
    EXPECT_FALSE(P.solve(x, solution)) << "not positive definite";
  }
  detail::Symmetric6d nan, out;
  nan.setZero();
  nan.addRigidBody(1.0, Vector3d::Zero(), Matrix3d::Identity());
  nan.a[detail::Symmetric6d::index(4, 2)] = std::nan("");
  EXPECT_FALSE(nan.invert(out));
  Vector6d x;
  EXPECT_FALSE(nan.solve(Vector6d::Ones(), x));
}

TEST(RecursiveRandomTrees, GeneratorCoversTheCases) {
  std::mt19937 rng(kTreeSeed);
  Coverage total;
  for (int t = 0; t < kRandomTrees; ++t) {
    const RandomTree rt = randomTree(rng);
    const Coverage& c = rt.coverage;
    EXPECT_GE(c.arms, 2);
    EXPECT_LE(c.arms, 4);
    total.arms += c.arms;
    total.branches += c.branches;
    total.revolute += c.revolute;
    total.prismatic += c.prismatic;
    total.fixed_massive += c.fixed_massive;
    total.massless_inner += c.massless_inner;
    total.frame_leaves += c.frame_leaves;
    // The model accepts the tree (it refuses a joint that moves no mass) and numbers its joints.
    const FloatingModel model(rt.tree, rt.base_inertia);
    EXPECT_EQ(static_cast<int>(model.nj()), c.revolute + c.prismatic);
    EXPECT_EQ(model.bodies().size(), rt.tree.getSegments().size());  // the root segment is the base
    EXPECT_NEAR(model.bodies()[0].mass, rt.base_inertia.getMass(), 0.0);
  }
  std::printf("[ coverage ] %d trees: %d arms, %d branches, %d revolute, %d prismatic, %d fixed with mass, "
              "%d massless inner links, %d frame-only leaves\n",
              kRandomTrees, total.arms, total.branches, total.revolute, total.prismatic, total.fixed_massive,
              total.massless_inner, total.frame_leaves);
  EXPECT_GT(total.branches, 3);
  EXPECT_GT(total.prismatic, 10);
  EXPECT_GT(total.fixed_massive, 5);
  EXPECT_GT(total.massless_inner, 3);
  EXPECT_GT(total.frame_leaves, 5);
}

TEST(RecursiveRandomTrees, AgreeWithDenseAndVirtualJointRoutes) {
  std::mt19937 rng(kTreeSeed);
  std::mt19937 state_rng(77);
  Worsts worst;
  for (int t = 0; t < kRandomTrees; ++t) {
    SCOPED_TRACE("random tree " + std::to_string(t));
    const RandomTree rt = randomTree(rng);
    const auto model = std::make_shared<const FloatingModel>(rt.tree, rt.base_inertia);
    RecursiveExIITSolver rec(model);
    FreeFloatingSolver dense(model);
    for (int s = 0; s < 3; ++s) {
      SCOPED_TRACE("state " + std::to_string(s));
      compareAtState(*model, rec, dense, randomState(*model, state_rng), state_rng, worst);
      if (HasFatalFailure()) return;
    }
  }
  worst.print("random trees");
}

TEST(RecursiveRandomTrees, ArmatureAgreesWithDenseAndVirtualJointRoutes) {
  std::mt19937 rng(kTreeSeed);
  std::mt19937 state_rng(1234);
  std::uniform_real_distribution<double> rotor(0.01, 5.0);
  Worsts worst;
  for (int t = 0; t < kRandomTrees; ++t) {
    SCOPED_TRACE("random tree " + std::to_string(t));
    const RandomTree rt = randomTree(rng);
    if (t % 3 != 0) continue;  // every third tree (same trees as above)
    std::vector<double> armature(rt.tree.getNrOfJoints());
    for (double& a : armature) a = rotor(state_rng);
    const auto model = std::make_shared<const FloatingModel>(FloatingModel(rt.tree, rt.base_inertia).withArmature(armature));
    RecursiveExIITSolver rec(model);
    FreeFloatingSolver dense(model);
    for (int s = 0; s < 2; ++s) {
      SCOPED_TRACE("state " + std::to_string(s));
      compareAtState(*model, rec, dense, randomState(*model, state_rng), state_rng, worst);
      if (HasFatalFailure()) return;
    }
  }
  worst.print("random trees + armature");
}

// A chain built directly with the FloatingModel(KDL::Chain) constructor: the same agreement.
TEST(RecursiveRandomTrees, ChainModelAgrees) {
  std::mt19937 rng(31);
  KDL::Chain chain;
  for (int k = 0; k < 7; ++k) {
    const KDL::Joint::JointType type = k == 3 ? KDL::Joint::TransAxis : KDL::Joint::RotAxis;
    chain.addSegment(KDL::Segment("link" + std::to_string(k),
                                  KDL::Joint("joint" + std::to_string(k), randomVector(rng, 0.2), randomUnit(rng), type),
                                  KDL::Frame(randomRotation(rng), randomVector(rng, 0.5)), randomLinkInertia(rng)));
  }
  const auto model = std::make_shared<const FloatingModel>(chain, randomBaseInertia(rng));
  RecursiveExIITSolver rec(model);
  FreeFloatingSolver dense(model);
  Worsts worst;
  for (int s = 0; s < 5; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    compareAtState(*model, rec, dense, randomState(*model, rng), rng, worst);
    if (HasFatalFailure()) return;
  }
  worst.print("random chain");
}

// --- Return codes ----------------------------------------------------------------------------

class RecursiveErrors : public ::testing::Test {
 protected:
  std::shared_ptr<const FloatingModel> model =
      std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/dual_arm.urdf"));
  RecursiveExIITSolver rec{model};
  Contact tip = model->contact("left_tool", KDL::Vector(0.1, 0.0, 0.05));
  Vector6d F = (Vector6d() << 1.0, -2.0, 3.0, 0.1, 0.2, -0.3).finished();

  /// Both queries, each expected to return `code`.
  void expectQueries(int code, const Contact& h) {
    Matrix6d G;
    Vector6d d_base;
    KDL::JntArray dq(model->nj());
    EXPECT_EQ(rec.G_star(h, G), code) << "G_star";
    EXPECT_EQ(rec.velocityJump(h, F, d_base, dq), code) << "velocityJump";
  }
  State someState() {
    std::mt19937 rng(5);
    return randomState(*model, rng);
  }
};

TEST_F(RecursiveErrors, QueriesBeforeComputeAreNotComputed) {
  expectQueries(E_NOT_COMPUTED, tip);
  expectQueries(E_NOT_COMPUTED, Contact{-1, KDL::Vector::Zero()});
}

TEST_F(RecursiveErrors, WrongSizeQ) {
  State state(*model);
  state.q = KDL::JntArray(model->nj() + 1);
  EXPECT_EQ(rec.compute(state), E_SIZE_MISMATCH);
  state.q = KDL::JntArray(model->nj() - 1);
  EXPECT_EQ(rec.compute(state), E_SIZE_MISMATCH);
  EXPECT_EQ(rec.compute(State()), E_SIZE_MISMATCH);  // q of size 0
  expectQueries(E_NOT_COMPUTED, tip);
}

TEST_F(RecursiveErrors, NotFiniteState) {
  State state = someState();
  state.q(2) = kNaN;
  EXPECT_EQ(rec.compute(state), E_NOT_FINITE);
  state.q(2) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(rec.compute(state), E_NOT_FINITE);
  State pose = someState();
  pose.world_T_base.p = KDL::Vector(0.0, kNaN, 0.0);
  EXPECT_EQ(rec.compute(pose), E_NOT_FINITE);
  State rotation = someState();
  rotation.world_T_base.M(1, 2) = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(rec.compute(rotation), E_NOT_FINITE);
  expectQueries(E_NOT_COMPUTED, tip);
}

// As FreeFloatingSolver does (test_model_errors.cpp): a failed compute discards the last result.
TEST_F(RecursiveErrors, FailedComputeDiscardsThePreviousResult) {
  ASSERT_EQ(rec.compute(someState()), E_NOERROR);
  expectQueries(E_NOERROR, tip);
  State bad = someState();
  bad.q(0) = kNaN;
  ASSERT_EQ(rec.compute(bad), E_NOT_FINITE);
  expectQueries(E_NOT_COMPUTED, tip);
}

TEST_F(RecursiveErrors, ContactBodyOutOfRange) {
  ASSERT_EQ(rec.compute(someState()), E_NOERROR);
  const int nb = static_cast<int>(model->bodies().size());
  for (int body : {-1, -7, nb, nb + 10}) {
    SCOPED_TRACE("body " + std::to_string(body));
    expectQueries(E_BAD_CONTACT, Contact{body, KDL::Vector::Zero()});
  }
  expectQueries(E_NOERROR, Contact{nb - 1, KDL::Vector::Zero()});
  expectQueries(E_NOERROR, Contact{0, KDL::Vector::Zero()});
}

TEST_F(RecursiveErrors, JointRatesOfWrongSize) {
  ASSERT_EQ(rec.compute(someState()), E_NOERROR);
  Vector6d d_base;
  for (unsigned int rows : {0u, model->nj() - 1, model->nj() + 1}) {
    KDL::JntArray dq(rows);
    EXPECT_EQ(rec.velocityJump(tip, F, d_base, dq), E_SIZE_MISMATCH) << rows << " rows";
  }
}

TEST_F(RecursiveErrors, NotFiniteImpulse) {
  ASSERT_EQ(rec.compute(someState()), E_NOERROR);
  Vector6d d_base;
  KDL::JntArray dq(model->nj());
  for (int k = 0; k < 6; ++k) {
    for (double bad : {kNaN, std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
      Vector6d G = F;
      G(k) = bad;
      EXPECT_EQ(rec.velocityJump(tip, G, d_base, dq), E_NOT_FINITE) << "component " << k << " = " << bad;
    }
  }
  // The solver still answers (and correctly) after the refused calls.
  FreeFloatingSolver dense(model);
  ASSERT_EQ(dense.compute(someState()), E_NOERROR);
  ASSERT_EQ(rec.velocityJump(tip, F, d_base, dq), E_NOERROR);
  KDL::JntArray dq_dense(model->nj());
  Vector6d dPL;
  ASSERT_EQ(dense.velocityJump(tip, Response::FreeFloating, F, dPL, dq_dense), E_NOERROR);
  EXPECT_TRUE(near(dq.data, dq_dense.data, kRel, kJumpFloor * dq_dense.data.norm(), "dqdot after errors"));
}

}  // namespace
}  // namespace kdl_space::test
