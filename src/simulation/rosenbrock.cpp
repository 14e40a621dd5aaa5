// RODAS3 (Sandu et al. 1997): one step with its embedded error estimate. See rosenbrock.hpp for
// the method's equations and the finite-difference Jacobian.
#include "simulation/rosenbrock.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::detail {
namespace {

constexpr int kStages = 4;
// RODAS3's coefficients in the transformed form (Sandu et al. 1997, Table 4; Hairer & Wanner's
// a_ij, c_ij, m_i): gamma, the stage times alpha_i, gamma_i = sum_j gamma_ij (the df/dt weights),
// the strictly lower triangular A and C, the solution's weights m and the estimate's weights e.
constexpr double kGamma = 0.5;
constexpr double kAlpha[kStages] = {0.0, 0.0, 1.0, 1.0};
constexpr double kGammaSum[kStages] = {0.5, 1.5, 0.0, 0.0};
constexpr double kRodasA[kStages][kStages] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {2, 0, 0, 0}, {2, 0, 1, 0}};
constexpr double kRodasC[kStages][kStages] = {
    {0, 0, 0, 0}, {4, 0, 0, 0}, {1, -1, 0, 0}, {1, -1, -8.0 / 3.0, 0}};
constexpr double kM[kStages] = {2, 0, 1, 1};
constexpr double kE[kStages] = {0, 0, 0, 1};
// Stage 2 evaluates f where stage 1 does (alpha_2 = alpha_1, a_21 = 0): f(t, x) is reused.
constexpr bool kNewF[kStages] = {true, false, true, true};

const double kSqrtEps = std::sqrt(std::numeric_limits<double>::epsilon());

}  // namespace

RosenbrockStepper::RosenbrockStepper(int size) {
  if (size < 1) throw ModelError("RosenbrockStepper: a state of " + std::to_string(size) + " numbers");
  const Eigen::Index n = size;
  f0_.setZero(n);
  f_pert_.setZero(n);
  dfdt_.setZero(n);
  x_pert_.setZero(n);
  y_.setZero(n);
  rhs_.setZero(n);
  K_.setZero(n, kStages);
  J_.setZero(n, n);
  W_.setZero(n, n);
  lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  power_.setZero(n);
  power_next_.setZero(n);
}

int RosenbrockStepper::evaluate(const Rhs& f, double t, const Eigen::VectorXd& x, Eigen::VectorXd& dx) {
  ++rhs_evaluations_;
  if (const int rc = f(t, x, dx)) return rc;
  return dx.size() == x.size() ? E_NOERROR : E_SIZE_MISMATCH;
}

int RosenbrockStepper::step(const Rhs& f, double t, double h, const Eigen::VectorXd& x,
                            Eigen::VectorXd& x_new, double& error, double rtol, double atol) {
  const Eigen::Index n = x_pert_.size();
  if (x.size() != n || x_new.size() != n) return E_SIZE_MISMATCH;
  if (!std::isfinite(t) || !std::isfinite(h) || !x.allFinite() || std::isnan(rtol) || std::isnan(atol))
    return E_NOT_FINITE;
  if (!(h > 0.0) || rtol < 0.0 || atol < 0.0 || rtol + atol == 0.0) return E_BAD_ARGUMENT;

  // The Jacobian at (t, x), column by column (forward differences; the increment is the
  // representable difference (x_j + d) - x_j, so that the quotient divides by the step taken).
  if (const int rc = evaluate(f, t, x, f0_)) return rc;
  x_pert_ = x;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double xj = x(j);
    x_pert_(j) = xj + kSqrtEps * std::max(std::abs(xj), 1.0);
    const double d = x_pert_(j) - xj;
    if (const int rc = evaluate(f, t, x_pert_, f_pert_)) return rc;
    J_.col(j) = (f_pert_ - f0_) / d;
    x_pert_(j) = xj;
  }
  {
    const double t_pert = t + kSqrtEps * std::max(std::abs(t), 1.0);
    const double dt = t_pert - t;
    if (const int rc = evaluate(f, t_pert, x, f_pert_)) return rc;
    dfdt_ = (f_pert_ - f0_) / dt;
  }

  // W = I/(gamma h) - J, factorised once for the four stages. A singular W leaves infinities or
  // NaN in the stages, caught by the finiteness check at the end.
  W_ = -J_;
  W_.diagonal().array() += 1.0 / (kGamma * h);
  lu_.compute(W_);

  for (int i = 0; i < kStages; ++i) {
    if (i == 0 || !kNewF[i]) {
      rhs_ = f0_;  // stage 1 at (t, x), and stage 2 where stage 1 is
    } else {
      y_ = x;
      for (int j = 0; j < i; ++j)
        if (kRodasA[i][j] != 0.0) y_ += kRodasA[i][j] * K_.col(j);
      if (const int rc = evaluate(f, t + kAlpha[i] * h, y_, rhs_)) return rc;
    }
    for (int j = 0; j < i; ++j)
      if (kRodasC[i][j] != 0.0) rhs_ += (kRodasC[i][j] / h) * K_.col(j);
    if (kGammaSum[i] != 0.0) rhs_ += (kGammaSum[i] * h) * dfdt_;
    K_.col(i).noalias() = lu_.solve(rhs_);
  }

  // x_new and the estimate err = sum e_i K_i (kept in y_), scaled as DOPRI5 scales it (simulation/steppers).
  x_new = x;
  y_.setZero();
  for (int i = 0; i < kStages; ++i) {
    if (kM[i] != 0.0) x_new += kM[i] * K_.col(i);
    if (kE[i] != 0.0) y_ += kE[i] * K_.col(i);
  }
  double sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double scale = atol + rtol * std::max(std::abs(x(i)), std::abs(x_new(i)));
    sum += (y_(i) / scale) * (y_(i) / scale);
  }
  error = std::sqrt(sum / static_cast<double>(n));
  return std::isfinite(error) && x_new.allFinite() ? E_NOERROR : E_NOT_FINITE;
}

double RosenbrockStepper::spectralRadiusEstimate() {
  // Power iteration v <- J v / |J v| from a start with no special direction (all components
  // nonzero and distinct, so not orthogonal to an eigenvector of a structured J by accident);
  // |J v| after the last iteration is the estimate.
  constexpr int kIterations = 30;
  const Eigen::Index n = J_.rows();
  for (Eigen::Index i = 0; i < n; ++i)
    power_(i) = 1.0 + 0.37 * static_cast<double>(i % 7) - 0.11 * static_cast<double>(i % 3);
  power_.normalize();
  double radius = 0.0;
  for (int k = 0; k < kIterations; ++k) {
    power_next_.noalias() = J_ * power_;
    radius = power_next_.norm();
    if (!(radius > 0.0) || !std::isfinite(radius)) return 0.0;  // J v = 0, or J not finite
    power_ = power_next_ / radius;
  }
  return radius;
}

}  // namespace kdl_space::detail
