// The library against the INDEPENDENT route of MATH.md (virtual_joint_route.hpp): the floating
// system as a grounded KDL tree/chain with six virtual joints, evaluated by KDL's solvers
// (TreeIdSolver_RNE, TreeJntToJacSolver, ChainDynParam, ChainJntToJacSolver). Every bundled
// model, 20 random states each (fixed seed), several contact points per state.
//
// Tolerances: 1e-9 relative per element, plus an absolute floor of 1e-12 times the norm of the
// reference matrix. The floor is needed because many elements are zero in exact arithmetic
// (planar models, joints off the contact's path, decoupled blocks) and come out of either route
// as round-off of order eps * ||matrix|| (the two routes sum in different orders), which a purely
// relative test would reject; 1e-12 * ||.|| is still ~1e3 times below any real discrepancy
// worth 1e-9 of the matrix.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-9;
constexpr double kFloor = 1e-12;
constexpr int kStates = 20;

::testing::AssertionResult close(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref, const std::string& what) {
  return near(a, ref, kRel, kFloor * ref.norm(), what);
}

struct ModelCase {
  std::string name;
  std::string path;
  std::vector<std::string> tips;
  std::string mid_link;  ///< a link in the middle of an arm
  bool chain = false;    ///< every joint on the path to tips[0]: check with the chain solvers too
};

std::ostream& operator<<(std::ostream& os, const ModelCase& c) { return os << c.name; }

std::vector<ModelCase> modelCases() {
  return {
      {"space_arm7", urdfDir() + "/space_arm7.urdf", {"end_effector"}, "link3", true},
      {"dual_arm", urdfDir() + "/dual_arm.urdf", {"left_tool", "right_tool"}, "right_link3", false},
      {"spacedyn_twolink", urdfDir() + "/spacedyn_twolink.urdf", {"hand"}, "link1", true},
      {"arm6_public", dataDir() + "/reference/models/arm6_public.urdf", {"tool"}, "telescope", true},
  };
}

/// Contact points of one state: every tip at its origin and at a random offset, a mid-arm link
/// and the base at random offsets.
std::vector<LinkPoint> contactPoints(const ModelCase& c, const FloatingModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> off(-0.4, 0.4);
  auto random = [&] { return KDL::Vector(off(rng), off(rng), off(rng)); };
  std::vector<LinkPoint> points;
  for (const std::string& tip : c.tips) {
    points.push_back({tip, KDL::Vector::Zero()});
    points.push_back({tip, random()});
  }
  points.push_back({c.mid_link, random()});
  points.push_back({model.bodies()[0].name, random()});
  return points;
}

Eigen::MatrixXd dense(const KDL::JntSpaceInertiaMatrix& m) { return m.data; }

class Independent : public ::testing::TestWithParam<ModelCase> {};
// Names the parameter in test listings (instead of a byte dump).
inline void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.name; }

TEST_P(Independent, JointOrderOfTheModelIsTheTreeNumbering) {
  // The model's joint order is documented as the KDL tree's q_nr: check it by name.
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(GetParam().path));
  int movable = 0;
  for (const auto& [name, element] : model->tree().getSegments()) {
    const KDL::Joint& joint = GetTreeElementSegment(element).getJoint();
    if (joint.getType() == KDL::Joint::None) continue;
    ++movable;
    EXPECT_EQ(model->jointIndex(joint.getName()), static_cast<int>(GetTreeElementQNr(element)))
        << "joint " << joint.getName();
  }
  EXPECT_EQ(movable, static_cast<int>(model->nj()));
}

TEST_P(Independent, AgreesWithVirtualJointTree) {
  const ModelCase& c = GetParam();
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(c.path));
  const int n = static_cast<int>(model->nj());
  FreeFloatingSolver solver(model);
  std::mt19937 rng(20240611);
  for (int s = 0; s < kStates; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    const State state = randomState(*model, rng);
    ASSERT_EQ(solver.compute(state), E_NOERROR);
    const VirtualJointTree route(*model, state);
    const Eigen::MatrixXd& M = route.M_full();

    // Centroid terms and H, H* from the blocks of M_full (coordinates: base twist at the base
    // origin, then joints). M_bb = spatial inertia of the locked system at the base origin:
    // its top-left block is w E, its top-right -w skew(r_g - p_b).
    const Eigen::MatrixXd M_bb = M.topLeftCorner(6, 6), M_bq = M.topRightCorner(6, n);
    const Eigen::MatrixXd H = M.bottomRightCorner(n, n);
    const double w = M_bb(0, 0);
    EXPECT_NEAR(solver.w(), w, kRel * w);
    const Vector3d c_b(M_bb(1, 5) / w, M_bb(2, 3) / w, M_bb(0, 4) / w);  // r_g - p_b, base origin
    const Vector3d p_b = toEigen(state.world_T_base.p);
    const Vector3d r_g = p_b + c_b;
    EXPECT_TRUE(near(solver.r_g(), r_g, kRel, kFloor * r_g.norm(), "r_g"));
    const Matrix6d X = transfer(p_b - r_g);  // twist at r_g -> twist at the base origin
    const Eigen::MatrixXd M_a = X.transpose() * M_bb * X;
    EXPECT_TRUE(close(solver.M_a(), M_a, "M_a"));
    EXPECT_TRUE(close(solver.A_m(), X.transpose() * M_bq, "A_m"));
    EXPECT_TRUE(close(dense(solver.H()), H, "H"));
    const Eigen::MatrixXd H_star = H - M_bq.transpose() * M_bb.ldlt().solve(M_bq);  // Schur complement
    EXPECT_TRUE(close(dense(solver.H_star()), H_star, "H_star"));

    for (const LinkPoint& p : contactPoints(c, *model, rng)) {
      SCOPED_TRACE("contact " + p.link);
      const Contact h = model->contact(p.link, p.offset);
      const Eigen::MatrixXd J_full = route.J_full(p);
      Matrix6d G;
      ASSERT_EQ(solver.G_star(h, G), E_NOERROR);
      const Eigen::MatrixXd G_ref = route.G(p);
      EXPECT_TRUE(close(G, G_ref, "G_star"));

      KDL::Jacobian J(n);
      ASSERT_EQ(solver.J(h, J), E_NOERROR);
      EXPECT_TRUE(close(J.data, J_full.rightCols(n), "J"));
      // J*: the hand twist per joint rate when the base moves so that momentum stays zero,
      // v_b = -M_bb^-1 M_bq qdot.
      const Eigen::MatrixXd J_star = J_full.rightCols(n) - J_full.leftCols(6) * M_bb.ldlt().solve(M_bq);
      ASSERT_EQ(solver.J_star(h, J), E_NOERROR);
      EXPECT_TRUE(close(J.data, J_star, "J_star"));

      ASSERT_EQ(solver.G_grounded(h, G), E_NOERROR);
      EXPECT_TRUE(close(G, route.G_grounded(p), "G_grounded"));
      // Locked: the base coordinates alone (joints frozen).
      ASSERT_EQ(solver.G_locked(h, G), E_NOERROR);
      const Eigen::MatrixXd J_b = J_full.leftCols(6);
      EXPECT_TRUE(close(G, J_b * M_bb.ldlt().solve(J_b.transpose()), "G_locked"));

      Vector3d p_h;
      ASSERT_EQ(solver.contactPoint(h, p_h), E_NOERROR);
      const Vector3d p_ref = toEigen(route.pose(p.link) * p.offset);
      EXPECT_TRUE(near(p_h, p_ref, kRel, kFloor * p_ref.norm(), "contact point"));
    }
  }
}

class IndependentChain : public ::testing::TestWithParam<ModelCase> {};

TEST_P(IndependentChain, AgreesWithVirtualJointChain) {
  const ModelCase& c = GetParam();
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(c.path));
  const int n = static_cast<int>(model->nj());
  FreeFloatingSolver solver(model);
  std::mt19937 rng(777);
  for (int s = 0; s < kStates; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    const State state = randomState(*model, rng);
    ASSERT_EQ(solver.compute(state), E_NOERROR);
    const VirtualJointChain chain(*model, state, c.tips[0]);
    // The two KDL routes (tree RNE, chain CRBA) agree with each other...
    const VirtualJointTree tree(*model, state);
    EXPECT_TRUE(close(chain.M_full(), tree.M_full(), "M_full chain vs tree"));
    // ...and with the library.
    EXPECT_TRUE(close(dense(solver.H()), chain.H(), "H"));
    for (const LinkPoint& p : contactPoints(c, *model, rng)) {
      SCOPED_TRACE("contact " + p.link);
      const Contact h = model->contact(p.link, p.offset);
      Matrix6d G;
      ASSERT_EQ(solver.G_star(h, G), E_NOERROR);
      EXPECT_TRUE(close(G, chain.G(p), "G_star"));
      KDL::Jacobian J(n);
      ASSERT_EQ(solver.J(h, J), E_NOERROR);
      EXPECT_TRUE(close(J.data, chain.J(p), "J"));
      ASSERT_EQ(solver.G_grounded(h, G), E_NOERROR);
      EXPECT_TRUE(close(G, chain.G_grounded(p), "G_grounded"));
    }
  }
}

std::vector<ModelCase> chainCases() {
  std::vector<ModelCase> chains;
  for (const ModelCase& c : modelCases())
    if (c.chain) chains.push_back(c);
  return chains;
}

std::string caseName(const ::testing::TestParamInfo<ModelCase>& info) { return info.param.name; }

INSTANTIATE_TEST_SUITE_P(BundledModels, Independent, ::testing::ValuesIn(modelCases()), caseName);
// dual_arm is a tree: no single KDL chain holds all its joints.
INSTANTIATE_TEST_SUITE_P(ChainModels, IndependentChain, ::testing::ValuesIn(chainCases()), caseName);

TEST(IndependentMultiContact, DualArmBothToolsAgainstVirtualJointTree) {
  const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(urdfDir() + "/dual_arm.urdf"));
  FreeFloatingSolver solver(model);
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> off(-0.2, 0.2);
  for (int s = 0; s < kStates; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    const State state = randomState(*model, rng);
    ASSERT_EQ(solver.compute(state), E_NOERROR);
    const VirtualJointTree route(*model, state);
    const std::vector<LinkPoint> points{{"left_tool", KDL::Vector(off(rng), off(rng), off(rng))},
                                        {"right_tool", KDL::Vector(off(rng), off(rng), off(rng))}};
    const std::vector<Contact> contacts{model->contact(points[0].link, points[0].offset),
                                        model->contact(points[1].link, points[1].offset)};
    Eigen::MatrixXd G(12, 12);
    ASSERT_EQ(solver.G_star(contacts, G), E_NOERROR);
    const Eigen::MatrixXd G_ref = route.G(points);  // J_full_all M_full^-1 J_full_all^T, 12 x 12
    EXPECT_TRUE(close(G, G_ref, "G_star 12x12"));
    for (int i = 0; i < 2; ++i) {
      Matrix6d G_single;
      ASSERT_EQ(solver.G_star(contacts[i], G_single), E_NOERROR);
      EXPECT_TRUE(close(G.block<6, 6>(6 * i, 6 * i), G_single, "diagonal block " + std::to_string(i)));
    }
    // The off-diagonal blocks are each other's transposes (G is symmetric).
    EXPECT_TRUE(close(G.block<6, 6>(0, 6), G.block<6, 6>(6, 0).transpose(), "symmetry"));
  }
}

}  // namespace
}  // namespace kdl_space::test
