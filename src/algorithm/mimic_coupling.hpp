// Private to the O(n) solvers: mimic joints as constraints on the articulated-body recursion.
//
// The recursions run the "free" system in which every body's joint has its own coordinate p_i
// (a mimic body's twist S_i already carries its multiplier, so p_m = q_leader on the coupled
// robot) and the k couplings C pdot = 0, C's rows e_m - e_l (m a mimic joint's body, l its
// coordinate's own body), are imposed by their Lagrange multipliers (MATH.md, "Mimic joints"):
//   Y = M^-1 C^T by k articulated-body solves (a unit joint-torque pair +1 at m, -1 at l, at zero
//   velocity), S = C Y (k x k, positive definite: C has full row rank and M is),
//   constrained accelerations a = a_free - Y S^-1 C a_free (C is constant: Cdot = 0),
//   constrained inverse inertia G_c = G - (J Y) S^-1 (J Y)^T.
// null(C) = range(T) of the coupled coordinates (q_e = T q + o), so these are the coupled
// robot's: T^T M T a = T^T (tau - c) and J T (T^T M T)^-1 T^T J^T, in O(n k + k^3).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space::detail {

class MimicCoupling {
 public:
  MimicCoupling() = default;
  /// The rows of C from the model (sized once: no allocation after this).
  explicit MimicCoupling(const FloatingModel& model) {
    const std::vector<Body>& bodies = model.bodies();
    const std::size_t nb = bodies.size();
    armature_.assign(nb, 0.0);
    for (std::size_t i = 1; i < nb; ++i) {
      const int j = bodies[i].joint;
      if (j < 0) continue;
      const int own = model.jointBody()[j];
      if (own == static_cast<int>(i)) {
        armature_[i] = model.armature()[j];  // the leader's (mimic joints' reflected onto it: T^T diag T)
      } else {
        m_.push_back(static_cast<int>(i));
        l_.push_back(own);
      }
    }
    const int k = rows();
    // Per row, the bodies whose bias force the torque pair makes non-zero: the paths from m and l
    // to the base (the inward pass walks only these, leaves first).
    path_start_.push_back(0);
    std::vector<char> on(nb, 0);
    for (int r = 0; r < k; ++r) {
      for (int b : {m_[r], l_[r]})
        for (; b > 0; b = bodies[b].parent) on[b] = 1;
      for (std::size_t i = nb; i-- > 1;)
        if (on[i]) path_.push_back(static_cast<int>(i)), on[i] = 0;
      path_start_.push_back(static_cast<int>(path_.size()));
    }
    on_path_.assign(nb, 0);
    a_.assign(nb * k, Vector6d::Zero());
    qdd_.assign(nb * k, 0.0);
    p_.assign(nb, Vector6d::Zero());
    u_.assign(nb, 0.0);
    S_.setZero(k, k);
    llt_ = Eigen::LLT<Eigen::MatrixXd>(k);
    c_.setZero(k);
    lambda_.setZero(k);
    Y_.setZero(6, k);
    Z_.setZero(k, 6);
  }

  int rows() const { return static_cast<int>(m_.size()); }
  /// The free system's armature of body i: the coordinate's on its own body, none on a mimic body's.
  double armature(int i) const { return armature_[i]; }

  /// \brief Y = M^-1 C^T of the free system from its articulated-body quantities (world axes, about
  /// one point): parent(i), moves(i) (a joint that is neither fixed nor locked), S(i), U(i) = I^A S,
  /// Dinv(i) = 1 / D, and base(p0, a0) the base's acceleration from its articulated bias force
  /// (false if singular); then S = C Y, factorised. A locked row (m and l both braked) answers
  /// nothing: its row and column of S are e_r. \return 0 or E_NOT_POSITIVE_DEFINITE.
  template <class Parent, class Moves, class SFn, class UFn, class DinvFn, class BaseFn>
  int compute(Parent parent, Moves moves, SFn S, UFn U, DinvFn Dinv, BaseFn base) {
    const int k = rows();
    const std::size_t nb = p_.size();
    for (int r = 0; r < k; ++r) {
      Vector6d* a = a_.data() + r * nb;
      double* qdd = qdd_.data() + r * nb;
      if (!moves(m_[r])) {
        for (std::size_t i = 0; i < nb; ++i) a[i].setZero(), qdd[i] = 0.0;
        continue;
      }
      // Inward: bias forces p^A from the torque pair alone (no velocity, no external force): zero
      // off the paths of m and l to the base, so only those are walked.
      const int* first = path_.data() + path_start_[r];
      const int* last = path_.data() + path_start_[r + 1];
      p_[0].setZero();
      for (const int* b = first; b != last; ++b) p_[*b].setZero(), on_path_[*b] = 1;
      for (const int* it = first; it != last; ++it) {
        const int b = *it;
        if (!moves(b)) {
          p_[parent(b)] += p_[b];
          u_[b] = 0.0;
          continue;
        }
        const double tau = (b == m_[r]) - (b == l_[r]);
        u_[b] = tau - S(b).dot(p_[b]);
        p_[parent(b)] += p_[b] + U(b) * (u_[b] * Dinv(b));
      }
      const bool ok = base(p_[0], a[0]);
      if (!ok) {
        for (const int* b = first; b != last; ++b) on_path_[*b] = 0;
        return E_NOT_POSITIVE_DEFINITE;
      }
      qdd[0] = 0.0;
      for (std::size_t i = 1; i < nb; ++i) {  // outward
        const int b = static_cast<int>(i);
        const Vector6d& a_parent = a[parent(b)];
        if (!moves(b)) {
          a[i] = a_parent;
          qdd[i] = 0.0;
          continue;
        }
        qdd[i] = ((on_path_[i] ? u_[i] : 0.0) - U(b).dot(a_parent)) * Dinv(b);
        a[i] = a_parent + S(b) * qdd[i];
      }
      for (const int* b = first; b != last; ++b) on_path_[*b] = 0;
    }
    for (int s = 0; s < k; ++s)
      for (int r = 0; r < k; ++r) S_(r, s) = qdd(s, m_[r]) - qdd(s, l_[r]);
    for (int s = 0; s < k; ++s)  // symmetric up to round-off: exactly so (in place: no allocation)
      for (int r = s + 1; r < k; ++r) S_(r, s) = S_(s, r) = 0.5 * (S_(r, s) + S_(s, r));
    for (int r = 0; r < k; ++r)
      if (!moves(m_[r])) S_(r, r) = 1.0;
    llt_.compute(S_);
    return llt_.info() == Eigen::Success ? E_NOERROR : E_NOT_POSITIVE_DEFINITE;
  }

  /// \brief The multipliers' share of the free system's accelerations qdd_free(i) (per body): sets
  /// lambda = S^-1 C qdd_free; then a = a_free - sum_r lambda_r (base(r), qdd(r, i)).
  template <class QddFn>
  void solve(QddFn qdd_free) {
    for (int r = 0; r < rows(); ++r) c_(r) = qdd_free(m_[r]) - qdd_free(l_[r]);
    lambda_ = llt_.solve(c_);
  }
  double lambda(int r) const { return lambda_(r); }
  /// Row r's response: the acceleration (twist, about the common point) of body i, and its joint's.
  const Vector6d& a(int r, int i) const { return a_[r * p_.size() + i]; }
  double qdd(int r, int i) const { return qdd_[r * p_.size() + i]; }
  /// sum_r lambda_r qdd(r, i): what the couplings take from body i's joint acceleration.
  double qddShare(int i) const {
    double s = 0.0;
    for (int r = 0; r < rows(); ++r) s += lambda_(r) * qdd(r, i);
    return s;
  }
  /// sum_r lambda_r a(r, 0): what they take from the base's.
  Vector6d baseShare() const {
    Vector6d s = Vector6d::Zero();
    for (int r = 0; r < rows(); ++r) s += lambda_(r) * a(r, 0);
    return s;
  }

  /// G -= (X Y_i) S^-1 (X Y_i)^T: the couplings' share of the inverse inertia at a point of body i
  /// (X the transfer from the common point to it).
  void correctG(const Matrix6d& X, int i, Matrix6d& G) {
    for (int r = 0; r < rows(); ++r) Y_.col(r).noalias() = X * a(r, i);
    Z_ = llt_.solve(Y_.transpose());
    G.noalias() -= Y_ * Z_;
  }

 private:
  std::vector<int> m_, l_;          ///< per row: the mimic body and its coordinate's own body
  std::vector<int> path_, path_start_;  ///< per row r: path_[path_start_[r] .. path_start_[r + 1]), leaves first
  std::vector<char> on_path_;       ///< scratch: the current row's path bodies
  std::vector<double> armature_;    ///< per body (free system)
  std::vector<Vector6d> a_;         ///< per row, per body: accelerations of Y's column
  std::vector<double> qdd_;         ///< per row, per body: joint accelerations of Y's column
  std::vector<Vector6d> p_;         ///< scratch: bias forces
  std::vector<double> u_;           ///< scratch: tau - S^T p
  Eigen::MatrixXd S_;               ///< C M^-1 C^T
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd c_, lambda_;
  Eigen::MatrixXd Y_, Z_;           ///< scratch of correctG: 6 x k, k x 6
};

}  // namespace kdl_space::detail
