#include "impact/impact_friction.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace kdl_space::friction {
namespace {

/// \brief Frictional point impact by Routh's method in impulse space with Stronge's energetic
/// restitution (W. J. Stronge, Impact Mechanics, Cambridge 2000, ch. 5; Stronge, Proc. R. Soc.
/// Lond. A 431 (1990) 169-181).
///
/// The normal impulse p is the independent variable; the relative velocity u = v_A - v_B moves
/// by du = -W dP with dP = (n + mu u_t/|u_t|) dp while A slides over B (Coulomb: friction on A
/// opposes its slip), dP = (n + tau) dp with |tau| <= mu while it sticks, and slip restarts in
/// the direction in which sliding is consistent when sticking would need |tau| > mu. Compression
/// ends when u_n = 0; restitution ends when the normal impulse has given back e^2 of the work it
/// absorbed in compression. Every increment lies in the friction cone and energy can only be lost.
class SlipProcessSolver {
 public:
  SlipProcessSolver(const Matrix3d& W, const Vector3d& n, double mu, double e) : W_(W), n_(n), mu_(mu), e_(e) {}

  SlipProcess solve(const Vector3d& u0) {
    State y{u0, Vector3d::Zero(), 0.0};
    const double scale = u0.norm();
    eps_ = 1e-13 * scale;
    bool compression = true;
    double absorbed = 0.0;  // work of the normal impulse in compression
    for (int step = 0; step < kMaxSteps; ++step) {
      const Vector3d u_t = tangential(y.u);
      // Slip below the round-off of u_t = u - (n.u) n is no slip.
      if (u_t.norm() <= eps_ + kRoundOff * y.u.norm()) {
        y.u -= u_t;  // exactly on the stick manifold
        Vector3d tau;
        if (stickImpulseRate(tau)) {
          // Sticking: constant direction d = n + tau, u_n falls linearly at rate b.
          const Vector3d d = n_ + tau;
          const double b = n_.dot(W_ * d), un = n_.dot(y.u);
          if (!(b > 0.0)) break;  // jam: cannot happen for W positive definite and |tau| <= mu
          if (compression) {
            absorbed = y.work + un * un / (2.0 * b);
            advance(y, d, un / b);
            y.work = absorbed;
            compression = false;
          }
          const double remaining = e_ * e_ * absorbed - (absorbed - y.work);  // work still to give back
          const double v = -n_.dot(y.u);                                      // >= 0 in restitution
          const double s = remaining > 0.0 ? (-v + std::sqrt(v * v + 2.0 * b * remaining)) / b : 0.0;
          advance(y, d, s);
          return {y.P, true};
        }
        // Sticking needs more friction than mu: slip starts along the consistent direction.
        const Vector3d d = n_ + mu_ * slipStart();
        advance(y, d, 1e-6 * scale / (W_ * d).norm());
        continue;
      }
      // Sliding: one RK4 step that changes u by a small fraction of its size (or of the initial
      // speed near the end of compression), and at most half the remaining slip: the approach
      // to sticking is geometric and the slip direction never jumps within a step. Cut back to
      // the first event inside it.
      const Vector3d Wd = W_ * (n_ + mu_ * u_t / u_t.norm());
      const double h = std::min(kStepFraction * std::max(y.u.norm(), 1e-3 * scale) / Wd.norm(),
                                0.5 * u_t.norm() / std::max(tangential(Wd).norm(), 1e-300));
      State next = rk4(y, h);
      double fraction = 1.0;
      const auto slipReversed = [&](const State& z) { return tangential(z.u).dot(u_t) <= eps_ * u_t.norm(); };
      if (slipReversed(next)) fraction = std::min(fraction, bisect(y, h, slipReversed));
      if (compression && n_.dot(next.u) <= 0.0)
        fraction = std::min(fraction, bisect(y, h, [&](const State& z) { return n_.dot(z.u) <= 0.0; }));
      if (!compression && absorbed - next.work >= e_ * e_ * absorbed)
        fraction = std::min(fraction, bisect(y, h, [&](const State& z) { return absorbed - z.work >= e_ * e_ * absorbed; }));
      if (fraction < 1.0) next = rk4(y, fraction * h);
      y = next;
      if (compression && n_.dot(y.u) <= 1e-15 * scale) {
        compression = false;
        absorbed = y.work;
      }
      if (!compression && absorbed - y.work >= e_ * e_ * absorbed * (1.0 - 1e-15)) return {y.P, false};
    }
    // Step budget spent: a contact that chatters between stick and slip (seen only for extremely
    // anisotropic W). Complete the impact from here with the maximum-dissipation impulse, which
    // lies in the cone, stops the approach and can only lose energy (Anitescu 2006).
    SlipProcess out{y.P + maximumDissipationImpulse(y.u), false};
    out.completed_by_max_dissipation = true;
    return out;
  }

 private:
  /// argmin 1/2 P^T W P - P^T u over the cone |P_t| <= mu P_n: the sticking impulse W^-1 u if it
  /// lies in the cone, else the best impulse on the cone's surface (a 1-D search over the slip
  /// angle: along d = n + mu s the best magnitude is max(0, d.u) / d.W d).
  Vector3d maximumDissipationImpulse(const Vector3d& u) const {
    const Vector3d P_stick = W_.llt().solve(u);
    const double P_n = n_.dot(P_stick);
    if (P_n >= 0.0 && tangential(P_stick).norm() <= mu_ * P_n) return P_stick;
    const Vector3d t1 = n_.unitOrthogonal(), t2 = n_.cross(t1);
    const auto direction = [&](double a) { return Vector3d(n_ + mu_ * (std::cos(a) * t1 + std::sin(a) * t2)); };
    const auto release = [&](double a) {
      const Vector3d d = direction(a);
      const double c = std::max(0.0, d.dot(u));
      return c * c / d.dot(W_ * d);
    };
    constexpr int kSamples = 720;
    constexpr double kTwoPi = 6.283185307179586, kGolden = 0.6180339887498949;
    double best = 0.0, best_release = -1.0;
    for (int i = 0; i < kSamples; ++i)
      if (const double r = release(kTwoPi * i / kSamples); r > best_release) best_release = r, best = kTwoPi * i / kSamples;
    double lo = best - kTwoPi / kSamples, hi = best + kTwoPi / kSamples;
    double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo), f1 = release(x1), f2 = release(x2);
    for (int it = 0; it < 100 && hi - lo > 1e-15; ++it) {
      if (f1 < f2) lo = x1, x1 = x2, f1 = f2, x2 = lo + kGolden * (hi - lo), f2 = release(x2);
      else hi = x2, x2 = x1, f2 = f1, x1 = hi - kGolden * (hi - lo), f1 = release(x1);
    }
    const Vector3d d = direction(0.5 * (lo + hi));
    return std::max(0.0, d.dot(u)) / d.dot(W_ * d) * d;
  }

  static constexpr double kStepFraction = 2e-3;  ///< relative change of u per RK4 step
  static constexpr double kRoundOff = 1e-12;     ///< relative floor of |u_t| (W's rounding)
  static constexpr int kMaxSteps = 100000;

  struct State {
    Vector3d u;   ///< relative velocity of A with respect to B
    Vector3d P;   ///< impulse on B so far
    double work;  ///< integral of u_n dp (normal work absorbed so far, net)
  };

  Vector3d tangential(const Vector3d& v) const { return v - n_.dot(v) * n_; }

  /// Exact advance along a constant impulse direction d (nd = 1) by normal impulse s.
  void advance(State& y, const Vector3d& d, double s) const {
    const double un = n_.dot(y.u), rate = n_.dot(W_ * d);
    y.work += un * s - 0.5 * rate * s * s;
    y.u -= s * (W_ * d);
    y.P += s * d;
  }

  State rate(const State& y) const {
    const Vector3d u_t = tangential(y.u);
    const Vector3d d = n_ + mu_ * u_t / u_t.norm();
    return {-(W_ * d), d, n_.dot(y.u)};
  }
  State rk4(const State& y, double h) const {
    const auto add = [](const State& a, const State& k, double c) {
      return State{a.u + c * k.u, a.P + c * k.P, a.work + c * k.work};
    };
    const State k1 = rate(y), k2 = rate(add(y, k1, h / 2)), k3 = rate(add(y, k2, h / 2)), k4 = rate(add(y, k3, h));
    return {y.u + h / 6 * (k1.u + 2 * k2.u + 2 * k3.u + k4.u), y.P + h / 6 * (k1.P + 2 * k2.P + 2 * k3.P + k4.P),
            y.work + h / 6 * (k1.work + 2 * k2.work + 2 * k3.work + k4.work)};
  }
  /// Smallest step fraction in (0, 1] at which `event` holds, by bisection.
  template <typename Event>
  double bisect(const State& y, double h, const Event& event) const {
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (event(rk4(y, mid * h)) ? hi : lo) = mid;
    }
    return hi;
  }

  /// Tangential impulse rate tau that keeps u_t = 0: (W (n + tau))_t = 0. True if |tau| <= mu.
  bool stickImpulseRate(Vector3d& tau) const {
    const Vector3d t1 = n_.unitOrthogonal(), t2 = n_.cross(t1);
    Eigen::Matrix2d Wtt;
    Wtt << t1.dot(W_ * t1), t1.dot(W_ * t2), t2.dot(W_ * t1), t2.dot(W_ * t2);
    const Eigen::Vector2d Wtn(t1.dot(W_ * n_), t2.dot(W_ * n_));
    const Eigen::Vector2d x = Wtt.llt().solve(-Wtn);
    tau = x(0) * t1 + x(1) * t2;
    return tau.norm() <= mu_;
  }
  /// Direction s in which slip starts from rest: -(W (n + mu s))_t = kappa s with kappa > 0.
  Vector3d slipStart() const {
    const Vector3d t1 = n_.unitOrthogonal(), t2 = n_.cross(t1);
    Eigen::Matrix2d Wtt;
    Wtt << t1.dot(W_ * t1), t1.dot(W_ * t2), t2.dot(W_ * t1), t2.dot(W_ * t2);
    const Eigen::Vector2d Wtn(t1.dot(W_ * n_), t2.dot(W_ * n_));
    const auto s = [&](double kappa) {
      return Eigen::Vector2d((kappa * Eigen::Matrix2d::Identity() + mu_ * Wtt).llt().solve(-Wtn));
    };
    double lo = 0.0, hi = 1.0;
    while (s(hi).norm() > 1.0) hi *= 2.0;
    for (int i = 0; i < 100; ++i) {
      const double mid = 0.5 * (lo + hi);
      (s(mid).norm() > 1.0 ? lo : hi) = mid;
    }
    const Eigen::Vector2d x = s(hi).normalized();
    return x(0) * t1 + x(1) * t2;
  }

  Matrix3d W_;
  Vector3d n_;
  double mu_, e_, eps_ = 0.0;
};

}  // namespace

SlipProcess solveSlipProcess(const Matrix3d& W, const Vector3d& n, double mu, double e, const Vector3d& u0) {
  return SlipProcessSolver(W, n, mu, e).solve(u0);
}

}  // namespace kdl_space::friction
