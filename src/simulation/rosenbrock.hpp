// One step of a linearly implicit (Rosenbrock) method with an embedded error estimate: the
// simulator's integrator for stiff servos (PD gains on light links), where an explicit method's
// step is bounded by the fastest mode rather than by the accuracy asked for.
//
// Method: RODAS3, Sandu, Verwer, Blom, Spee, Carmichael & Potra, "Benchmarking stiff ODE solvers
// for atmospheric chemistry problems II: Rosenbrock solvers", Atmospheric Environment 31(20),
// 3459-3472 (1997). Four stages (three evaluations of f: stage 2 sits where stage 1 does), order
// 3, embedded order 2; L-stable and stiffly accurate (the solution is the last stage, so R(inf) = 0:
// a mode far faster than the step is damped out, not carried along). Written in the transformed
// variables of Hairer & Wanner, "Solving ODEs II", sec. IV.7 (eq. 7.25), with W = I/(gamma h) - J:
//
//   Y_i   = x + sum_{j<i} a_ij K_j,                          t_i = t + alpha_i h
//   W K_i = f(t_i, Y_i) + sum_{j<i} (c_ij / h) K_j + gamma_i h df/dt(t, x)
//   x_new = x + sum_i m_i K_i,    err = sum_i e_i K_i   (= K_4: x_new minus the order-2 Y_4)
//
// Non-autonomous f: the gamma_i h df/dt term is the method's own (it makes the time a state
// whose Jacobian column is df/dt); df/dt is a forward difference in t (below).
//
// Jacobian: forward differences column by column, once per step at (t, x):
//   J e_j = (f(t, x + d_j e_j) - f(t, x)) / d_j,   d_j = sqrt(eps) max(|x_j|, 1)
// (d_j rounded to a representable increment of x_j), and df/dt the same with d_t = sqrt(eps)
// max(|t|, 1). A step costs n + 4 evaluations of f (n columns, df/dt, three stages) and one LU
// factorisation of W (Eigen::PartialPivLU). RODAS3 is not a W-method: the order holds for the
// Jacobian at (t, x), which the O(sqrt(eps)) differences approximate far below any tolerance used.
//
// A private detail of the library: compute calls return codes (kdl_space/spatial/errors.hpp), never
// throw, never print, and allocate nothing after the constructor.
#pragma once

#include <Eigen/Dense>
#include <functional>

namespace kdl_space::detail {

class RosenbrockStepper {
 public:
  /// The right-hand side x' = f(t, x): writes dx (of x's size; it must not resize it) and returns
  /// 0, or an error code that step() passes on.
  using Rhs = std::function<int(double t, const Eigen::VectorXd& x, Eigen::VectorXd& dx)>;

  static constexpr int order = 3;           ///< of x_new (local error O(h^4))
  static constexpr int embedded_order = 2;  ///< of the embedded solution: `error` is O(h^3), so a
                                            ///< step-size controller uses the exponent 1/3

  /// Workspaces for states of `size` numbers (size >= 1; throws ModelError otherwise).
  explicit RosenbrockStepper(int size);

  int size() const { return static_cast<int>(x_pert_.size()); }

  /// One step of size h > 0 from (t, x): x_new and the error estimate
  ///   error = sqrt(mean_i (err_i / (atol + rtol max(|x_i|, |x_new_i|)))^2),
  /// the scaled RMS norm of the simulator's DOPRI5 (simulation/steppers); acceptable when error <= 1.
  /// Returns 0; E_SIZE_MISMATCH (x or x_new not of size(), or f resized dx); E_BAD_ARGUMENT
  /// (h <= 0, rtol or atol < 0, or both 0); E_NOT_FINITE (t, h or x not finite, or a result that
  /// is not, e.g. from a singular W); or the first nonzero code of f. On an error x_new and error
  /// are unspecified (the caller rejects the step).
  int step(const Rhs& f, double t, double h, const Eigen::VectorXd& x, Eigen::VectorXd& x_new,
           double& error, double rtol, double atol);

  /// Evaluations of f since construction (n + 4 per complete step).
  long rhsEvaluations() const { return rhs_evaluations_; }

  /// The Jacobian df/dx at the last step's (t, x) (zero before the first step; partly updated if f
  /// failed while it was computed).
  const Eigen::MatrixXd& jacobian() const { return J_; }

  /// An estimate of the spectral radius of jacobian() (the rate of the fastest mode, 1/s) by a few
  /// power iterations: |lambda_max| for a diagonalisable J whose largest eigenvalue is separated;
  /// within a small factor otherwise (a complex pair, a non-normal J). Compare with 1/h for "the
  /// fastest mode vs the step". 0 before the first Jacobian or for a non-finite one.
  double spectralRadiusEstimate();

 private:
  int evaluate(const Rhs& f, double t, const Eigen::VectorXd& x, Eigen::VectorXd& dx);

  Eigen::VectorXd f0_;      // f(t, x): the Jacobian's base point and stage 1
  Eigen::VectorXd f_pert_;  // f at a perturbed point
  Eigen::VectorXd dfdt_;
  Eigen::VectorXd x_pert_;  // x with one coordinate perturbed
  Eigen::VectorXd y_;       // a stage's state Y_i
  Eigen::VectorXd rhs_;     // a stage's right-hand side
  Eigen::MatrixXd K_;       // the stage increments K_i, one column each
  Eigen::MatrixXd J_;
  Eigen::MatrixXd W_;       // I/(gamma h) - J
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd power_, power_next_;  // spectralRadiusEstimate's iterates
  long rhs_evaluations_ = 0;
};

}  // namespace kdl_space::detail
