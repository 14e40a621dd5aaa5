#include "kdl_space/algorithm/conditioning.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <sstream>

namespace kdl_space {
namespace {

double product(const Eigen::VectorXd& sigma) { return sigma.size() ? sigma.prod() : 0.0; }

/// The singular values of a 6 x n matrix, largest first; none for n = 0 (Eigen 3.4's JacobiSVD
/// of a 6 x 0 matrix crashes: PITFALLS, a robot without movable joints).
Eigen::VectorXd singularValues(const Eigen::MatrixXd& A) {
  if (A.rows() == 0 || A.cols() == 0) return Eigen::VectorXd();
  return Eigen::JacobiSVD<Eigen::MatrixXd>(A).singularValues();
}

}  // namespace

Conditioning conditioning(const Eigen::MatrixXd& J_star, const Eigen::MatrixXd& J) {
  Conditioning c;
  c.sigma_J_star = singularValues(J_star);  // descending
  const Eigen::Index k = c.sigma_J_star.size();
  if (k > 0 && c.sigma_J_star(k - 1) > 0.0) c.condition_number = c.sigma_J_star(0) / c.sigma_J_star(k - 1);
  c.manipulability_J_star = product(c.sigma_J_star);
  c.manipulability_J = product(singularValues(J));
  return c;
}

std::vector<JointMargin> jointMargins(const FloatingModel& model, const KDL::JntArray& q) {
  std::vector<JointMargin> out(model.nj());
  for (unsigned int j = 0; j < model.nj() && j < q.rows(); ++j) {
    const JointProperties& p = model.jointProperties()[j];
    JointMargin& m = out[j];
    m.joint = static_cast<int>(j);
    m.limited = std::isfinite(p.lower) || std::isfinite(p.upper);
    m.to_lower = q(j) - p.lower;  // +inf without a lower limit
    m.to_upper = p.upper - q(j);
  }
  return out;
}

std::vector<Diagnostic> configurationWarnings(const FloatingModel& model, const KDL::JntArray& q,
                                              const Conditioning* c, const std::string& contact) {
  std::vector<Diagnostic> out;
  for (const JointMargin& m : jointMargins(model, q)) {
    if (!m.outside()) continue;
    const JointProperties& p = model.jointProperties()[m.joint];
    std::ostringstream s;
    s << "at " << q(m.joint) << ", outside its limits [" << p.lower << ", " << p.upper << "] by " << -m.margin()
      << " (a joint left out of q is at 0): give its position inside the limits";
    out.push_back({model.jointNames()[m.joint], s.str(), "joint_outside_limits", Severity::Warning});
  }
  if (c && c->sigma_J_star.size() > 0 && c->ratio() < kNearSingularRatio) {
    std::ostringstream s;
    s << "J* is near a singularity here: sigma_min / sigma_max = " << c->ratio() << " < " << kNearSingularRatio
      << " (singular values " << c->sigma_J_star.transpose()
      << "): the hand cannot move in some direction, and rates for it grow without bound";
    out.push_back({contact, s.str(), "near_singular", Severity::Warning});
  }
  return out;
}

int checkConfiguration(const std::shared_ptr<const FloatingModel>& model, const State& state, const Contact& h,
                       Conditioning& c, std::vector<Diagnostic>& warnings) {
  warnings = configurationWarnings(*model, state.q, nullptr, "");
  FreeFloatingSolver solver(model, FreeFloatingSolver::Extent::Jacobians);  // J* and J alone: O(n)
  KDL::Jacobian J_star(model->nj()), J(model->nj());
  int rc = solver.compute(state);
  if (rc == E_NOERROR) rc = solver.J_star(h, J_star);
  if (rc == E_NOERROR) rc = solver.J(h, J);
  if (rc != E_NOERROR) return rc;
  c = conditioning(J_star.data, J.data);
  const std::string name = h.body >= 0 ? "contact '" + model->bodies()[h.body].name + "'" : "contact";
  warnings = configurationWarnings(*model, state.q, &c, name);
  return E_NOERROR;
}

}  // namespace kdl_space
