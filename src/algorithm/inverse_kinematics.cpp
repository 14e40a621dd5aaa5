#include "kdl_space/algorithm/inverse_kinematics.hpp"

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>

#include "algorithm/contact_chain.hpp"
#include "algorithm/rank_test.hpp"
#include "spatial/message_text.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/multibody/kinematics.hpp"

namespace kdl_space {

IkUnreachable::~IkUnreachable() = default;
std::exception_ptr IkUnreachable::renamed(const std::string& what) const {
  return std::make_exception_ptr(IkUnreachable(what, best_));
}

namespace {

constexpr double kPi = 3.14159265358979323846;

/// |v|. KDL's Vector::Norm returns 0 when every component is below its epsilon (1e-6): too
/// coarse for a 1e-9 tolerance.
double length(const KDL::Vector& v) { return std::sqrt(KDL::dot(v, v)); }

/// The error twist that takes `current` to `goal` (base frame, reference point at the tip).
KDL::Twist poseError(const KDL::Frame& current, const KDL::Frame& goal) {
  return KDL::Twist(goal.p - current.p, rotationVector(goal.M * current.M.Inverse()));
}

double clampTo(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }

/// The 6 x 6 upper triangle of J^T = Q R (J 6 x n, n >= 6): J J^T = R^T R.
Eigen::Matrix<double, 6, 6> upperR(const Eigen::HouseholderQR<Eigen::MatrixXd>& qr) {
  return qr.matrixQR().topRows<6>().triangularView<Eigen::Upper>();
}

/// The solvers on one chain (each keeps a reference to it: it outlives them).
class IkSearch {
 public:
  IkSearch(const ContactChain& c, const KDL::JntArray& preferred, const KDL::Frame& goal, const IkOptions& o)
      : c_(c), preferred_(preferred), goal_(goal), o_(o), fk_(c.chain), jac_(c.chain),
        vel_(c.chain, 1e-9, 150),
        lma_(c.chain, 1e-12, static_cast<int>(o.max_iterations), 1e-15) {}

  /// One attempt from `q` (chain order, inside the limits); true when the tolerances are met:
  /// Newton-Raphson, else KDL's Levenberg-Marquardt (which ignores the limits: clamped into them)
  /// finished by Newton-Raphson. On failure `q` is the closest configuration either came to.
  bool attempt(KDL::JntArray& q, unsigned int& iterations) {
    KDL::JntArray newton = q;
    if (refine(newton, iterations)) {
      q = newton;
      return true;
    }
    KDL::JntArray lma_chain(c_.chain.getNrOfJoints());
    lma_.CartToJnt(c_.chainAngles(q), goal_, lma_chain);  // its code is not the verdict: refine measures the residual
    iterations += static_cast<unsigned int>(std::max(0, lma_.lastNrOfIter));
    // KDL's LMA moves the chain's joints independently: back to the coordinates by least squares.
    KDL::JntArray lma(q.rows());
    lma.data = c_.coupled ? Eigen::VectorXd(c_.T.completeOrthogonalDecomposition().solve(lma_chain.data - c_.o))
                          : Eigen::VectorXd(lma_chain.data);
    for (unsigned int k = 0; k < q.rows(); ++k) lma(k) = clampTo(lma(k), c_.lower(k), c_.upper(k));
    const bool ok = refine(lma, iterations);
    q = ok || distance(lma) < distance(newton) ? lma : newton;
    return ok;
  }

  /// Newton-Raphson with the accurate error twist over KDL's pseudo-inverse (no null-space term:
  /// quadratic convergence), steps of at most 0.5 per joint, clamped to the limits. On failure `q`
  /// is the iterate closest to the goal (distance + angle).
  bool refine(KDL::JntArray& q, unsigned int& iterations) {
    KDL::JntArray dq(q.rows()), best = q;
    double best_distance = std::numeric_limits<double>::infinity();
    for (unsigned int i = 0; i < o_.max_iterations; ++i) {
      stopIfCancelled(iterations);
      KDL::Frame f;
      fk_.JntToCart(c_.chainAngles(q), f);
      const KDL::Twist e = poseError(f, goal_);
      if (length(e.vel) <= 0.5 * o_.position_tolerance && length(e.rot) <= 0.5 * o_.orientation_tolerance) return true;
      if (length(e.vel) + length(e.rot) < best_distance) {
        best_distance = length(e.vel) + length(e.rot);
        best = q;
      }
      ++iterations;
      if (velocity(q, e, dq) < 0) break;
      const double largest = dq.data.cwiseAbs().maxCoeff();
      if (largest > 0.5) dq.data *= 0.5 / largest;  // far from the goal the linearisation is poor
      for (unsigned int k = 0; k < q.rows(); ++k) q(k) = clampTo(q(k) + dq(k), c_.lower(k), c_.upper(k));
    }
    q = best;
    return false;
  }

  /// Throws Cancelled when the caller's poll says so (IkOptions::cancelled).
  void stopIfCancelled(unsigned int iterations) const {
    if (o_.cancelled && o_.cancelled())
      throw Cancelled("inverse kinematics: cancelled after " + std::to_string(iterations) + " iterations");
  }

  /// Distance + angle (1 m per rad) from the contact frame at `q` to the goal.
  double distance(const KDL::JntArray& q) {
    KDL::Frame f;
    fk_.JntToCart(c_.chainAngles(q), f);
    const KDL::Twist e = poseError(f, goal_);
    return length(e.vel) + length(e.rot);
  }

  /// An orthonormal basis of the self-motion at q (the null space of the chain's Jacobian): the
  /// last n - 6 columns of Q in J^T = Q R when J has full rank 6, else by J's SVD.
  Eigen::MatrixXd nullBasis(const KDL::JntArray& q) {
    const Eigen::MatrixXd J = jacobian(q);
    if (J.cols() > 6) {
      const Eigen::HouseholderQR<Eigen::MatrixXd> qr(J.transpose());
      if (detail::wellConditioned(upperR(qr), 1e-9))
        return (qr.householderQ() * Eigen::MatrixXd::Identity(J.cols(), J.cols())).rightCols(J.cols() - 6);
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
    return svd.matrixV().rightCols(J.cols() - svd.rank());
  }

  /// The contact frame's Jacobian in the coordinates (6 x n): KDL's chain Jacobian times T.
  Eigen::MatrixXd jacobian(const KDL::JntArray& q) {
    KDL::Jacobian J(c_.chain.getNrOfJoints());
    jac_.JntToJac(c_.chainAngles(q), J);
    return c_.coupled ? Eigen::MatrixXd(J.data * c_.T) : Eigen::MatrixXd(J.data);
  }

  /// The least-norm coordinate step for the error twist `e`: KDL's ChainIkSolverVel_pinv on an
  /// uncoupled chain; on a coupled one the same pseudo-inverse (singular values below 1e-9
  /// dropped, as KDL's) of J T. Away from a singularity (every singular value above 1e-8, KDL's
  /// cut 1e-9 below) the same least-norm step by J^T = Q R, dq = Q_1 R^-T e (to round-off).
  int velocity(const KDL::JntArray& q, const KDL::Twist& e, KDL::JntArray& dq) {
    Eigen::Matrix<double, 6, 1> t;
    t << e.vel.x(), e.vel.y(), e.vel.z(), e.rot.x(), e.rot.y(), e.rot.z();
    const Eigen::MatrixXd J = jacobian(q);
    if (J.cols() >= 6) {
      const Eigen::HouseholderQR<Eigen::MatrixXd> qr(J.transpose());
      if (detail::singularValuesAbove(upperR(qr), 1e-16)) {
        Eigen::VectorXd y = Eigen::VectorXd::Zero(J.cols());
        y.head<6>() = qr.matrixQR().topRows<6>().triangularView<Eigen::Upper>().transpose().solve(t);
        dq.data = qr.householderQ() * y;
        return dq.data.allFinite() ? 0 : -1;
      }
    }
    if (!c_.coupled) return vel_.CartToJnt(q, e, dq);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
    Eigen::VectorXd ut = svd.matrixU().transpose() * t;
    for (Eigen::Index i = 0; i < ut.size(); ++i) ut(i) = svd.singularValues()(i) < 1e-9 ? 0.0 : ut(i) / svd.singularValues()(i);
    dq.data = svd.matrixV() * ut;
    return dq.data.allFinite() ? 0 : -1;
  }

  /// N (preferred - q): the part of the way to the preferred posture that does not move the tip.
  Eigen::VectorXd preferenceGradient(const KDL::JntArray& q) {
    const Eigen::MatrixXd Vn = nullBasis(q);
    return Vn * (Vn.transpose() * (preferred_.data - q.data));
  }

  /// The measure a Reaction preference minimises, of chain angles (empty: Posture).
  void setMeasure(std::function<double(const KDL::JntArray&)> m) { measure_ = std::move(m); }
  bool minimisesMeasure() const { return static_cast<bool>(measure_); }

  /// N grad measure by central differences (step 1e-6 rad: the measure is smooth away from
  /// singularities, the error ~1e-12 relative).
  Eigen::VectorXd measureGradient(const KDL::JntArray& q) {
    Eigen::VectorXd g(q.rows());
    for (unsigned int j = 0; j < q.rows(); ++j) {
      KDL::JntArray a = q, b = q;
      a(j) += 1e-6;
      b(j) -= 1e-6;
      g(j) = (measure_(a) - measure_(b)) / 2e-6;
    }
    const Eigen::MatrixXd Vn = nullBasis(q);
    return Vn * (Vn.transpose() * g);
  }

  /// \brief The least measure over the self-motion through q: for a one-dimensional self-motion
  /// a scan along it both ways (steps of 0.05 rad, each projected back onto the pose, until a
  /// limit, a failed projection or the loop closes) for the best start, then steps down
  /// N grad measure (a line search: shorter on failure, longer on success) from there.
  void minimiseMeasure(KDL::JntArray& q, unsigned int& iterations) {
    if (q.rows() <= 6) return;
    KDL::JntArray best = q;
    double best_f = measure_(q);
    if (nullBasis(q).cols() == 1) {
      for (const double way : {1.0, -1.0}) {
        KDL::JntArray x = q;
        Eigen::VectorXd t = way * nullBasis(q).col(0);
        for (int k = 0; k < 600; ++k) {
          Eigen::VectorXd t_new = nullBasis(x).col(0);
          if (t_new.dot(t) < 0) t_new = -t_new;  // keep going the same way
          t = t_new;
          KDL::JntArray trial(x.rows());
          for (unsigned int j = 0; j < x.rows(); ++j) trial(j) = clampTo(x(j) + 0.05 * t(j), c_.lower(j), c_.upper(j));
          if (!refine(trial, iterations) || (trial.data - x.data).norm() < 1e-3) break;  // a limit, a singularity
          x = trial;
          const double f = measure_(x);
          if (f < best_f) best_f = f, best = x;
          if (k > 10 && (x.data - q.data).norm() < 0.04) break;  // back where it started: the loop is closed
        }
      }
    }
    q = best;
    double step = 0.05;
    for (int k = 0; k < 300 && step > 1e-9; ++k) {
      const Eigen::VectorXd g = measureGradient(q);
      if (g.norm() < 1e-12) return;
      KDL::JntArray trial(q.rows());
      for (unsigned int j = 0; j < q.rows(); ++j) trial(j) = clampTo(q(j) - step * g(j) / g.norm(), c_.lower(j), c_.upper(j));
      double f = 0;
      if (refine(trial, iterations) && (f = measure_(trial)) < best_f) {
        q = trial;
        best_f = f;
        step = std::min(2.0 * step, 0.2);
      } else {
        step *= 0.5;
      }
    }
  }

  /// Null-space steps towards the preferred posture, each projected back onto the pose, to where
  /// the way there has no part along the self-motion (|N (preferred - q)| at round-off): the
  /// nearest configuration on the pose's self-motion, whatever the start. The steps' lengths are
  /// Barzilai and Borwein's, s.s / s.y (a secant of the curvature: the plain step g converges only
  /// linearly, by ~0.45 an iteration on a 7-joint arm: 29 iterations, now 5); a step that makes no
  /// progress is halved, down to 1e-3.
  void preferPosture(KDL::JntArray& q, unsigned int& iterations) {
    if (q.rows() <= 6) return;
    const double converged = 1e-13 * (1.0 + preferred_.data.norm()), noise = 10.0 * converged;
    Eigen::VectorXd g = preferenceGradient(q);
    double step = 1.0;
    for (int k = 0; k < 100 && step > 1e-3 && g.norm() > converged; ++k) {
      KDL::JntArray trial(q.rows());
      for (unsigned int j = 0; j < q.rows(); ++j) trial(j) = clampTo(q(j) + step * g(j), c_.lower(j), c_.upper(j));
      if (!refine(trial, iterations)) {
        step *= 0.5;
        continue;
      }
      const Eigen::VectorXd g_trial = preferenceGradient(trial);
      const double d = (q.data - preferred_.data).norm(), d_trial = (trial.data - preferred_.data).norm();
      // Progress: nearer beyond round-off, or as near with a gradient a tenth smaller (a joint held
      // at its limit blocks the way: neither, and the steps shrink to the end).
      if (!(d_trial < d - noise || (d_trial <= d + noise && g_trial.norm() < 0.9 * g.norm()))) {
        step *= 0.5;
        continue;
      }
      // f = |q - preferred|^2 / 2 on the self-motion, its gradient -g: s.y with y = g - g_trial.
      const Eigen::VectorXd s = trial.data - q.data;
      const double sy = s.dot(g - g_trial);
      step = sy > 0.0 ? std::clamp(s.squaredNorm() / sy, 0.05, 4.0) : 1.0;
      q = trial;
      g = g_trial;
    }
  }

  bool withinLimits(const KDL::JntArray& q) const {
    for (unsigned int k = 0; k < q.rows(); ++k)
      if (!(q(k) >= c_.lower(k) && q(k) <= c_.upper(k))) return false;
    return true;
  }

 private:
  const ContactChain& c_;
  KDL::JntArray preferred_;
  KDL::Frame goal_;
  IkOptions o_;
  KDL::ChainFkSolverPos_recursive fk_;
  KDL::ChainJntToJacSolver jac_;
  KDL::ChainIkSolverVel_pinv vel_;
  KDL::ChainIkSolverPos_LMA lma_;
  std::function<double(const KDL::JntArray&)> measure_;
};

/// The a-th deterministic start (a >= 1): a low-discrepancy point (fractional parts of multiples
/// of sqrt(prime)) in each joint's range; an unlimited joint ranges over a turn (or 1 m) about
/// the seed.
KDL::JntArray start(const ContactChain& c, const KDL::JntArray& seed, unsigned int a) {
  static const double primes[] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53};
  KDL::JntArray q(seed.rows());
  for (unsigned int k = 0; k < q.rows(); ++k) {
    const double lo = std::isfinite(c.lower(k)) ? c.lower(k) : seed(k) - kPi;
    const double hi = std::isfinite(c.upper(k)) ? c.upper(k) : seed(k) + kPi;
    const double alpha = std::sqrt(primes[k % 16] + 16.0 * static_cast<double>(k / 16));
    const double u = std::fmod(0.5 + a * alpha, 1.0);
    q(k) = lo + u * (hi - lo);
  }
  return q;
}

/// Residuals of `q` (model order) by the model's own forward kinematics.
void measure(const FloatingModel& model, const State& seed, const Contact& contact, const KDL::Frame& goal,
             IkResult& r) {
  State s = seed;
  s.q = r.q;
  const KDL::Frame f = contactFrame(model, s, contact);
  r.position_residual = length(f.p - goal.p);
  r.orientation_residual = length(rotationVector(goal.M * f.M.Inverse()));
}

}  // namespace

double reactionMeasure(const FloatingModel& model, const State& state, const Contact& contact,
                       const std::vector<int>& joints) {
  // Not owned: the solver lives only for this call, within the caller's model's lifetime.
  const std::shared_ptr<const FloatingModel> shared(&model, [](const FloatingModel*) {});
  FreeFloatingSolver solver(shared, FreeFloatingSolver::Extent::Jacobians);
  KDL::Jacobian J_h(model.nj()), J_base(model.nj());
  int rc = solver.compute(state);
  if (rc == E_NOERROR) rc = solver.J_star(contact, J_h);
  if (rc == E_NOERROR) rc = solver.J_star(Contact{0, KDL::Vector::Zero()}, J_base);
  if (rc != E_NOERROR) throw ModelError(std::string("reaction measure: ") + strError(rc));
  const Eigen::Index k = static_cast<Eigen::Index>(joints.size());
  Eigen::MatrixXd A(6, k), W(3, k);
  for (Eigen::Index i = 0; i < k; ++i) {
    A.col(i) = J_h.data.col(joints[i]);
    W.col(i) = J_base.data.col(joints[i]).tail<3>();
  }
  if (k == 0) return 0.0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (sv(i) > 1e-12 * sv(0)) inv(i) = 1.0 / sv(i);
  return (W * svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose()).norm();
}

IkResult solveInverseKinematics(const FloatingModel& model, const State& seed, const Contact& contact,
                                const KDL::Frame& world_T_goal, const IkOptions& options) {
  if (seed.q.rows() != model.nj())
    throw ModelError("inverse kinematics: the seed has " + std::to_string(seed.q.rows()) + " joint values, the model " +
                     std::to_string(model.nj()) + " joints");
  if (contact.body < 0 || static_cast<std::size_t>(contact.body) >= model.bodies().size())
    throw ModelError("inverse kinematics: contact body " + std::to_string(contact.body) + " is outside the model");
  if (options.preferred && options.preferred->rows() != model.nj())
    throw ModelError("inverse kinematics: the preferred posture has " + std::to_string(options.preferred->rows()) +
                     " joint values, the model " + std::to_string(model.nj()) + " joints");
  const ContactChain c = contactChain(model, contact);
  const unsigned int n = static_cast<unsigned int>(c.joints.size());
  if (n == 0)
    throw InputError("inverse kinematics: no movable joint moves the contact frame on link " +
                     detail::quoted(model.bodies()[contact.body].name) +
                     (model.nj() == 0 ? std::string(" (the robot has no movable joint: a rigid body)")
                                      : " (none lies between the base and this link)") +
                     ": it moves only with the base, which inverse kinematics holds; give a contact on an arm");
  KDL::JntArray q0(n), preferred(n);
  const KDL::JntArray& pref_model = options.preferred ? *options.preferred : seed.q;
  for (unsigned int k = 0; k < n; ++k) {
    q0(k) = clampTo(seed.q(c.joints[k]), c.lower(k), c.upper(k));
    preferred(k) = clampTo(pref_model(c.joints[k]), c.lower(k), c.upper(k));
  }
  const KDL::Frame base_T_goal = seed.world_T_base.Inverse() * world_T_goal;  // the chain's frame
  IkSearch search(c, preferred, base_T_goal, options);

  const auto toModel = [&](const KDL::JntArray& qc) {
    KDL::JntArray q = seed.q;
    for (unsigned int k = 0; k < n; ++k) q(c.joints[k]) = qc(k);
    return q;
  };
  // The reaction measure of chain angles, the base where the seed puts it.
  const auto reaction = [&](const KDL::JntArray& qc) {
    State st = seed;
    st.q = toModel(qc);
    return reactionMeasure(model, st, contact, c.joints);
  };
  const auto measureOr = [&](const KDL::JntArray& qc) {
    try {
      return reaction(qc);
    } catch (const ModelError&) {
      return std::numeric_limits<double>::quiet_NaN();
    }
  };
  if (options.prefer == IkPreference::Reaction && n > 6) search.setMeasure(reaction);
  IkResult best;
  best.chain_joints = c.joints;
  double best_score = std::numeric_limits<double>::infinity();
  unsigned int iterations = 0;
  for (unsigned int a = 0; a <= options.restarts; ++a) {
    search.stopIfCancelled(iterations);
    KDL::JntArray qc = a == 0 ? q0 : start(c, q0, a);
    const bool ok = search.attempt(qc, iterations);
    if (ok && search.minimisesMeasure())
      search.minimiseMeasure(qc, iterations);
    else if (ok)
      search.preferPosture(qc, iterations);
    IkResult r;
    r.q = toModel(qc);
    r.chain_joints = c.joints;
    r.attempts = a + 1;
    measure(model, seed, contact, world_T_goal, r);
    r.iterations = iterations;
    if (ok && n > 6)
      r.preference_gradient = (search.minimisesMeasure() ? search.measureGradient(qc) : search.preferenceGradient(qc)).norm();
    if (options.measure_reaction) r.reaction_measure = measureOr(qc);
    if (ok && search.withinLimits(qc) && r.position_residual <= options.position_tolerance &&
        r.orientation_residual <= options.orientation_tolerance)
      return r;
    const double score = r.position_residual + r.orientation_residual;  // m + rad (1 m per rad)
    if ((score < best_score || best.q.rows() == 0) && search.withinLimits(qc)) {
      best_score = score;
      best = r;
    }
  }
  if (best.q.rows() == 0) {  // no attempt ended inside the limits: report the seed
    best.q = seed.q;
    best.chain_joints = c.joints;
    measure(model, seed, contact, world_T_goal, best);
  }
  best.iterations = iterations;
  best.attempts = options.restarts + 1;
  std::ostringstream msg;
  msg.precision(6);
  msg << "inverse kinematics: the pose is out of reach of the contact frame on link "
      << detail::quoted(model.bodies()[contact.body].name) << ": after " << best.attempts
      << " starts the closest came within " << best.position_residual << " m and " << best.orientation_residual
      << " rad of it (tolerances " << options.position_tolerance << " m, " << options.orientation_tolerance
      << " rad), with";
  for (unsigned int k = 0; k < n; ++k)
    msg << (k ? ", " : " ") << model.jointNames()[c.joints[k]] << " = " << best.q(c.joints[k]);
  msg << "; move the goal closer or check its frame";
  throw IkUnreachable(msg.str(), best);
}

}  // namespace kdl_space
