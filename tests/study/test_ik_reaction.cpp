// The reaction-minimising inverse kinematics (IkPreference::Reaction): on the default 7-joint arm,
// the solution's reaction measure || W J_h^+ ||_F (recomputed here from the solver's J* by Eigen's
// complete orthogonal decomposition, not by the library's measure) is no larger than the
// posture-preferred solution's and than that of any configuration along the arm's self-motion
// through the same hand pose, sampled by the study's own route (selfMotionJoints).
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <string>

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/study/study.hpp"

namespace kdl_space {
namespace {

/// || W J_h^+ ||_F over all joints (the whole arm is the contact's chain): W the base frame's
/// angular rows of J*, J_h the contact's J*.
double measure(const FloatingSystem& robot, const KDL::JntArray& q) {
  FreeFloatingSolver solver(robot.model);
  State s = robot.state;
  s.q = q;
  KDL::Jacobian J_h(robot.model->nj()), J_base(robot.model->nj());
  EXPECT_EQ(solver.compute(s), 0);
  EXPECT_EQ(solver.J_star(robot.contact, J_h), 0);
  EXPECT_EQ(solver.J_star(Contact{0, KDL::Vector::Zero()}, J_base), 0);
  const Eigen::MatrixXd pinv = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(J_h.data).pseudoInverse();
  return (J_base.data.bottomRows(3) * pinv).norm();
}

TEST(IkReaction, LeastReactionOverTheSelfMotion) {
  const Scenario sc = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml");
  const FloatingSystem& robot = sc.capture.robot;
  ASSERT_EQ(robot.model->nj(), 7u);
  const KDL::Frame goal = contactFrame(*robot.model, robot.state, robot.contact);  // the scenario's hand pose
  IkOptions posture_options, reaction_options;
  reaction_options.prefer = IkPreference::Reaction;
  const IkResult posture = solveInverseKinematics(*robot.model, robot.state, robot.contact, goal, posture_options);
  const IkResult reaction = solveInverseKinematics(*robot.model, robot.state, robot.contact, goal, reaction_options);
  EXPECT_LE(reaction.position_residual, 1e-9);
  EXPECT_LE(reaction.orientation_residual, 1e-9);
  for (unsigned int j = 0; j < 7; ++j) {
    EXPECT_GE(reaction.q(j), robot.model->jointProperties()[j].lower);
    EXPECT_LE(reaction.q(j), robot.model->jointProperties()[j].upper);
  }
  const double m_reaction = measure(robot, reaction.q);
  // The library reports the same measure (its own SVD route).
  EXPECT_NEAR(reaction.reaction_measure, m_reaction, 1e-9 * m_reaction);
  // The posture solution is robot.q itself (the goal is its pose): no better than the reaction one.
  EXPECT_LE(m_reaction, measure(robot, posture.q) * (1 + 1e-12));
  // Every sample along the self-motion (0.05 rad of arc apart, until the study's route stops at
  // a singularity or a limit) holds the same pose; none turns the base less. The optimum is
  // found by a line search on a smooth measure: it is exact to ~1e-12 relative, not to round-off.
  int samples = 0;
  double smallest = std::numeric_limits<double>::infinity();
  for (double s = -6.0; s <= 6.0 + 1e-9; s += 0.05) {
    std::vector<double> q;
    try {
      q = selfMotionJoints(sc, s);
    } catch (const InputError&) {
      continue;  // beyond a singularity or a limit on that side
    }
    KDL::JntArray qa(7);
    for (unsigned int j = 0; j < 7; ++j) qa(j) = q[j];
    smallest = std::min(smallest, measure(robot, qa));
    ++samples;
  }
  ASSERT_GE(samples, 20);
  EXPECT_LE(m_reaction, smallest * (1 + 1e-9)) << "reaction " << m_reaction << ", best sample " << smallest;
  // The measure varies along the self-motion: the test can tell a minimiser from any solution.
  EXPECT_LT(m_reaction, 0.99 * measure(robot, posture.q));
}

}  // namespace
}  // namespace kdl_space
