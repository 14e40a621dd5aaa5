// Private to the simulator: its three time-stepping methods (RK4, DOPRI5, RODAS3) behind one
// interface, so that the run loop and the event location never ask which method runs. A stepper
// sees the equations of motion only as x' = f(t, x) (Derivative, which the simulator provides) and
// owns its workspaces, sized once: a step allocates nothing.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>

#include "kdl_space/simulation/integrator.hpp"

namespace kdl_space::detail {

/// The right-hand side x' = f(t, x): the one thing every stepper asks of the simulator.
class Derivative {
 public:
  /// Writes dx (x's size) and returns 0, or an error code that the step passes on.
  virtual int f(double t, const Eigen::VectorXd& x, Eigen::VectorXd& dx) = 0;

 protected:
  ~Derivative() = default;
};

/// The adaptive methods' error control.
struct ErrorControl {
  double rtol = 0.0, atol = 0.0;  ///< per component: atol + rtol max(|x_i|, |x_new_i|)
  /// DOPRI5's norm counts the leading `components` (the motion's: the work and impulse integrals
  /// that follow do not steer the step); RODAS3's counts every component (detail/rosenbrock).
  int components = 0;
};

class Stepper {
 public:
  virtual ~Stepper() = default;

  /// \brief One step of length h from (t, x) into x_new (not x itself). The adaptive methods give
  /// `error`, the scaled RMS norm of their estimate (acceptable when <= 1); RK4 gives 0.
  /// `trial_failed`: the step reached a state where the dynamics are undefined (a stage away from
  /// x, or the estimate), which a smaller step may avoid: the caller rejects the step instead of
  /// failing. \return 0 or the code of the failure; x_new and error are unspecified then.
  virtual int step(double t, double h, const Eigen::VectorXd& x, Eigen::VectorXd& x_new, double& error,
                   bool& trial_failed) = 0;

  /// The step of length h from (t, x) again, without error control: to locate an event inside an
  /// accepted step.
  int retake(double t, double h, const Eigen::VectorXd& x, Eigen::VectorXd& x_new) {
    double error = 0.0;
    bool trial_failed = false;
    return step(t, h, x, x_new, error, trial_failed);
  }

  /// Whether the step size follows the error (RK4 takes the step it is given).
  bool adaptive() const { return exponent_ < 0.0; }
  /// The next step's factor after an error: 0.9 error^(-1/(p+1)), p the order of the estimate's
  /// embedded solution, clamped to [0.2, 5] (5 for a zero error).
  double stepFactor(double error) const {
    return error == 0.0 ? 5.0 : std::clamp(0.9 * std::pow(error, exponent_), 0.2, 5.0);
  }

 protected:
  /// error_exponent: -1/(p+1), or 0 for a fixed step.
  explicit Stepper(double error_exponent) : exponent_(error_exponent) {}

 private:
  double exponent_;
};

/// The stepper of `integrator` for states of `size` numbers, evaluating f. \throws ModelError for
/// an integrator that is no enumerator.
std::unique_ptr<Stepper> makeStepper(Integrator integrator, Derivative& f, int size, const ErrorControl& control);

}  // namespace kdl_space::detail
