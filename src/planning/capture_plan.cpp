// planCapture: a scan of the searched parameters' box on a fixed grid, then NLopt local polishes
// (derivative-free: the objective comes through inverse kinematics and a capture) from the scan's
// best local minima. Everything is deterministic: the grid, the starts, the algorithms (BOBYQA and
// COBYLA draw no random numbers).
#include "kdl_space/planning/capture_plan.hpp"

#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "planning/plan_evaluator.hpp"

namespace kdl_space {
namespace {

/// The searched parameters and their ranges, in the scan's order: the self-motion and the closing
/// speed vary fastest (neither changes the hand's goal: one inverse kinematics serves their rows).
struct Box {
  std::vector<int> which;  ///< 0 self_motion, 1 wrist_roll, 2 timing, 3 closing_speed
  std::vector<PlanRange> range;
  unsigned int N = 2;      ///< the scan's points per parameter
};

double& coordinate(PlanPoint& p, int which) {
  return which == 0 ? p.self_motion : which == 1 ? p.wrist_roll : which == 2 ? p.timing : p.closing_speed;
}

/// The search: the chart's evaluator, the box, and the best feasible configuration seen.
struct PlanSearch {
  PlanEvaluator& evaluator;
  Box box;
  PlanPoint fixed;  ///< the values of the parameters not searched
  unsigned int evaluations = 0;
  bool found = false;
  PlanPoint best;
  PlanTerms best_terms;
  bool cancelled = false;
  std::string first_why;  ///< why the first configuration evaluated is out (for the error)

  bool stopped() {
    if (!cancelled && evaluator.options().cancelled) cancelled = evaluator.options().cancelled();
    return cancelled;
  }

  PlanPoint point(const std::vector<double>& x) const {
    PlanPoint p = fixed;
    for (std::size_t k = 0; k < x.size(); ++k) {
      coordinate(p, box.which[k]) = std::clamp(x[k], box.range[k].lower, box.range[k].upper);
    }
    return p;
  }
  double score(const std::vector<double>& x) {
    if (stopped()) return PlanEvaluator::score(PlanTerms{});
    const PlanPoint p = point(x);
    const PlanTerms t = evaluator.evaluate(p);
    if (++evaluations == 1 && !t.feasible) first_why = t.infeasible;
    if (t.feasible && (!found || t.objective < best_terms.objective)) {
      found = true;
      best = p;
      best_terms = t;
    }
    return PlanEvaluator::score(t);
  }
};

double nloptScore(const std::vector<double>& x, std::vector<double>& /*grad*/, void* data) {
  return static_cast<PlanSearch*>(data)->score(x);
}

/// The scan: N points per searched parameter, the box's first varying fastest (the inverse
/// kinematics of a (wrist_roll, timing) pair is computed once for its rows). Returns the scores.
std::vector<double> scan(PlanSearch& s, unsigned int N, std::vector<std::vector<double>>& points) {
  const std::size_t d = s.box.which.size();
  std::size_t total = 1;
  for (std::size_t k = 0; k < d; ++k) total *= N;
  std::vector<double> scores(total);
  points.assign(total, std::vector<double>(d));
  for (std::size_t i = 0; i < total; ++i) {
    std::size_t rest = i;
    for (std::size_t k = 0; k < d; ++k) {
      const std::size_t digit = rest % N;
      rest /= N;
      const PlanRange& r = s.box.range[k];
      points[i][k] = digit + 1 == N ? r.upper : r.lower + (r.upper - r.lower) * static_cast<double>(digit) / (N - 1);
    }
    scores[i] = s.score(points[i]);
  }
  return scores;
}

/// The scan's local minima (no axis neighbour scores lower), best first, ties by index.
std::vector<std::size_t> localMinima(const std::vector<double>& scores, unsigned int N, std::size_t d) {
  std::vector<std::size_t> minima;
  for (std::size_t i = 0; i < scores.size(); ++i) {
    bool lowest = scores[i] < 1e6;  // a feasible point (the penalties start at 1e6)
    std::size_t stride = 1;
    for (std::size_t k = 0; k < d && lowest; ++k, stride *= N) {
      const std::size_t digit = (i / stride) % N;
      if (digit > 0 && scores[i - stride] < scores[i]) lowest = false;
      if (digit + 1 < N && scores[i + stride] < scores[i]) lowest = false;
    }
    if (lowest) minima.push_back(i);
  }
  std::stable_sort(minima.begin(), minima.end(), [&](std::size_t a, std::size_t b) { return scores[a] < scores[b]; });
  return minima;
}

void polish(PlanSearch& s, const std::vector<double>& start, unsigned int N, unsigned int evaluations) {
  const std::size_t d = start.size();
  nlopt::opt opt(d == 1 ? nlopt::LN_COBYLA : nlopt::LN_BOBYQA, static_cast<unsigned>(d));
  std::vector<double> lower(d), upper(d), step(d), tol(d);
  for (std::size_t k = 0; k < d; ++k) {
    const PlanRange& r = s.box.range[k];
    lower[k] = r.lower;
    upper[k] = r.upper;
    step[k] = (r.upper - r.lower) / (N - 1);  // one scan cell: the basin the start stands for
    tol[k] = 1e-9 * (r.upper - r.lower);
  }
  opt.set_lower_bounds(lower);
  opt.set_upper_bounds(upper);
  opt.set_initial_step(step);
  opt.set_xtol_abs(tol);
  opt.set_ftol_rel(1e-12);
  opt.set_maxeval(static_cast<int>(evaluations));
  opt.set_min_objective(nloptScore, &s);
  if (s.cancelled) return;
  std::vector<double> x = start;
  double f = 0.0;
  try {
    opt.optimize(x, f);
    if (s.cancelled) return;
  } catch (const std::exception&) {
    // NLopt's roundoff_limited or forced stops: the best point seen is kept by the search anyway
  }
}

}  // namespace

CapturePlan planCapture(const Scenario& scenario, const PlanOptions& options) {
  PlanEvaluator evaluator(scenario, options);  // or InputError: the options, nothing to plan
  const PlanOptions& o = evaluator.options();
  PlanSearch s{evaluator, {}, {}, 0, false, {}, {}, false, {}};
  const bool closing = o.closing_speed.has_value();
  const PlanRange ranges[4] = {*o.self_motion, o.wrist_roll, o.timing, closing ? *o.closing_speed : PlanRange{}};
  for (const int k : {0, 3, 1, 2}) {
    if (ranges[k].searched()) {
      s.box.which.push_back(k);
      s.box.range.push_back(ranges[k]);
    }
  }
  for (int k = 0; k < 4; ++k) coordinate(s.fixed, k) = ranges[k].lower;
  if (!closing) s.fixed.closing_speed = std::numeric_limits<double>::quiet_NaN();  // the scenario's rates
  // The scan's points per parameter: `scan`, fewer when the grid would pass scan_limit in all.
  const std::size_t d = s.box.which.size();
  s.box.N = o.scan;
  if (std::pow(static_cast<double>(o.scan), static_cast<double>(d)) > o.scan_limit)
    s.box.N = std::max(2u, static_cast<unsigned int>(std::floor(std::pow(o.scan_limit, 1.0 / d) + 1e-9)));
  std::vector<std::vector<double>> points;
  const std::vector<double> scores = scan(s, s.box.N, points);
  const std::vector<std::size_t> minima = localMinima(scores, s.box.N, d);
  for (std::size_t m = 0; m < minima.size() && m < o.polish_starts; ++m) polish(s, points[minima[m]], s.box.N, o.polish_evaluations);
  CapturePlan plan;
  plan.cancelled = s.cancelled;
  if (s.cancelled && !s.found) return plan;
  if (!s.found)
    throw InputError("plan: no configuration in the box keeps the joints inside their position and velocity limits "
                     "(widen or move the ranges, or check the scenario's robot.q); at the box's first point: " +
                     s.first_why);

  const FloatingModel& model = *scenario.capture.robot.model;
  plan.joint_names = model.jointNames();
  plan.optimum = evaluator.evaluate(s.best, &plan, true);  // with its motion, when a horizon is asked
  const std::vector<std::string>& names = planParameters();
  for (int k = 0; k < 4; ++k) {
    if (k == 0 && !evaluator.redundant()) continue;
    if (k == 2 && !ranges[2].searched() && ranges[2].lower == 0.0) continue;
    if (k == 3 && !closing) continue;
    plan.parameters.emplace_back(names[k], coordinate(s.best, k));
    if (ranges[k].searched()) plan.searched.emplace_back(names[k]);
  }
  plan.nominal = evaluator.evaluate(PlanPoint{}, nullptr, true);  // the scenario as written
  plan.horizon = evaluator.horizon();
  plan.nominal_q.resize(model.nj());
  for (unsigned int j = 0; j < model.nj(); ++j) plan.nominal_q[j] = scenario.capture.robot.state.q(j);
  plan.evaluations = s.evaluations + 2;
  return plan;
}

}  // namespace kdl_space
