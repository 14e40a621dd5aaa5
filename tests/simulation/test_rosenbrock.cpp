// RODAS3 (src/detail/rosenbrock): stiff accuracy and L-stability (Prothero-Robinson), the
// order of convergence and of the error estimate against closed-form solutions, an adaptive run
// through a stiff transient, and the return codes of a failing right-hand side.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "simulation/rosenbrock.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::test {
namespace {

using detail::RosenbrockStepper;
using Eigen::VectorXd;
using Rhs = RosenbrockStepper::Rhs;

/// x(t_end) by n fixed steps of size (t_end - t0)/n; accuracy-free tolerances (error unused).
VectorXd fixedSteps(const Rhs& f, double t0, double t_end, VectorXd x, int n) {
  RosenbrockStepper stepper(static_cast<int>(x.size()));
  VectorXd x_new(x.size());
  const double h = (t_end - t0) / n;
  double error;
  for (int k = 0; k < n; ++k) {
    EXPECT_EQ(stepper.step(f, t0 + k * h, h, x, x_new, error, 1e-6, 1e-6), E_NOERROR);
    x = x_new;
  }
  return x;
}

/// The observed orders log2(e(h) / e(h/2)) of successive halvings.
std::vector<double> observedOrders(const std::vector<double>& errors) {
  std::vector<double> p;
  for (size_t k = 0; k + 1 < errors.size(); ++k) p.push_back(std::log2(errors[k] / errors[k + 1]));
  return p;
}

// y' = -2 t y^2, y(0) = 1: y = 1/(1 + t^2). Nonlinear and non-autonomous (the df/dt term counts).
const Rhs kRational = [](double t, const VectorXd& y, VectorXd& dy) {
  dy(0) = -2.0 * t * y(0) * y(0);
  return 0;
};
double rational(double t) { return 1.0 / (1.0 + t * t); }

// Prothero-Robinson: y' = lambda (y - phi(t)) + phi'(t), phi = sin; y = sin t from y(0) = 0.
constexpr double kLambda = -1e6;
const Rhs kProtheroRobinson = [](double t, const VectorXd& y, VectorXd& dy) {
  dy(0) = kLambda * (y(0) - std::sin(t)) + std::cos(t);
  return 0;
};

TEST(Rosenbrock, ProtheroRobinsonStaysOnTheSmoothSolution) {
  // h lambda = -1e4: an explicit method's amplification (|1 + h lambda| = 9999 for Euler, alike
  // for dopri5) would blow up; an L-stable method follows phi. In the stiff limit the error of a
  // stiffly accurate Rosenbrock method is set by its stage order (1), not by its order 3: it is
  // C h^2 |phi''| / |h lambda| = C h / |lambda| with C of order one (0.28 measured, and linear in
  // h and 1/|lambda| from 1e4 to 1e7), so below h / |lambda| = 1e-8.
  const double h = 0.01;
  RosenbrockStepper stepper(1);
  VectorXd y = VectorXd::Zero(1), y_new(1);
  double max_error = 0.0, error;
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(stepper.step(kProtheroRobinson, k * h, h, y, y_new, error, 1e-6, 1e-9), E_NOERROR);
    y = y_new;
    max_error = std::max(max_error, std::abs(y(0) - std::sin((k + 1) * h)));
  }
  EXPECT_LT(max_error, h / std::abs(kLambda));
}

TEST(Rosenbrock, AStiffModeIsDampedInOneStep) {
  // L-stability: R(h lambda) -> 0 as h lambda -> -inf. Starting 1 off phi, the deviation after one
  // step of h lambda = -1e4 is |R(-1e4)| (~1/|h lambda| or smaller) plus the smooth error; an
  // A-stable method with |R(-inf)| = 1 (the trapezoidal rule) would keep the whole deviation.
  RosenbrockStepper stepper(1);
  VectorXd y = VectorXd::Constant(1, 1.0), y_new(1);
  double error;
  ASSERT_EQ(stepper.step(kProtheroRobinson, 0.0, 0.01, y, y_new, error, 1e-6, 1e-9), E_NOERROR);
  EXPECT_LT(std::abs(y_new(0) - std::sin(0.01)), 1e-3);
}

TEST(Rosenbrock, ConvergesWithOrderThree) {
  // Global errors at t = 2 for h = 0.1, 0.05, 0.025, 0.0125: each halving divides them by ~2^3.
  std::vector<double> nonlinear, rotation;
  // A damped rotation x' = A x, A = [-0.5 2; -2 -0.5]: x(t) = e^{-t/2} R(-2t) x(0).
  Eigen::Matrix2d A;
  A << -0.5, 2.0, -2.0, -0.5;
  const Rhs linear = [&A](double, const VectorXd& x, VectorXd& dx) {
    dx.noalias() = A * x;
    return 0;
  };
  const VectorXd x0 = Eigen::Vector2d(1.0, 0.5);
  const double c = std::cos(4.0), s = std::sin(4.0), decay = std::exp(-1.0);
  const VectorXd exact = decay * Eigen::Vector2d(c * x0(0) + s * x0(1), -s * x0(0) + c * x0(1));
  for (int n : {20, 40, 80, 160}) {
    nonlinear.push_back(std::abs(fixedSteps(kRational, 0.0, 2.0, VectorXd::Ones(1), n)(0) - rational(2.0)));
    rotation.push_back((fixedSteps(linear, 0.0, 2.0, x0, n) - exact).norm());
  }
  for (const auto* errors : {&nonlinear, &rotation})
    for (double p : observedOrders(*errors)) EXPECT_NEAR(p, RosenbrockStepper::order, 0.3);
}

TEST(Rosenbrock, ErrorEstimateHasTheEmbeddedOrder) {
  // One step from y(0.5) of y' = -2ty^2: the estimate (x_new minus the order-2 solution, atol = 1,
  // rtol = 0: its plain size) is O(h^{p^+1}) = O(h^3); the true local error of x_new is O(h^4) and
  // smaller than the estimate (the estimate is conservative for the solution it accompanies).
  std::vector<double> estimates, local_errors;
  RosenbrockStepper stepper(1);
  const VectorXd y = VectorXd::Constant(1, rational(0.5));
  VectorXd y_new(1);
  for (double h : {0.02, 0.01, 0.005, 0.0025}) {
    double error;
    ASSERT_EQ(stepper.step(kRational, 0.5, h, y, y_new, error, 0.0, 1.0), E_NOERROR);
    estimates.push_back(error);
    local_errors.push_back(std::abs(y_new(0) - rational(0.5 + h)));
    EXPECT_LT(local_errors.back(), error);
  }
  for (double p : observedOrders(estimates)) EXPECT_NEAR(p, RosenbrockStepper::embedded_order + 1, 0.3);
  for (double p : observedOrders(local_errors)) EXPECT_NEAR(p, RosenbrockStepper::order + 1, 0.3);
}

TEST(Rosenbrock, AdaptiveRunThroughAStiffTransient) {
  // x' = A x with eigenvalues -1 and -1e5: A = V diag(-1, -1e5) V^-1, V = [1 1; 0 1], so that
  // x(t) = V (e^{-t}, e^{-1e5 t}) for x(0) = V (1, 1) = (2, 1). An explicit method is held to
  // h < ~3/1e5 by the fast mode long after it has decayed: > 3e5 steps to t = 10.
  Eigen::Matrix2d A;
  A << -1.0, 1.0 - 1e5, 0.0, -1e5;
  const Rhs f = [&A](double, const VectorXd& x, VectorXd& dx) {
    dx.noalias() = A * x;
    return 0;
  };
  const auto exact = [](double t) {
    const double slow = std::exp(-t), fast = std::exp(-1e5 * t);
    return Eigen::Vector2d(slow + fast, fast);
  };
  const double rtol = 1e-5, atol = 1e-10, t_end = 10.0;
  RosenbrockStepper stepper(2);
  VectorXd x = Eigen::Vector2d(2.0, 1.0), x_new(2);
  double t = 0.0, h = 1e-7, max_error = 0.0;
  int steps = 0;
  while (t < t_end && steps < 10000) {
    const double h_try = std::min(h, t_end - t);
    double error;
    ASSERT_EQ(stepper.step(f, t, h_try, x, x_new, error, rtol, atol), E_NOERROR);
    ++steps;
    // The standard controller with the estimate's order p^ = 2: exponent -1/(p^ + 1).
    const double factor = error == 0.0 ? 5.0 : std::clamp(0.9 * std::pow(error, -1.0 / (RosenbrockStepper::embedded_order + 1)), 0.2, 5.0);
    h = h_try * factor;
    if (error > 1.0) continue;
    t = t_end - t < h_try * (1 + 1e-12) ? t_end : t + h_try;
    x = x_new;
    // Global error relative to the solution's own scale (atol below e^{-10}: relative throughout).
    const Eigen::Vector2d e = exact(t);
    max_error = std::max(max_error, (x - e).cwiseAbs().maxCoeff() / (atol + rtol * e.cwiseAbs().maxCoeff()));
  }
  EXPECT_EQ(t, t_end);
  EXPECT_LT(steps, 500);       // 373: 153 through the transient (t < 1e-4), 220 for the slow mode
  EXPECT_LT(max_error, 10.0);  // within ~10 rtol of the exact solution all along (4.8 rtol)
  EXPECT_NEAR(stepper.spectralRadiusEstimate(), 1e5, 1e5 * 1e-3);
}

TEST(Rosenbrock, EvaluationsPerStepAndSpectralRadius) {
  // n columns + df/dt + three stages (stage 2 reuses f(t, x)).
  const double w = 3.0;
  const Rhs rotation = [w](double, const VectorXd& x, VectorXd& dx) {
    dx(0) = w * x(1), dx(1) = -w * x(0);
    return 0;
  };
  RosenbrockStepper stepper(2);
  EXPECT_EQ(stepper.spectralRadiusEstimate(), 0.0);  // no Jacobian yet
  VectorXd x = Eigen::Vector2d(1.0, 0.0), x_new(2);
  double error;
  ASSERT_EQ(stepper.step(rotation, 0.0, 0.1, x, x_new, error, 1e-6, 1e-6), E_NOERROR);
  EXPECT_EQ(stepper.rhsEvaluations(), 2 + 4);
  ASSERT_EQ(stepper.step(rotation, 0.1, 0.1, x_new, x, error, 1e-6, 1e-6), E_NOERROR);
  EXPECT_EQ(stepper.rhsEvaluations(), 2 * (2 + 4));
  // J = w [0 1; -1 0]: |J v| = w |v| for every v (eigenvalues +-i w).
  EXPECT_NEAR(stepper.spectralRadiusEstimate(), w, w * 1e-6);
  EXPECT_NEAR(stepper.jacobian()(0, 1), w, 1e-6);
}

TEST(Rosenbrock, AFailingRightHandSideGivesItsCode) {
  // Fail at the k-th evaluation: the base point, a Jacobian column, df/dt, stage 3, stage 4.
  const int n = 3;
  for (int fail_at : {1, 2, n + 1, n + 2, n + 3, n + 4}) {
    int calls = 0;
    const Rhs f = [&calls, fail_at](double, const VectorXd& x, VectorXd& dx) {
      if (++calls == fail_at) return -42;
      dx = -x;
      return 0;
    };
    RosenbrockStepper stepper(n);
    VectorXd x = VectorXd::Ones(n), x_new(n);
    double error;
    EXPECT_EQ(stepper.step(f, 0.0, 0.1, x, x_new, error, 1e-6, 1e-6), -42) << "failing at call " << fail_at;
    EXPECT_EQ(calls, fail_at);  // nothing evaluated after the failure
  }
}

TEST(Rosenbrock, NotFiniteResultsAndBadArguments) {
  const int n = 2;
  RosenbrockStepper stepper(n);
  VectorXd x = VectorXd::Ones(n), x_new(n), wrong(n + 1);
  double error;
  // NaN from f, everywhere or in stage 4 only (t = 1 is stage 3's and 4's time, alpha = 1).
  const Rhs nan_everywhere = [](double, const VectorXd&, VectorXd& dx) {
    dx.setConstant(std::nan(""));
    return 0;
  };
  const Rhs nan_late = [](double t, const VectorXd& x, VectorXd& dx) {
    dx = t >= 1.0 ? VectorXd::Constant(x.size(), std::nan("")) : VectorXd(-x);
    return 0;
  };
  EXPECT_EQ(stepper.step(nan_everywhere, 0.0, 0.1, x, x_new, error, 1e-6, 1e-6), E_NOT_FINITE);
  EXPECT_EQ(stepper.step(nan_late, 0.0, 1.0, x, x_new, error, 1e-6, 1e-6), E_NOT_FINITE);
  // A singular W = I/(gamma h) - J: f = 4 x with gamma h = 0.25 (the differences exact in binary).
  const Rhs singular = [](double, const VectorXd& x, VectorXd& dx) {
    dx = 4.0 * x;
    return 0;
  };
  EXPECT_EQ(stepper.step(singular, 0.0, 0.5, x, x_new, error, 1e-6, 1e-6), E_NOT_FINITE);
  // An f that resizes dx.
  const Rhs resizing = [](double, const VectorXd& x, VectorXd& dx) {
    dx = VectorXd::Zero(x.size() + 1);
    return 0;
  };
  const Rhs decay = [](double, const VectorXd& x, VectorXd& dx) {
    dx = -x;
    return 0;
  };
  EXPECT_EQ(stepper.step(resizing, 0.0, 0.1, x, x_new, error, 1e-6, 1e-6), E_SIZE_MISMATCH);
  EXPECT_EQ(stepper.step(decay, 0.0, 0.1, wrong, x_new, error, 1e-6, 1e-6), E_SIZE_MISMATCH);
  EXPECT_EQ(stepper.step(decay, 0.0, 0.1, x, wrong, error, 1e-6, 1e-6), E_SIZE_MISMATCH);
  for (double h : {0.0, -0.1}) EXPECT_EQ(stepper.step(decay, 0.0, h, x, x_new, error, 1e-6, 1e-6), E_BAD_ARGUMENT);
  EXPECT_EQ(stepper.step(decay, 0.0, 0.1, x, x_new, error, 0.0, 0.0), E_BAD_ARGUMENT);
  EXPECT_EQ(stepper.step(decay, 0.0, 0.1, x, x_new, error, -1e-6, 1e-6), E_BAD_ARGUMENT);
  EXPECT_EQ(stepper.step(decay, std::nan(""), 0.1, x, x_new, error, 1e-6, 1e-6), E_NOT_FINITE);
  EXPECT_EQ(stepper.step(decay, 0.0, INFINITY, x, x_new, error, 1e-6, 1e-6), E_NOT_FINITE);
  EXPECT_EQ(stepper.step(decay, 0.0, 0.1, VectorXd::Constant(n, INFINITY), x_new, error, 1e-6, 1e-6), E_NOT_FINITE);
  // And the stepper still works after all that.
  ASSERT_EQ(stepper.step(decay, 0.0, 0.1, x, x_new, error, 1e-6, 1e-6), E_NOERROR);
  EXPECT_NEAR(x_new(0), std::exp(-0.1), 1e-5);
  EXPECT_THROW(RosenbrockStepper(0), ModelError);
}

}  // namespace
}  // namespace kdl_space::test
