#include "kdl_space/algorithm/self_motion.hpp"

#include <Eigen/SVD>
#include <cmath>

#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

SelfMotion::SelfMotion(std::shared_ptr<const FloatingModel> model, const Contact& h, const State& nominal)
    : solver_(model, FreeFloatingSolver::Extent::Jacobians), h_(h), J_(model->nj()) {
  if (solver_.compute(nominal) != E_NOERROR || solver_.J(h_, J_) != E_NOERROR)
    throw InputError("robot.self_motion: the arm's Jacobian cannot be computed at the scenario's state");
  for (unsigned int j = 0; j < model->nj(); ++j)
    if (J_.data.col(j).norm() > 0.0) path_.push_back(static_cast<int>(j));
  J_path_.resize(6, static_cast<Eigen::Index>(path_.size()));
  const std::string arm = std::to_string(path_.size()) + " joints on the path to the contact link";
  if (path_.size() != 7)
    throw InputError("robot.self_motion: the arm has " + arm + "; a self-motion holding the hand's pose is a "
                     "one-parameter family only for 7 (one redundant joint)");
  for (std::size_t k = 0; k < path_.size(); ++k) J_path_.col(static_cast<Eigen::Index>(k)) = J_.data.col(path_[k]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J_path_);
  if (!(svd.singularValues()(5) > 1e-6 * svd.singularValues()(0)))
    throw InputError("robot.self_motion: the arm is singular at the scenario's state (the hand's Jacobian has rank < 6)");
}

int SelfMotion::handFrame(const State& state, KDL::Frame& F) {
  if (const int rc = solver_.compute(state)) return rc;
  const KDL::Frame& body = solver_.bodyPose(h_.body);
  F = KDL::Frame(body.M, body * h_.offset);
  return E_NOERROR;
}

int SelfMotion::direction(const State& state, const Eigen::VectorXd& previous, Eigen::VectorXd& v) {
  if (const int rc = solver_.compute(state)) return rc;
  if (const int rc = solver_.J(h_, J_)) return rc;
  for (std::size_t k = 0; k < path_.size(); ++k) J_path_.col(static_cast<Eigen::Index>(k)) = J_.data.col(path_[k]);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J_path_, Eigen::ComputeFullV);
  if (!(svd.singularValues()(5) > 1e-6 * svd.singularValues()(0))) return E_NOT_POSITIVE_DEFINITE;
  v = svd.matrixV().col(6);
  if (previous.size() == 0) {
    Eigen::Index largest = 0;
    v.cwiseAbs().maxCoeff(&largest);
    if (v(largest) < 0.0) v = -v;
  } else if (v.dot(previous) < 0.0) {
    v = -v;
  }
  return E_NOERROR;
}

int SelfMotion::holdHand(State& state, const KDL::Frame& F0) {
  KDL::Frame F;
  for (int iteration = 0; iteration < 8; ++iteration) {
    if (const int rc = handFrame(state, F)) return rc;
    const KDL::Twist e = KDL::diff(F, F0);  // what takes the hand back, world frame, at the hand
    Vector6d err;
    err << e.vel.x(), e.vel.y(), e.vel.z(), e.rot.x(), e.rot.y(), e.rot.z();
    if (err.norm() < 1e-13) return E_NOERROR;
    if (const int rc = solver_.J(h_, J_)) return rc;
    for (std::size_t k = 0; k < path_.size(); ++k) J_path_.col(static_cast<Eigen::Index>(k)) = J_.data.col(path_[k]);
    const Eigen::VectorXd dq = J_path_.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(err);
    for (std::size_t k = 0; k < path_.size(); ++k) state.q(path_[k]) += dq(static_cast<Eigen::Index>(k));
  }
  if (const int rc = handFrame(state, F)) return rc;
  const KDL::Twist e = KDL::diff(F, F0);
  return e.vel.Norm() + e.rot.Norm() < 1e-10 ? E_NOERROR : E_NOT_FINITE;
}

int SelfMotion::move(State& state, double s) {
  if (!std::isfinite(s)) return E_NOT_FINITE;
  KDL::Frame F0;
  if (const int rc = handFrame(state, F0)) return rc;
  const int steps = static_cast<int>(std::ceil(std::abs(s) / 0.05));
  const double h = steps > 0 ? s / steps : 0.0;
  Eigen::VectorXd v, v_mid, none;
  State mid = state;
  for (int k = 0; k < steps; ++k) {
    if (const int rc = direction(state, k == 0 ? none : v_mid, v)) return rc;
    mid.q = state.q;
    for (std::size_t i = 0; i < path_.size(); ++i) mid.q(path_[i]) += 0.5 * h * v(static_cast<Eigen::Index>(i));
    if (const int rc = direction(mid, v, v_mid)) return rc;
    for (std::size_t i = 0; i < path_.size(); ++i) state.q(path_[i]) += h * v_mid(static_cast<Eigen::Index>(i));
    if (const int rc = holdHand(state, F0)) return rc;
  }
  return E_NOERROR;
}

}  // namespace kdl_space
