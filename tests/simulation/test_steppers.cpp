// The simulator's steppers (src/simulation/steppers: private) through their one interface: each
// method's order on a closed form, the adaptive methods' estimate and step factor, retake as the
// step itself, a failing f; and the integrators' names (integrator.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "kdl_space/simulation/integrator.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "simulation/steppers.hpp"

namespace kdl_space::test {
namespace {

using Eigen::VectorXd;

/// x' = (x1, -x0 + t): a rotation driven by the time (non-autonomous), from x(0) = (1, 0):
/// x0 = t + cos t - sin t, x1 = 1 - sin t - cos t. `fail_at`: the evaluation that returns -42.
struct Rotation final : detail::Derivative {
  int f(double t, const VectorXd& x, VectorXd& dx) override {
    if (++calls == fail_at) return -42;
    dx(0) = x(1);
    dx(1) = -x(0) + t;
    return 0;
  }
  static VectorXd exact(double t) {
    VectorXd x(2);
    x << t + std::cos(t) - std::sin(t), 1.0 - std::sin(t) - std::cos(t);
    return x;
  }
  long calls = 0, fail_at = -1;
};

const detail::ErrorControl kControl{1e-6, 1e-6, 2};

/// |x(1) - exact| after n fixed steps of `integrator`.
double globalError(Integrator integrator, int n) {
  Rotation f;
  const auto stepper = detail::makeStepper(integrator, f, 2, kControl);
  VectorXd x = Rotation::exact(0.0), x_new(2);
  const double h = 1.0 / n;
  double error = 0.0;
  bool trial_failed = true;
  for (int k = 0; k < n; ++k) {
    EXPECT_EQ(stepper->step(k * h, h, x, x_new, error, trial_failed), 0);
    EXPECT_FALSE(trial_failed);
    x = x_new;
  }
  return (x - Rotation::exact(1.0)).norm();
}

TEST(Steppers, EachMethodHasItsOrder) {
  const struct {
    Integrator integrator;
    double order;
  } cases[] = {{Integrator::RK4, 4.0}, {Integrator::DormandPrince54, 5.0}, {Integrator::Rosenbrock, 3.0}};
  for (const auto& c : cases) {
    SCOPED_TRACE(toString(c.integrator));
    const double e1 = globalError(c.integrator, 8), e2 = globalError(c.integrator, 16);
    EXPECT_NEAR(std::log2(e1 / e2), c.order, 0.35);
  }
}

TEST(Steppers, AdaptiveMethodsEstimateTheirErrorAndRetakeIsTheStep) {
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54, Integrator::Rosenbrock}) {
    SCOPED_TRACE(toString(integrator));
    Rotation f;
    const auto stepper = detail::makeStepper(integrator, f, 2, detail::ErrorControl{1e-4, 1e-4, 2});
    EXPECT_EQ(stepper->adaptive(), integrator != Integrator::RK4);
    const VectorXd x = Rotation::exact(0.3);
    VectorXd x_new(2), again(2);
    double error = -1.0;
    bool trial_failed = true;
    ASSERT_EQ(stepper->step(0.3, 0.05, x, x_new, error, trial_failed), 0);
    EXPECT_FALSE(trial_failed);
    if (stepper->adaptive()) {
      EXPECT_GT(error, 0.0);
      EXPECT_LT(error, 1.0);  // 0.05 is a small step for 1e-4 on this motion
      EXPECT_GT(stepper->stepFactor(error), 1.0);
      EXPECT_EQ(stepper->stepFactor(1e12), 0.2);
      EXPECT_EQ(stepper->stepFactor(0.0), 5.0);
    } else {
      EXPECT_EQ(error, 0.0);
    }
    ASSERT_EQ(stepper->retake(0.3, 0.05, x, again), 0);
    EXPECT_EQ(again, x_new);  // bit for bit: the event location replays the accepted step
  }
}

TEST(Steppers, AFailingDerivativeIsPassedOnAndAStageAwayFromXIsATrialThatFailed) {
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54}) {
    SCOPED_TRACE(toString(integrator));
    for (long fail_at : {1L, 2L}) {
      Rotation f;
      f.fail_at = fail_at;
      const auto stepper = detail::makeStepper(integrator, f, 2, kControl);
      VectorXd x = Rotation::exact(0.0), x_new(2);
      double error = 0.0;
      bool trial_failed = false;
      EXPECT_EQ(stepper->step(0.0, 0.1, x, x_new, error, trial_failed), -42);
      // At x itself no smaller step helps; a later stage is away from x (RK4's step is fixed).
      EXPECT_EQ(trial_failed, integrator == Integrator::DormandPrince54 && fail_at > 1);
    }
  }
}

TEST(Integrators, NamesBothWays) {
  for (Integrator integrator : {Integrator::RK4, Integrator::DormandPrince54, Integrator::Rosenbrock})
    EXPECT_EQ(integratorFromName(toString(integrator)), integrator);
  EXPECT_STREQ(toString(Integrator::RK4), "rk4");
  EXPECT_STREQ(toString(Integrator::DormandPrince54), "dopri5");
  EXPECT_STREQ(toString(Integrator::Rosenbrock), "rosenbrock");
  for (const std::string& bad : {std::string("euler"), std::string("RK4"), std::string(""), std::string("rk4 ")}) {
    try {
      integratorFromName(bad);
      ADD_FAILURE() << "'" << bad << "' was read";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), "'" + bad + "' is not one of rk4, dopri5, rosenbrock");
    }
  }
}

}  // namespace
}  // namespace kdl_space::test
