// One hostile-input table, run over every compute call of every solver: a state of the wrong
// size, NaN or infinite, or so far away that it overflows; kinematics of another model or never
// computed; a contact on no body or with a non-finite offset. Each call must return the table's
// code, never throw, and leave its output untouched.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"

namespace kdl_space::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSentinel = 12345.0;
using ModelPtr = std::shared_ptr<const FloatingModel>;

ModelPtr arm7() { return std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/space_arm7.urdf")); }

/// A hostile state and the code every state-taking compute call must return for it.
struct BadState {
  std::string name;
  std::function<void(State&)> spoil;
  int code;
};

std::vector<BadState> badStates(unsigned int n) {
  return {
      {"q of the wrong size", [n](State& s) { s.q = KDL::JntArray(n + 1); }, E_SIZE_MISMATCH},
      {"infinite q", [](State& s) { s.q(2) = kInf; }, E_NOT_FINITE},
      {"NaN q", [](State& s) { s.q(0) = kNaN; }, E_NOT_FINITE},
      {"NaN base rotation", [](State& s) { s.world_T_base.M(1, 1) = kNaN; }, E_NOT_FINITE},
      {"infinite base position", [](State& s) { s.world_T_base.p.z(kInf); }, E_NOT_FINITE},
      // Finite, but so far away that the first moment of mass overflows: refused.
      {"base 1e307 m away", [](State& s) { s.world_T_base.p = KDL::Vector(1e307, 0.0, 0.0); }, E_NOT_FINITE},
  };
}

/// Every compute call that takes a state, as (name, call) pairs; each returns a code.
struct StateCall {
  std::string name;
  std::function<int(const State&)> call;
};

class EverySolver : public ::testing::Test {
 protected:
  ModelPtr model = arm7();
  unsigned int n = model->nj();
  Contact tip = model->contact("end_effector", KDL::Vector(0, 0, 0.05));
  FreeFloatingSolver dense{model};
  RecursiveExIITSolver recursive{model};
  MomentumSolver momentum{model};
  ForwardDynamicsSolver dynamics{model};
  Kinematics kin{*model};
  FloatingVelocity velocity{*model};

  std::vector<StateCall> stateCalls() {
    return {
        {"forwardKinematics", [this](const State& s) { return forwardKinematics(*model, s, kin); }},
        {"FreeFloatingSolver::compute", [this](const State& s) { return dense.compute(s); }},
        {"RecursiveExIITSolver::compute", [this](const State& s) { return recursive.compute(s); }},
        {"ForwardDynamicsSolver::CartToJnt",
         [this](const State& s) {
           FloatingAcceleration a;
           a.qddot = KDL::JntArray(n);
           return dynamics.CartToJnt(s, velocity, KDL::JntArray(n), {}, a);
         }},
    };
  }
};

TEST_F(EverySolver, StateTakingCallsRefuseTheSameHostileStates) {
  for (const BadState& bad : badStates(n)) {
    for (const StateCall& c : stateCalls()) {
      SCOPED_TRACE(c.name + ", " + bad.name);
      State s(*model);
      bad.spoil(s);
      EXPECT_NO_THROW(EXPECT_EQ(c.call(s), bad.code));
    }
    // After a refused state, nothing computed is served.
    Matrix6d G = Matrix6d::Constant(kSentinel);
    EXPECT_EQ(dense.G_star(tip, G), E_NOT_COMPUTED) << bad.name;
    EXPECT_EQ(recursive.G_star(tip, G), E_NOT_COMPUTED) << bad.name;
    EXPECT_EQ(G, Matrix6d::Constant(kSentinel));
    EXPECT_FALSE(kin.valid) << bad.name;
  }
}

TEST_F(EverySolver, KinematicsOfAnotherModelOrNotComputedAreRefused) {
  const ModelPtr other = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/dual_arm.urdf"));
  Kinematics foreign(*other);
  ASSERT_EQ(forwardKinematics(*other, State(*other), foreign), E_NOERROR);
  EXPECT_EQ(forwardKinematics(*model, State(*model), foreign), E_SIZE_MISMATCH) << "sized for another model";
  Kinematics fresh(*model);  // never computed
  const Vector6d h = Vector6d::Ones();
  KDL::Twist t(KDL::Vector(kSentinel, 0, 0), KDL::Vector::Zero());
  for (const Kinematics* k : {&foreign, &fresh}) {
    const int code = k == &foreign ? E_SIZE_MISMATCH : E_NOT_COMPUTED;
    SCOPED_TRACE(k == &foreign ? "foreign kinematics" : "kinematics never computed");
    EXPECT_NO_THROW({
      EXPECT_EQ(dense.compute(*k), code);
      EXPECT_EQ(recursive.compute(*k), code);
      EXPECT_EQ(momentum.compute(*k, velocity), code);
      EXPECT_EQ(momentum.baseTwist(*k, h, velocity.qdot, t), code);
      FloatingAcceleration a;
      a.qddot = KDL::JntArray(n);
      a.qddot.data.setConstant(kSentinel);
      EXPECT_EQ(dynamics.CartToJnt(*k, velocity, KDL::JntArray(n), {}, a), code);
      EXPECT_EQ(a.qddot.data, Eigen::VectorXd::Constant(n, kSentinel));
    });
    EXPECT_EQ(t.vel.x(), kSentinel);
  }
}

TEST_F(EverySolver, ContactQueriesRefuseTheSameHostileContacts) {
  ASSERT_EQ(forwardKinematics(*model, State(*model), kin), E_NOERROR);
  ASSERT_EQ(dense.compute(kin), E_NOERROR);
  ASSERT_EQ(recursive.compute(kin), E_NOERROR);
  ASSERT_EQ(momentum.compute(kin, velocity), E_NOERROR);
  const int nb = static_cast<int>(model->bodies().size());
  const struct {
    Contact h;
    int code;
  } cases[] = {
      {Contact{-1, KDL::Vector::Zero()}, E_BAD_CONTACT},
      {Contact{nb, KDL::Vector::Zero()}, E_BAD_CONTACT},
      {Contact{1 << 30, KDL::Vector::Zero()}, E_BAD_CONTACT},
      {Contact{tip.body, KDL::Vector(kNaN, 0, 0)}, E_NOT_FINITE},  // the O(n) G* once returned 0 here
      {Contact{tip.body, KDL::Vector(0, -kInf, 0)}, E_NOT_FINITE},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE("body " + std::to_string(c.h.body) + ", offset x " + std::to_string(c.h.offset.x()));
    Matrix6d M = Matrix6d::Constant(kSentinel);
    Vector6d v = Vector6d::Constant(kSentinel);
    KDL::JntArray dqdot(n);
    dqdot.data.setConstant(kSentinel);
    Vector3d p = Vector3d::Constant(kSentinel);
    KDL::Jacobian J(n);
    J.data.setConstant(kSentinel);
    KDL::Twist t = KDL::Twist::Zero();
    Eigen::MatrixXd G_all = Eigen::MatrixXd::Constant(12, 12, kSentinel);
    EXPECT_NO_THROW({
      EXPECT_EQ(dense.contactPoint(c.h, p), c.code) << "FreeFloatingSolver::contactPoint";
      EXPECT_EQ(dense.R_h(c.h, M), c.code) << "FreeFloatingSolver::R_h";
      EXPECT_EQ(dense.J(c.h, J), c.code) << "FreeFloatingSolver::J";
      EXPECT_EQ(dense.J_star(c.h, J), c.code) << "FreeFloatingSolver::J_star";
      EXPECT_EQ(dense.G_star(c.h, M), c.code) << "FreeFloatingSolver::G_star";
      EXPECT_EQ(dense.G_grounded(c.h, M), c.code) << "FreeFloatingSolver::G_grounded";
      EXPECT_EQ(dense.G_locked(c.h, M), c.code) << "FreeFloatingSolver::G_locked";
      EXPECT_EQ(dense.handTwist(c.h, velocity.qdot, Vector6d::Zero(), t), c.code) << "FreeFloatingSolver::handTwist";
      for (Response r : {Response::FreeFloating, Response::Grounded, Response::JointsLocked}) {
        EXPECT_EQ(dense.G(c.h, r, M), c.code) << "FreeFloatingSolver::G";
        EXPECT_EQ(dense.velocityJump(c.h, r, Vector6d::Ones(), v, dqdot), c.code) << "FreeFloatingSolver::velocityJump";
      }
      EXPECT_EQ(dense.G_star(std::vector<Contact>{tip, c.h}, G_all), c.code) << "FreeFloatingSolver::G_star(contacts)";
      EXPECT_EQ(recursive.G_star(c.h, M), c.code) << "RecursiveExIITSolver::G_star";
      for (Response r : {Response::FreeFloating, Response::Grounded}) {
        EXPECT_EQ(recursive.G(c.h, r, M), c.code) << "RecursiveExIITSolver::G";
        EXPECT_EQ(recursive.velocityJump(c.h, r, Vector6d::Ones(), v, dqdot), c.code) << "RecursiveExIITSolver::velocityJump";
      }
      EXPECT_EQ(momentum.contactTwist(c.h, v), c.code) << "MomentumSolver::contactTwist";
      EXPECT_EQ(momentum.G_locked(c.h, M), c.code) << "MomentumSolver::G_locked";
    });
    EXPECT_EQ(M, Matrix6d::Constant(kSentinel));
    EXPECT_EQ(v, Vector6d::Constant(kSentinel));
    EXPECT_EQ(dqdot.data, Eigen::VectorXd::Constant(n, kSentinel));
    EXPECT_EQ(p, Vector3d::Constant(kSentinel));
    EXPECT_EQ(J.data, Matrix6Xd::Constant(6, n, kSentinel));
    EXPECT_TRUE(toEigen(t) == Vector6d::Zero());
    EXPECT_EQ(G_all, Eigen::MatrixXd::Constant(12, 12, kSentinel));
  }
  // A finite offset so large that the lever arms squared overflow: every G is refused.
  const Contact far{tip.body, KDL::Vector(1e308, 1e308, 0)};
  Matrix6d M = Matrix6d::Constant(kSentinel);
  EXPECT_EQ(dense.G_star(far, M), E_NOT_FINITE);
  EXPECT_EQ(recursive.G_star(far, M), E_NOT_FINITE);
  EXPECT_EQ(recursive.G(far, Response::Grounded, M), E_NOT_FINITE);
  EXPECT_EQ(momentum.G_locked(far, M), E_NOT_FINITE);
  EXPECT_EQ(M, Matrix6d::Constant(kSentinel));
}

TEST_F(EverySolver, WrongSizesNonFiniteVelocitiesAndEnumValues) {
  ASSERT_EQ(forwardKinematics(*model, State(*model), kin), E_NOERROR);
  ASSERT_EQ(recursive.compute(kin), E_NOERROR);
  FloatingVelocity wrong{KDL::Twist::Zero(), KDL::JntArray(n - 1)};
  FloatingVelocity nan_twist = velocity;
  nan_twist.base_twist.rot.z(kNaN);
  KDL::Twist t(KDL::Vector(kSentinel, 0, 0), KDL::Vector::Zero());
  Vector6d v = Vector6d::Constant(kSentinel);
  Matrix6d M = Matrix6d::Constant(kSentinel);
  KDL::JntArray dqdot(n), dq_wrong(n + 2);
  dqdot.data.setConstant(kSentinel);
  Vector6d F = Vector6d::Ones();
  F(3) = kNaN;
  EXPECT_NO_THROW({
    EXPECT_EQ(momentum.compute(kin, wrong), E_SIZE_MISMATCH);
    EXPECT_EQ(momentum.compute(kin, nan_twist), E_NOT_FINITE);
    EXPECT_EQ(momentum.contactTwist(tip, v), E_NOT_COMPUTED) << "a refused compute serves nothing";
    EXPECT_EQ(momentum.baseTwist(kin, Vector6d::Ones(), wrong.qdot, t), E_SIZE_MISMATCH);
    EXPECT_EQ(momentum.baseTwist(kin, Vector6d::Constant(kNaN), velocity.qdot, t), E_NOT_FINITE);
    EXPECT_EQ(recursive.G(tip, Response::JointsLocked, M), E_BAD_ARGUMENT);
    EXPECT_EQ(recursive.G(tip, static_cast<Response>(9), M), E_BAD_ARGUMENT);
    EXPECT_EQ(recursive.velocityJump(tip, Response::JointsLocked, Vector6d::Ones(), v, dqdot), E_BAD_ARGUMENT);
    EXPECT_EQ(recursive.velocityJump(tip, Vector6d::Ones(), v, dq_wrong), E_SIZE_MISMATCH);
    EXPECT_EQ(recursive.velocityJump(tip, F, v, dqdot), E_NOT_FINITE);
    EXPECT_EQ(recursive.velocityJump(tip, Vector6d::Constant(1e308), v, dqdot), E_NOT_FINITE) << "a jump that overflows";
  });
  EXPECT_EQ(t.vel.x(), kSentinel);
  EXPECT_EQ(v, Vector6d::Constant(kSentinel));
  EXPECT_EQ(M, Matrix6d::Constant(kSentinel));
  EXPECT_EQ(dqdot.data, Eigen::VectorXd::Constant(n, kSentinel));
}

}  // namespace
}  // namespace kdl_space::test
