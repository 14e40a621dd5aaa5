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
    tau_.resize(nb);  // per body: the rows whose torque pair acts on it, and the sign
    for (int r = 0; r < k; ++r) {
      tau_[m_[r]].push_back({r, 1.0});
      tau_[l_[r]].push_back({r, -1.0});
    }
    A_.setZero(6, nb * k);
    P_.setZero(6, nb * k);
    Q_.setZero(k, nb);
    u_.setZero(k, nb);
    row_.setZero(k);
    S_.setZero(k, k);
    // Sized here, so that compute() allocates nothing later. Not `llt_ = LLT(k)`: Eigen 3.4's
    // LLT(size) leaves its info unset and the move assignment reads it (UBSan: an invalid enum).
    llt_.compute(Eigen::MatrixXd::Identity(k, k));
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
  /// Dinv(i) = 1 / D, and base(P0, A0) the base's accelerations (6 x k) from its articulated bias
  /// forces (false if singular); then S = C Y, factorised. A locked row (m and l both braked) answers
  /// nothing: its row and column of S are e_r. \return 0 or E_NOT_POSITIVE_DEFINITE.
  /// All k rows at once: per body a 6 x k block of bias forces (inward) and of accelerations
  /// (outward), so that each step is a few vectorised 6 x k operations.
  template <class Parent, class Moves, class SFn, class UFn, class DinvFn, class BaseFn>
  int compute(Parent parent, Moves moves, SFn S, UFn U, DinvFn Dinv, BaseFn base) {
    const int k = rows();
    const Eigen::Index nb = Q_.cols();
    const auto P = [&](Eigen::Index i) { return P_.middleCols(i * k, k); };
    const auto A = [&](Eigen::Index i) { return A_.middleCols(i * k, k); };
    P_.setZero();
    for (Eigen::Index i = nb; i-- > 1;) {  // inward: bias forces of the torque pairs alone
      const int b = static_cast<int>(i);
      if (!moves(b)) {
        P(parent(b)) += P(i);
        continue;
      }
      row_.noalias() = -P(i).transpose() * S(b);  // not -(A * b): that evaluates the product into a heap temporary
      for (const Tau& t : tau_[i]) row_(t.row) += t.sign;
      u_.col(i) = row_;
      row_ *= Dinv(b);
      P(parent(b)) += P(i);
      P(parent(b)).noalias() += U(b) * row_.transpose();
    }
    if (!base(P(0), A(0))) return E_NOT_POSITIVE_DEFINITE;
    Q_.col(0).setZero();
    for (Eigen::Index i = 1; i < nb; ++i) {  // outward
      const int b = static_cast<int>(i);
      if (!moves(b)) {
        A(i) = A(parent(b));
        Q_.col(i).setZero();
        continue;
      }
      row_ = u_.col(i);
      row_.noalias() -= A(parent(b)).transpose() * U(b);
      row_ *= Dinv(b);
      Q_.col(i) = row_;
      A(i) = A(parent(b));
      A(i).noalias() += S(b) * row_.transpose();
    }
    for (int r = 0; r < k; ++r) S_.row(r) = Q_.col(m_[r]).transpose() - Q_.col(l_[r]).transpose();
    for (int s = 0; s < k; ++s)  // symmetric up to round-off: exactly so (in place: no allocation)
      for (int r = s + 1; r < k; ++r) S_(r, s) = S_(s, r) = 0.5 * (S_(r, s) + S_(s, r));
    for (int r = 0; r < k; ++r)
      if (!moves(m_[r])) S_(r, r) = 1.0;  // a braked pair: its row and column are zero
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
  /// sum_r lambda_r qdd(r, i): what the couplings take from body i's joint acceleration.
  double qddShare(int i) const { return Q_.col(i).dot(lambda_); }
  /// sum_r lambda_r a(r, 0): what they take from the base's.
  Vector6d baseShare() const { return A_.leftCols(rows()) * lambda_; }

  /// G -= (X Y_i) S^-1 (X Y_i)^T: the couplings' share of the inverse inertia at a point of body i
  /// (X the transfer from the common point to it).
  void correctG(const Matrix6d& X, int i, Matrix6d& G) {
    Y_.noalias() = X * A_.middleCols(static_cast<Eigen::Index>(i) * rows(), rows());
    Z_ = llt_.solve(Y_.transpose());
    G.noalias() -= Y_ * Z_;
  }

 private:
  std::vector<int> m_, l_;          ///< per row: the mimic body and its coordinate's own body
  std::vector<double> armature_;    ///< per body (free system)
  struct Tau {
    int row;
    double sign;
  };
  std::vector<std::vector<Tau>> tau_;  ///< per body: the torque pairs' entries on its joint
  Eigen::MatrixXd A_;               ///< 6 x (k per body): the accelerations of Y's columns (twists)
  Eigen::MatrixXd P_;               ///< 6 x (k per body): scratch, bias forces
  Eigen::MatrixXd Q_;               ///< k x bodies: the joint accelerations of Y's columns
  Eigen::MatrixXd u_;               ///< k x bodies: scratch, tau - S^T p
  Eigen::VectorXd row_;             ///< scratch (k): one body's entries of the k rows
  Eigen::MatrixXd S_;               ///< C M^-1 C^T
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd c_, lambda_;
  Eigen::MatrixXd Y_, Z_;           ///< scratch of correctG: 6 x k, k x 6
};

}  // namespace kdl_space::detail
