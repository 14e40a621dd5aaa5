#include "kdl_space/algorithm/self_motion.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "algorithm/rank_test.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {
namespace {

/// J's smallest singular value is more than 1e-6 of its Frobenius norm.
bool fullRank(const Eigen::Matrix<double, 6, 6>& JJt) { return detail::gramAbove(JJt, 1e-12 * JJt.trace()); }

/// Bit for bit (KDL's operator== on a Rotation compares within an epsilon).
bool samePose(const KDL::Frame& a, const KDL::Frame& b) {
  for (int i = 0; i < 3; ++i)
    if (a.p.data[i] != b.p.data[i]) return false;
  for (int i = 0; i < 9; ++i)
    if (a.M.data[i] != b.M.data[i]) return false;
  return true;
}

/// The twist that takes the hand from F back to F0 (v; w), world frame, at the hand; the rotation
/// by rotationVector (KDL::diff reads a rotation below ~1e-6 rad as none: a short step's drift).
Vector6d handError(const KDL::Frame& F, const KDL::Frame& F0) {
  Vector6d err;
  err << toEigen(F0.p - F.p), toEigen(rotationVector(F0.M * F.M.Inverse()));
  return err;
}

}  // namespace

SelfMotion::SelfMotion(std::shared_ptr<const FloatingModel> model, const Contact& h, const State& nominal)
    : model_(std::move(model)), kin_(*model_), h_(h), J_(Matrix6Xd::Zero(6, model_->nj())) {
  if (contactCode(true, h_, model_->bodies().size()) != E_NOERROR ||
      forwardKinematics(*model_, nominal, kin_) != E_NOERROR || pathJacobian() != E_NOERROR)
    throw InputError("robot.self_motion: the arm's Jacobian cannot be computed at the scenario's state");
  for (unsigned int j = 0; j < model_->nj(); ++j)
    if (J_.col(j).norm() > 0.0) path_.push_back(static_cast<int>(j));
  const std::string arm = std::to_string(path_.size()) + " joints on the path to the contact link";
  if (path_.size() != 7)
    throw InputError("robot.self_motion: the arm has " + arm + "; a self-motion holding the hand's pose is a "
                     "one-parameter family only for 7 (one redundant joint)");
  if (pathJacobian(nominal) != E_NOERROR || !fullRank(J_path_ * J_path_.transpose()))
    throw InputError("robot.self_motion: the arm is singular at the scenario's state (the hand's Jacobian has rank < 6)");
}

int SelfMotion::pathJacobian(const State& state) {
  if (const int rc = forwardKinematics(*model_, state, kin_)) return rc;
  return pathJacobian();
}

int SelfMotion::pathJacobian() {
  // Each joint's unit twist carried from the base origin to the hand point (a coordinate that
  // moves several joints, mimic, sums their columns).
  const std::vector<Body>& bodies = model_->bodies();
  const Vector3d r = kin_.point(h_) - kin_.p_b;
  J_.setZero();
  for (int b = h_.body; b >= 0; b = bodies[b].parent)
    if (bodies[b].joint >= 0) J_.col(bodies[b].joint) += shiftTwist(kin_.S[b], r);
  if (!J_.allFinite()) return E_NOT_FINITE;
  for (std::size_t k = 0; k < path_.size(); ++k) J_path_.col(static_cast<Eigen::Index>(k)) = J_.col(path_[k]);
  return E_NOERROR;
}

int SelfMotion::handFrame(const State& state, KDL::Frame& F) {
  if (const int rc = forwardKinematics(*model_, state, kin_)) return rc;
  const KDL::Frame body = kin_.pose(h_.body);
  F = KDL::Frame(body.M, body * h_.offset);
  return E_NOERROR;
}

int SelfMotion::direction(const State& state, const PathVector* previous, PathVector& v) {
  if (const int rc = pathJacobian(state)) return rc;
  const Eigen::Matrix<double, 6, 6> JJt = J_path_ * J_path_.transpose();
  if (!fullRank(JJt)) return E_NOT_POSITIVE_DEFINITE;
  // The self-motion's tangent: a vector projected onto J's null space, P u = u - J^T (J J^T)^-1 J u
  // (once more for round-off), normalised. u is the direction the walk came along; at the start the
  // coordinate axis P keeps most of, the sign then making the largest component positive.
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(JJt);
  PathVector u;
  if (previous) {
    u = *previous;
  } else {
    const Eigen::Matrix<double, 6, 7> X = llt.solve(J_path_);
    Eigen::Index kept = 0;
    (PathVector::Ones() - (J_path_.cwiseProduct(X)).colwise().sum().transpose()).maxCoeff(&kept);
    u = PathVector::Unit(kept);
  }
  for (int pass = 0; pass < 2; ++pass) u -= J_path_.transpose() * llt.solve(J_path_ * u);
  if (!(u.norm() > 0.0) || !u.allFinite()) return E_NOT_POSITIVE_DEFINITE;
  v = u.normalized();
  if (!previous) {
    Eigen::Index largest = 0;
    v.cwiseAbs().maxCoeff(&largest);
    if (v(largest) < 0.0) v = -v;
  } else if (v.dot(*previous) < 0.0) {
    v = -v;
  }
  return E_NOERROR;
}

int SelfMotion::holdHand(State& state, const KDL::Frame& F0) {
  KDL::Frame F;
  for (int iteration = 0; iteration < 8; ++iteration) {
    if (const int rc = handFrame(state, F)) return rc;
    const Vector6d err = handError(F, F0);  // what takes the hand back, world frame, at the hand
    if (err.norm() < 1e-13) return E_NOERROR;
    if (const int rc = pathJacobian()) return rc;  // at the state handFrame computed
    // The least-norm step dq = J^T (J J^T)^-1 err (J is well conditioned along the walk: the
    // directions' rank test; a Newton step's round-off is the next one's error).
    const Eigen::Matrix<double, 6, 6> JJt = J_path_ * J_path_.transpose();
    const PathVector dq = J_path_.transpose() * Eigen::LLT<Eigen::Matrix<double, 6, 6>>(JJt).solve(err);
    for (Eigen::Index k = 0; k < 7; ++k) state.q(path_[static_cast<std::size_t>(k)]) += dq(k);
  }
  if (const int rc = handFrame(state, F)) return rc;
  const Vector6d err = handError(F, F0);
  return err.head<3>().norm() + err.tail<3>().norm() < 1e-10 ? E_NOERROR : E_NOT_FINITE;
}

int SelfMotion::step(State& state, double h, const PathVector* previous, PathVector& v_mid) {
  PathVector v;
  if (const int rc = direction(state, previous, v)) return rc;
  mid_ = state;  // (its storage kept from step to step)
  for (Eigen::Index i = 0; i < 7; ++i) mid_.q(path_[static_cast<std::size_t>(i)]) += 0.5 * h * v(i);
  if (const int rc = direction(mid_, &v, v_mid)) return rc;
  for (Eigen::Index i = 0; i < 7; ++i) state.q(path_[static_cast<std::size_t>(i)]) += h * v_mid(i);
  return holdHand(state, F0_);
}

int SelfMotion::restart(const State& state) {
  started_ = false;
  walk_[0].clear();
  walk_[1].clear();
  failed_[0] = failed_[1] = 0;
  if (const int rc = handFrame(state, F0_)) return rc;
  start_ = state;
  started_ = true;
  return E_NOERROR;
}

int SelfMotion::extend(int way, std::size_t k) {
  std::vector<Checkpoint>& walk = walk_[way];
  State x = start_;
  if (!walk.empty())
    for (Eigen::Index i = 0; i < 7; ++i) x.q(path_[static_cast<std::size_t>(i)]) = walk.back().q(i);
  while (walk.size() < k && !failed_[way]) {
    Checkpoint c;
    if ((failed_[way] = step(x, way == 0 ? kStep : -kStep, walk.empty() ? nullptr : &walk.back().v, c.v))) break;
    for (Eigen::Index i = 0; i < 7; ++i) c.q(i) = x.q(path_[static_cast<std::size_t>(i)]);
    walk.push_back(c);
  }
  return walk.size() < k ? failed_[way] : E_NOERROR;
}

int SelfMotion::move(State& state, double s) {
  if (!std::isfinite(s)) return E_NOT_FINITE;
  const bool same = started_ && state.q.data == start_.q.data && samePose(state.world_T_base, start_.world_T_base);
  if (!same)
    if (const int rc = restart(state)) return rc;
  // The checkpoint at the largest multiple of kStep within |s| (a multiple within round-off is one).
  const double steps = std::abs(s) / kStep;
  const double nearest = std::round(steps);
  const std::size_t m = static_cast<std::size_t>(std::abs(steps - nearest) < 1e-9 ? nearest : std::floor(steps));
  const int way = s < 0.0 ? 1 : 0;
  if (const int rc = extend(way, m)) return rc;
  if (m > 0)
    for (Eigen::Index i = 0; i < 7; ++i) state.q(path_[static_cast<std::size_t>(i)]) = walk_[way][m - 1].q(i);
  const double rest = std::abs(s) - static_cast<double>(m) * kStep;
  if (std::abs(rest) < 1e-12) return E_NOERROR;
  PathVector v_mid;
  return step(state, way == 0 ? rest : -rest, m > 0 ? &walk_[way][m - 1].v : nullptr, v_mid);
}

}  // namespace kdl_space
