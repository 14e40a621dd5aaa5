// The mass-matrix rule of a model whose links leave it undecided (model_build.hpp): a massless
// base, rigid bodies with a rotational inertia but no mass.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <vector>

#include "spatial/message_text.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "multibody/model_build.hpp"
#include "multibody/model_rules.hpp"

namespace kdl_space::detail {
namespace {

/// \brief The kinetic-energy matrix M (6 + n) of the free-floating system at `kin`: the base twist
/// (v at the base origin; w), world axes, then the coordinates' rates. M = sum_i J_i^T I_i J_i
/// with J_i body i's twist (at the base origin) per generalised velocity and I_i its spatial
/// inertia at the base origin, [[m E, -m c^], [m c^, I_c - m c^ c^]] (c its CoM from there); the
/// armature on the coordinates' diagonal. Written from the definition, apart from the solvers.
Eigen::MatrixXd massMatrix(const FloatingModel& model, const Kinematics& kin) {
  const std::vector<Body>& bodies = model.bodies();
  const int n = static_cast<int>(model.nj());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(6 + n, 6 + n), J(6, 6 + n);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    J.setZero();
    J.leftCols<6>().setIdentity();
    for (int k = static_cast<int>(i); k > 0; k = bodies[k].parent)
      if (bodies[k].joint >= 0) J.col(6 + bodies[k].joint) += kin.S[k];
    const double m = bodies[i].mass;
    const Matrix3d C = skew(Vector3d(kin.com[i] - kin.p_b));
    Matrix6d I = Matrix6d::Zero();
    I.topLeftCorner<3, 3>() = m * Matrix3d::Identity();
    I.topRightCorner<3, 3>() = -m * C;
    I.bottomLeftCorner<3, 3>() = m * C;
    I.bottomRightCorner<3, 3>() = kin.I_com[i] - m * C * C;
    M.noalias() += J.transpose() * I * J;
  }
  for (int j = 0; j < n; ++j) M(6 + j, 6 + j) += model.armature()[j];
  return M;
}

std::string quotedNames(const std::vector<std::string>& names) {
  std::vector<std::string> quoted_names;
  for (const std::string& name : names) quoted_names.push_back(quoted(name));
  return listNames(quoted_names);
}

}  // namespace

void checkMassMatrix(const FloatingModel& model, std::vector<Diagnostic>& diagnostics) {
  // The rigid bodies: the base, or a link on a movable joint, with the links fixed to it.
  const std::vector<Body>& bodies = model.bodies();
  std::vector<int> head(bodies.size(), 0);
  std::vector<double> mass(bodies.size(), 0.0);
  std::vector<bool> rotational(bodies.size(), false);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    head[i] = i == 0 || bodies[i].joint >= 0 ? static_cast<int>(i) : head[bodies[i].parent];
    mass[head[i]] += bodies[i].mass;
    if (!bodies[i].I_com.isZero(0.0)) rotational[head[i]] = true;
  }
  const bool massless_base = mass[0] == 0.0;
  bool rotors = false;  // rigid bodies with a rotational inertia and no mass, on movable joints
  for (std::size_t h = 1; h < bodies.size(); ++h) rotors |= head[h] == static_cast<int>(h) && mass[h] == 0.0 && rotational[h];
  if (!massless_base && !rotors) return;  // the link rules have decided

  std::vector<std::string> base_links;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (head[i] == 0) base_links.push_back(bodies[i].name);
  Kinematics kin(model);
  forwardKinematics(model, State(model), kin);
  const Eigen::MatrixXd M = massMatrix(model, kin);
  // Scaled by its diagonal, so that units and mass scales do not hide or fake a singularity.
  const Eigen::VectorXd d = M.diagonal();
  Eigen::VectorXd null = Eigen::VectorXd::Zero(M.rows());
  bool singular = false;
  for (Eigen::Index k = 0; k < d.size() && !singular; ++k)
    if (!(d(k) > 0.0)) singular = true, null(k) = 1.0;
  if (!singular) {
    const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s.asDiagonal() * M * s.asDiagonal());
    singular = eig.info() != Eigen::Success || !(eig.eigenvalues()(0) > 1e-10);
    null = eig.eigenvectors().col(0);
  }
  const std::string what = base_links.size() == 1 ? "the free-floating base" : "the free-floating base (the links " +
                           quotedNames(base_links) + ": the root and the links fixed to it)";
  if (!singular) {
    if (massless_base)
      diagnostics.push_back({bodies[0].name, what + " has no mass" + (rotational[0] ? " (only a rotational inertia)" : "") +
                                                 ": the links it carries supply it (the system's mass matrix is "
                                                 "positive definite at q = 0)",
                             "massless_base", Severity::Note});
    return;
  }
  // What moves without inertia: the base and the coordinates of the null vector (a motion that
  // moves no mass leaves the others exactly at rest: their components are round-off).
  const double largest = null.cwiseAbs().maxCoeff();
  const bool base_moves = null.head<6>().cwiseAbs().maxCoeff() > 1e-6 * largest;
  std::vector<std::string> joints;
  for (unsigned int j = 0; j < model.nj(); ++j)
    if (std::abs(null(6 + j)) > 1e-6 * largest) joints.push_back(model.jointNames()[j]);
  const std::string with = joints.empty() ? "" : " with joint" + std::string(joints.size() == 1 ? " " : "s ") + quotedNames(joints);
  if (massless_base && base_moves) {
    const std::string fix = "(kdl_space reads the root link's <inertial>, which kdl_parser drops)";
    throw rules::RuleError(rules::error(
        "base_without_mass", ElementType::Link, bodies[0].name,
        what + " has no mass, and the links it carries do not supply it: the system's mass matrix is singular (the "
               "base moves" + with + " without moving any mass); give " +
            (base_links.size() == 1 ? "this link" : "one of them") + " an <inertial> with its mass and inertia " + fix));
  }
  // The links without mass but with a rotational inertia that those joints move.
  std::vector<bool> moved(bodies.size(), joints.empty());
  for (const std::string& joint : joints) moved[model.jointBody()[model.jointIndex(joint)]] = true;
  std::vector<std::string> rotor_links;
  for (std::size_t i = 1; i < bodies.size(); ++i) {
    if (moved[bodies[i].parent]) moved[i] = true;
    if (moved[i] && bodies[i].mass == 0.0 && !bodies[i].I_com.isZero(0.0) && mass[head[i]] == 0.0)
      rotor_links.push_back(bodies[i].name);
  }
  // A singularity of what the link rules already let pass (a point mass on its joint's axis) is
  // theirs to report (singular_composite); this rule refuses what it alone admits.
  if (rotor_links.empty()) return;
  const bool one = joints.size() == 1;
  const std::string movers = joints.empty() ? std::string("the base moves")
                                            : std::string(one ? "joint " : "joints ") + quotedNames(joints) +
                                                  (base_moves ? " and the base move" : one ? " moves" : " move");
  throw rules::RuleError(rules::error(
      "singular_inertia", joints.empty() ? ElementType::File : ElementType::Joint, joints.empty() ? "" : joints.front(),
      "the system's mass matrix is singular at q = 0: " + movers + " no inertia (" +
          (rotor_links.size() == 1 ? "the link " + quotedNames(rotor_links) + " has"
                                   : "the links " + quotedNames(rotor_links) + " have") +
          " a rotational inertia but no mass); give " + (rotor_links.size() == 1 ? "it its" : "them their") +
          " mass, the joint an armature, or no <inertial> to a link that only carries a frame (its joint is then "
          "treated as fixed)"));
}

}  // namespace kdl_space::detail
