// The simulator's three methods, each a Stepper: RK4, Dormand-Prince 5(4) and RODAS3
// (detail/rosenbrock.hpp), on the same x' = f(t, x).
#include "simulation/steppers.hpp"

#include <vector>

#include "simulation/rosenbrock.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space::detail {
namespace {

using Vector = Eigen::VectorXd;

/// Classical fourth-order Runge-Kutta, fixed step.
class Rk4 final : public Stepper {
 public:
  Rk4(Derivative& f, int size) : Stepper(0.0), f_(f), k_(4, Vector::Zero(size)), x_stage_(Vector::Zero(size)) {}

  int step(double t, double h, const Vector& x, Vector& x_new, double& error, bool& trial_failed) override {
    error = 0.0;
    trial_failed = false;  // a fixed step cannot be retried smaller: every failure is the run's
    if (int rc = f_.f(t, x, k_[0])) return rc;
    x_stage_ = x + 0.5 * h * k_[0];
    if (int rc = f_.f(t + 0.5 * h, x_stage_, k_[1])) return rc;
    x_stage_ = x + 0.5 * h * k_[1];
    if (int rc = f_.f(t + 0.5 * h, x_stage_, k_[2])) return rc;
    x_stage_ = x + h * k_[2];
    if (int rc = f_.f(t + h, x_stage_, k_[3])) return rc;
    x_new = x + h / 6.0 * (k_[0] + 2.0 * k_[1] + 2.0 * k_[2] + k_[3]);
    return E_NOERROR;
  }

 private:
  Derivative& f_;
  std::vector<Vector> k_;
  Vector x_stage_;
};

// Dormand & Prince (1980) RK5(4)7M tableau: c, A, the fifth-order weights b5 (the solution: local
// extrapolation) and the fourth-order b4 (the estimate is their difference).
constexpr double kDopriC[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
constexpr double kDopriA[7][6] = {
    {},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
constexpr double kB5[7] = {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0.0};
constexpr double kB4[7] = {5179.0 / 57600, 0.0, 7571.0 / 16695, 393.0 / 640, -92097.0 / 339200, 187.0 / 2100, 1.0 / 40};

/// Dormand-Prince 5(4): the estimate's order is 4, so the step factor's exponent is -1/5.
class Dopri5 final : public Stepper {
 public:
  Dopri5(Derivative& f, int size, const ErrorControl& control)
      : Stepper(-0.2), f_(f), control_(control), k_(7, Vector::Zero(size)), x_stage_(Vector::Zero(size)) {}

  int step(double t, double h, const Vector& x, Vector& x_new, double& error, bool& trial_failed) override {
    trial_failed = false;
    for (int i = 0; i < 7; ++i) {
      x_stage_ = x;
      for (int j = 0; j < i; ++j) x_stage_ += h * kDopriA[i][j] * k_[j];
      if (int rc = f_.f(t + kDopriC[i] * h, x_stage_, k_[i])) {
        trial_failed = i > 0;  // a stage away from x: a smaller step may not reach that state
        return rc;
      }
    }
    x_new = x;
    x_stage_.setZero();  // the error estimate
    for (int i = 0; i < 7; ++i) {
      x_new += h * kB5[i] * k_[i];
      x_stage_ += h * (kB5[i] - kB4[i]) * k_[i];
    }
    error = errorNorm(x, x_new, x_stage_);
    trial_failed = !std::isfinite(error);
    return trial_failed ? E_NOT_FINITE : E_NOERROR;
  }

 private:
  /// sqrt(mean_i (err_i / (atol + rtol max(|x_i|, |x_new_i|)))^2) over the controlled components.
  double errorNorm(const Vector& x, const Vector& x_new, const Vector& err) const {
    const Eigen::Index size = control_.components;
    double sum = 0.0;
    for (Eigen::Index i = 0; i < size; ++i) {
      const double scale = control_.atol + control_.rtol * std::max(std::abs(x(i)), std::abs(x_new(i)));
      sum += (err(i) / scale) * (err(i) / scale);
    }
    return std::sqrt(sum / static_cast<double>(size));
  }

  Derivative& f_;
  ErrorControl control_;
  std::vector<Vector> k_;
  Vector x_stage_;  ///< a stage's state; after the stages, the error estimate
};

/// RODAS3, linearly implicit (stiff servos): detail::RosenbrockStepper on the simulator's f.
class Rodas3 final : public Stepper {
 public:
  Rodas3(Derivative& f, int size, const ErrorControl& control)
      : Stepper(-1.0 / (RosenbrockStepper::embedded_order + 1)),
        // A lambda holding one pointer is stored inside std::function: no allocation.
        f_([&f](double t, const Vector& x, Vector& dx) { return f.f(t, x, dx); }),
        control_(control),
        method_(size) {}

  int step(double t, double h, const Vector& x, Vector& x_new, double& error, bool& trial_failed) override {
    const int rc = method_.step(f_, t, h, x, x_new, error, control_.rtol, control_.atol);
    // A stage (or a Jacobian column) where the dynamics are undefined: a smaller step may avoid it.
    trial_failed = rc == E_NOT_FINITE || rc == E_NOT_POSITIVE_DEFINITE;
    return rc;
  }

 private:
  RosenbrockStepper::Rhs f_;
  ErrorControl control_;
  RosenbrockStepper method_;
};

}  // namespace

std::unique_ptr<Stepper> makeStepper(Integrator integrator, Derivative& f, int size, const ErrorControl& control) {
  switch (integrator) {
    case Integrator::RK4:
      return std::make_unique<Rk4>(f, size);
    case Integrator::DormandPrince54:
      return std::make_unique<Dopri5>(f, size, control);
    case Integrator::Rosenbrock:
      return std::make_unique<Rodas3>(f, size, control);
  }
  throw ModelError("simulation: the integrator is not one of RK4, DormandPrince54, Rosenbrock");
}

}  // namespace kdl_space::detail
