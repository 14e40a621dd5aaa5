#include "study/study_sampling.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <variant>

#include "study/target_shape.hpp"

namespace kdl_space::sampling {

std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

namespace {
std::uint64_t key(std::uint64_t seed, std::uint64_t sample, std::uint64_t stream) {
  return mix(mix(mix(seed) ^ sample) ^ (stream * 0xd1b54a32d192ed03ULL));
}
}  // namespace

double unit(std::uint64_t seed, std::uint64_t sample, std::uint64_t stream) {
  // (2^53 - 1) + 0.5 rounds to 2^53 (to even): the top key would give 1.
  return std::min((static_cast<double>(key(seed, sample, stream) >> 11) + 0.5) * 0x1.0p-53, highest_unit);
}

std::uint64_t permute(std::uint64_t i, std::uint64_t n, std::uint64_t seed, std::uint64_t stream) {
  if (n <= 1) return 0;
  int half = 1;
  while (half < 32 && (std::uint64_t{1} << (2 * half)) < n) ++half;
  const std::uint64_t mask = (std::uint64_t{1} << half) - 1;
  const std::uint64_t k = key(seed, ~std::uint64_t{0}, stream);
  std::uint64_t x = i;
  do {  // cycle-walking: the network permutes [0, 4^half); iterate until the image is in [0, n)
    std::uint64_t left = x >> half, right = x & mask;
    for (std::uint64_t round = 0; round < 4; ++round) {
      const std::uint64_t next = left ^ (mix(right ^ mix(k + round)) & mask);
      left = right;
      right = next;
    }
    x = (left << half) | right;
  } while (x >= n);
  return x;
}

double normalQuantile(double p) {
  // Acklam's coefficients (relative error 1.15e-9), then one Halley step.
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01,  -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double p_low = 0.02425;
  double x;
  if (p < p_low) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p <= 1.0 - p_low) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  } else {
    const double q = std::sqrt(-2.0 * std::log(1.0 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;  // Phi(x) - p
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

double quantile(const Distribution& d, double u) {
  switch (d.kind) {
    case Distribution::Kind::Uniform:
      return d.a + (d.b - d.a) * u;
    case Distribution::Kind::LogNormal:
      return d.a * std::exp(std::log(d.b) * normalQuantile(u));
    case Distribution::Kind::Normal:
    case Distribution::Kind::Grid:
      break;
  }
  if (d.min == -HUGE_VAL && d.max == HUGE_VAL) return d.a + d.b * normalQuantile(u);
  double alpha = (d.min - d.a) / d.b, beta = (d.max - d.a) / d.b;
  // Bounds both above the mean: the mirror image's, in the lower tail, where Phi is exact
  // (1 - Phi(8) would be 6e-16 of rounding, Phi(-8) is 6.2e-16 to 16 digits).
  const bool mirror = alpha > 0.0;
  if (mirror) {
    std::swap(alpha, beta);
    alpha = -alpha, beta = -beta;
  }
  const double p_alpha = normalCdf(alpha), p_beta = normalCdf(beta);
  // p_beta = 1 (no upper bound) can round p to 1, where Phi^-1 is infinite.
  const double p = std::min(p_alpha + u * (p_beta - p_alpha), highest_unit);
  const double z = std::clamp(normalQuantile(p), alpha, beta);
  return d.a + d.b * (mirror ? -z : z);
}

std::pair<double, double> drawnRange(const Distribution& d) {
  if (d.kind == Distribution::Kind::Grid || d.kind == Distribution::Kind::Uniform)
    return {std::min(d.a, d.b), std::isfinite(d.b - d.a) ? std::max(d.a, d.b) : HUGE_VAL};
  return {quantile(d, lowest_unit), quantile(d, highest_unit)};
}

std::uint64_t gridSize(const Study& study) {
  std::uint64_t g = 1;
  for (const StudyInput& in : study.inputs)
    if (in.distribution.kind == Distribution::Kind::Grid) g *= static_cast<std::uint64_t>(in.distribution.count);
  return g;
}

int valuesOf(const StudyInput& input) {
  using F = StudyInput::Field;
  return input.field == F::TargetTumble || input.field == F::TargetInertiaTilt || input.field == F::TargetTumbleCone ? 4 : 1;
}

void draw(const Study& study, std::uint64_t i, double* values) {
  const std::uint64_t grid_index = i % gridSize(study);
  double *tumble = nullptr, *cone = nullptr;  // target.tumble's axis, target.tumble_cone's
  for (std::size_t k = 0; k < study.inputs.size(); ++k) {
    const StudyInput& in = study.inputs[k];
    const Distribution& d = in.distribution;
    const std::uint64_t stream = 4 * k;
    double value;
    if (d.kind == Distribution::Kind::Grid) {
      // This input's grid coordinate: the last grid input varies fastest.
      std::uint64_t stride = 1;
      for (std::size_t later = k + 1; later < study.inputs.size(); ++later)
        if (study.inputs[later].distribution.kind == Distribution::Kind::Grid)
          stride *= static_cast<std::uint64_t>(study.inputs[later].distribution.count);
      const std::uint64_t point = grid_index / stride % static_cast<std::uint64_t>(d.count);
      value = d.count == 1 ? d.a : d.a + (d.b - d.a) * static_cast<double>(point) / static_cast<double>(d.count - 1);
    } else {
      double u = unit(study.seed, i, stream);
      if (study.latin_hypercube)  // stratum permute(i) of `samples`, a uniform point inside it
        u = (static_cast<double>(permute(i, study.samples, study.seed, stream)) + u) / static_cast<double>(study.samples);
      value = quantile(d, std::min(u, highest_unit));  // the top stratum's u can round to 1: Phi^-1(1) = inf
    }
    *values++ = value;
    using F = StudyInput::Field;
    if (in.field == F::TargetTumble || in.field == F::TargetInertiaTilt) {  // an axis uniform on the sphere
      const double z = 2.0 * unit(study.seed, i, stream + 1) - 1.0;
      const double phi = 2.0 * M_PI * unit(study.seed, i, stream + 2);
      const double r = std::sqrt(1.0 - z * z);
      *values++ = r * std::cos(phi);
      *values++ = r * std::sin(phi);
      *values++ = z;
    } else if (in.field == F::TargetTumbleCone) {  // at `value` from the scenario's tumble axis, azimuth uniform
      const Vector3d w = std::get<RigidTarget>(study.scenario.capture.target).twist.tail<3>();
      const Vector3d axis = coneAxis(w.normalized(), value, 2.0 * M_PI * unit(study.seed, i, stream + 1));
      for (int c = 0; c < 3; ++c) *values++ = axis(c);
      cone = values - 3;
    }
    if (in.field == F::TargetTumble) tumble = values - 3;
  }
  if (tumble && cone) std::copy(cone, cone + 3, tumble);  // target.tumble's rate about the cone's axis
}

}  // namespace kdl_space::sampling
