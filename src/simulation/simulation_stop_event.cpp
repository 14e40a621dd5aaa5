// The simulator's located stop (Simulator::setStopEvent): the first instant where g(s) <= 0, found
// inside the step where g changed sign, as the hard stops' instants are (simulation_events.cpp).
#include <algorithm>
#include <cmath>

#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {
namespace {

constexpr double kEventTimeTolerance = 1e-10;  ///< the bracket's width at which the instant is taken [s]
constexpr int kEventIterations = 200;          ///< far more than the safeguarded Illinois method needs

}  // namespace

int Simulator::eventValue(double t, const Vector& x, double& g) {
  if (const int rc = unpack(x, t, scratch_)) return rc;
  g = event_(scratch_);
  return E_NOERROR;
}

int Simulator::stopEvent(double t_prev, const Vector& x_prev, double& t, Vector& x, bool& fired) {
  fired = false;
  double g_end = 0.0;
  if (const int rc = eventValue(t, x, g_end)) return rc;
  if (!(g_end <= 0.0)) {  // not met (or NaN): the next step starts from here
    event_start_ = g_end;
    return E_NOERROR;
  }
  fired = true;
  if (!(event_start_ > 0.0)) return E_NOERROR;  // NaN at the start: no bracket, the step's end
  // The retaken steps run with the locks of the step taken; afterStep may have changed them (a
  // joint stopped at the step's end, or one released there).
  const bool relocked = !std::equal(at_stop_.begin(), at_stop_.end(), at_stop_before_.begin());
  if (relocked) {
    std::copy(at_stop_.begin(), at_stop_.end(), at_stop_after_.begin());
    std::copy(at_stop_before_.begin(), at_stop_before_.end(), at_stop_.begin());
    applyLocks();
  }
  // Illinois on the time into the step, [a, b] with g(a) > 0 >= g(b); b starts at the step's end
  // (after a hard stop's impulse, if any: g may jump there, and then the crossing is the stop).
  const double length = t - t_prev;
  double a = 0.0, b = length, ga = event_start_, gb = g_end;
  bool b_is_end = true;
  int side = 0;
  double checkpoint = length;  // the width four iterations ago: the Illinois point must beat bisection
  for (int iteration = 1; iteration <= kEventIterations && b - a > kEventTimeTolerance; ++iteration) {
    double tau = (a * gb - b * ga) / (gb - ga);
    const bool slow = iteration % 4 == 0 && b - a > 0.5 * checkpoint;
    if (iteration % 4 == 0) checkpoint = b - a;
    if (slow || !(tau > a && tau < b)) tau = 0.5 * (a + b);
    if (const int rc = retake(t_prev, tau, x_prev, x_event_)) return rc;
    double g = 0.0;
    if (const int rc = eventValue(t_prev + tau, x_event_, g)) return rc;
    if (g <= 0.0) {
      b = tau, gb = g;
      x_located_ = x_event_;
      b_is_end = false;
      if (side == 1) ga *= 0.5;
      side = 1;
      if (g == 0.0) break;
    } else {
      a = tau, ga = std::isfinite(g) ? g : ga;  // a NaN inside: the bracket still shrinks
      if (side == -1) gb *= 0.5;
      side = -1;
    }
  }
  if (b_is_end) {  // at the step's end: as afterStep left it
    if (relocked) {
      std::copy(at_stop_after_.begin(), at_stop_after_.end(), at_stop_.begin());
      applyLocks();
    }
    return E_NOERROR;
  }
  // Before the step's end: a hard stop met at the end did not happen.
  for (std::size_t j = 0; j < just_stopped_.size(); ++j)
    if (just_stopped_[j]) --stats_.joints[j].stops;
  std::fill(just_stopped_.begin(), just_stopped_.end(), false);
  x = x_located_;
  x.segment<4>(3).normalize();
  t = t_prev + b;
  return E_NOERROR;
}

}  // namespace kdl_space
