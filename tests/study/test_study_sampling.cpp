// The study's draws (src/study_sampling, private): uniform numbers, the permutation behind the
// Latin hypercube, the normal quantile, grids; and the self-motion of the redundant arm.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>

#include "kdl_space/parsers/scenario/scenario.hpp"
#include "study/study_sampling.hpp"
#include "kdl_space/algorithm/self_motion.hpp"

namespace kdl_space {
namespace {

TEST(StudySampling, UnitIsInsideTheOpenIntervalWithTheUniformMoments) {
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = sampling::unit(42, static_cast<std::uint64_t>(i), 3);
    ASSERT_GT(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u, sum2 += u * u;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));  // 5 sigma
  EXPECT_NEAR(var, 1.0 / 12.0, 5.0 * std::sqrt(1.0 / 180.0 / n));
  // Another seed, sample or stream gives another number.
  EXPECT_NE(sampling::unit(42, 7, 3), sampling::unit(43, 7, 3));
  EXPECT_NE(sampling::unit(42, 7, 3), sampling::unit(42, 8, 3));
  EXPECT_NE(sampling::unit(42, 7, 3), sampling::unit(42, 7, 4));
}

TEST(StudySampling, PermuteIsABijectionOfEveryRange) {
  for (const std::uint64_t n : {1ULL, 2ULL, 3ULL, 17ULL, 1000ULL, 4097ULL}) {
    std::set<std::uint64_t> images;
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::uint64_t k = sampling::permute(i, n, 9, 2);
      ASSERT_LT(k, n);
      images.insert(k);
    }
    EXPECT_EQ(images.size(), n) << "n = " << n;
  }
  // Not the identity, and keyed: another stream permutes otherwise.
  int moved = 0, differ = 0;
  for (std::uint64_t i = 0; i < 1000; ++i) {
    moved += sampling::permute(i, 1000, 9, 2) != i;
    differ += sampling::permute(i, 1000, 9, 2) != sampling::permute(i, 1000, 9, 6);
  }
  EXPECT_GT(moved, 900);
  EXPECT_GT(differ, 900);
}

TEST(StudySampling, NormalQuantileInvertsTheNormalDistribution) {
  // Known values (Abramowitz and Stegun 26.2; to 16 digits from the series of erfc).
  EXPECT_EQ(sampling::normalQuantile(0.5), 0.0);
  EXPECT_NEAR(sampling::normalQuantile(0.975), 1.959963984540054, 1e-15);
  EXPECT_NEAR(sampling::normalQuantile(0.8413447460685429), 1.0, 1e-14);
  EXPECT_NEAR(sampling::normalQuantile(1e-10), -6.361340902404056, 1e-13);
  for (double p = 1e-12; p < 1.0; p = p < 0.01 ? p * 10.0 : p + 0.01) {
    const double x = sampling::normalQuantile(p);
    const double back = 0.5 * std::erfc(-x / std::sqrt(2.0));
    EXPECT_NEAR(back, p, 4e-16 * std::max(p, 1e-300) + 1e-17) << "p = " << p;
  }
}

Study twoInputs(bool lhs) {
  Study st;
  st.seed = 5;
  st.samples = 97;
  st.latin_hypercube = lhs;
  StudyInput a, b;
  a.name = "a", a.distribution = {Distribution::Kind::Uniform, -1.0, 3.0, 0};
  b.name = "b", b.distribution = {Distribution::Kind::Normal, 2.0, 0.5, 0};
  st.inputs = {a, b};
  return st;
}

TEST(StudySampling, LatinHypercubePutsOneSampleInEveryStratumOfEveryInput) {
  const Study st = twoInputs(true);
  std::vector<int> strata_a(st.samples, 0), strata_b(st.samples, 0);
  double v[2];
  for (std::uint64_t i = 0; i < st.samples; ++i) {
    sampling::draw(st, i, v);
    const double u_a = (v[0] + 1.0) / 4.0;
    const double u_b = 0.5 * std::erfc(-(v[1] - 2.0) / 0.5 / std::sqrt(2.0));  // back to (0, 1)
    ++strata_a[static_cast<std::size_t>(u_a * st.samples)];
    ++strata_b[static_cast<std::size_t>(u_b * st.samples + 1e-9)];
  }
  EXPECT_EQ(std::count(strata_a.begin(), strata_a.end(), 1), static_cast<long>(st.samples));
  EXPECT_EQ(std::count(strata_b.begin(), strata_b.end(), 1), static_cast<long>(st.samples));
  // Independent draws do not (97 samples in 97 strata leave about 36 empty).
  const Study random = twoInputs(false);
  std::set<std::size_t> hit;
  for (std::uint64_t i = 0; i < random.samples; ++i) {
    sampling::draw(random, i, v);
    hit.insert(static_cast<std::size_t>((v[0] + 1.0) / 4.0 * random.samples));
  }
  EXPECT_LT(hit.size(), random.samples - 10);
}

/// A study of three inputs: a normal truncated to [min, max], a log-normal (median 3, factor 2),
/// a normal truncated on one side far in its upper tail (20 to 20.5 standard deviations above).
Study boundedInputs(bool lhs) {
  Study st;
  st.seed = 8;
  st.samples = 101;
  st.latin_hypercube = lhs;
  StudyInput a, b, c;
  a.name = "a", a.distribution = {Distribution::Kind::Normal, 10.0, 20.0, 0, 0.5, 30.0};
  b.name = "b", b.distribution = {Distribution::Kind::LogNormal, 3.0, 2.0, 0};
  c.name = "c", c.distribution = {Distribution::Kind::Normal, 0.0, 1.0, 0, 20.0, 20.5};
  st.inputs = {a, b, c};
  return st;
}

/// The distribution functions, written from their definitions: a normal truncated to [lo, hi]
/// (Phi(z) - Phi(alpha)) / (Phi(beta) - Phi(alpha)), in the upper tail through 1 - Phi(z) =
/// Phi(-z); a log-normal Phi(ln(x / median) / ln(factor)).
double truncatedCdf(double x, double mean, double std, double lo, double hi) {
  const auto upper = [](double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); };  // 1 - Phi(z)
  const double z = (x - mean) / std, alpha = (lo - mean) / std, beta = (hi - mean) / std;
  return (upper(alpha) - upper(z)) / (upper(alpha) - upper(beta));
}
double logNormalCdf(double x, double median, double factor) {
  return 0.5 * std::erfc(-std::log(x / median) / std::log(factor) / std::sqrt(2.0));
}

TEST(StudySampling, TruncatedAndLogNormalDrawsFollowTheirDistributionsInEveryStratum) {
  for (const bool lhs : {false, true}) {
    SCOPED_TRACE(lhs ? "latin hypercube" : "random");
    const Study st = boundedInputs(lhs);
    std::vector<std::vector<int>> strata(3, std::vector<int>(st.samples, 0));
    double v[3];
    double sum_log = 0.0;
    for (std::uint64_t i = 0; i < st.samples; ++i) {
      sampling::draw(st, i, v);
      ASSERT_GE(v[0], 0.5) << i;
      ASSERT_LE(v[0], 30.0) << i;
      ASSERT_GT(v[1], 0.0) << i;
      ASSERT_GE(v[2], 20.0) << i;
      ASSERT_LE(v[2], 20.5) << i;
      // Each value's probability: the unit it was drawn from, so its stratum.
      const double p[3] = {truncatedCdf(v[0], 10.0, 20.0, 0.5, 30.0), logNormalCdf(v[1], 3.0, 2.0),
                           truncatedCdf(v[2], 0.0, 1.0, 20.0, 20.5)};
      for (int k = 0; k < 3; ++k) {
        ASSERT_GT(p[k], 0.0) << k;
        ASSERT_LT(p[k], 1.0) << k;
        ++strata[k][static_cast<std::size_t>(p[k] * static_cast<double>(st.samples))];
      }
      sum_log += std::log(v[1] / 3.0) / std::log(2.0);
      // Deterministic: the same (seed, i), the same values.
      double again[3];
      sampling::draw(st, i, again);
      EXPECT_EQ(std::vector<double>(v, v + 3), std::vector<double>(again, again + 3));
    }
    if (lhs)
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(std::count(strata[k].begin(), strata[k].end(), 1), static_cast<long>(st.samples)) << "input " << k;
    // ln(x / median) / ln(factor) is a standard normal: its mean within 5 standard errors of 0.
    EXPECT_NEAR(sum_log / static_cast<double>(st.samples), 0.0, 5.0 / std::sqrt(static_cast<double>(st.samples)));
  }
}

TEST(StudySampling, TheQuantileAtTheExtremeUnitsIsFinite) {
  // The largest unit a Latin hypercube's top stratum rounds to (1 - 2^-53), and the smallest.
  const Distribution normal{Distribution::Kind::Normal, 0.0, 1.0, 0};
  // Truncated below only (p = Phi(alpha) + u (1 - Phi(alpha)) rounds to 1 at the top), above
  // only, and far in either tail.
  const Distribution one_sided[] = {{Distribution::Kind::Normal, 0.0, 1.0, 0, -1.0},
                                    {Distribution::Kind::Normal, 0.0, 1.0, 0, -HUGE_VAL, 1.0},
                                    {Distribution::Kind::Normal, 0.0, 1.0, 0, 30.0},
                                    {Distribution::Kind::Normal, 0.0, 1.0, 0, -HUGE_VAL, -30.0}};
  for (const double u : {sampling::lowest_unit, sampling::highest_unit}) {
    EXPECT_TRUE(std::isfinite(sampling::quantile(normal, u))) << u;
    for (const Distribution& d : one_sided) {
      const double x = sampling::quantile(d, u);
      EXPECT_TRUE(std::isfinite(x)) << u << " " << d.min << " " << d.max;
      EXPECT_GE(x, d.min);
      EXPECT_LE(x, d.max);
    }
  }
  // (normalQuantile's refinement resolves the upper tail to ~1e-9 only: Phi(x) - p near p = 1.)
  EXPECT_NEAR(sampling::quantile(normal, sampling::highest_unit), -sampling::normalQuantile(0x1p-53), 1e-8);
  // unit() never returns 1 (its top key, 2^53 - 1 + 0.5, would round to 2^53).
  EXPECT_LT(sampling::highest_unit, 1.0);
}

TEST(StudySampling, SampleIDependsOnlyOnSeedAndI) {
  const Study st = twoInputs(true);
  double forward[2], again[2];
  sampling::draw(st, 40, forward);
  for (std::uint64_t i = 96; i > 0; --i) sampling::draw(st, i, again);  // any other draws in between
  sampling::draw(st, 40, again);
  EXPECT_EQ(forward[0], again[0]);
  EXPECT_EQ(forward[1], again[1]);
}

TEST(StudySampling, AGridVisitsEveryPointOnceTheLastInputFastest) {
  Study st;
  StudyInput a, b;
  a.name = "a", a.distribution = {Distribution::Kind::Grid, 0.0, 1.0, 3};
  b.name = "b", b.distribution = {Distribution::Kind::Grid, -2.0, 2.0, 5};
  st.inputs = {a, b};
  st.samples = 30;
  ASSERT_EQ(sampling::gridSize(st), 15u);
  std::set<std::pair<double, double>> points;
  double v[2];
  for (std::uint64_t i = 0; i < 15; ++i) {
    sampling::draw(st, i, v);
    EXPECT_EQ(v[0], 0.5 * static_cast<double>(i / 5)) << i;
    EXPECT_EQ(v[1], -2.0 + static_cast<double>(i % 5)) << i;
    points.insert({v[0], v[1]});
  }
  EXPECT_EQ(points.size(), 15u);
  sampling::draw(st, 15 + 7, v);  // the grid repeats
  EXPECT_EQ(v[0], 0.5);
  EXPECT_EQ(v[1], 0.0);
}

TEST(StudySelfMotion, HoldsTheHandAndMovesTheArmAlongJsNullSpace) {
  const Scenario sc = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml");
  const FloatingSystem& r = sc.capture.robot;
  SelfMotion motion(r.model, r.contact, r.state);
  FreeFloatingSolver solver(r.model);
  const auto hand = [&](const State& s) {
    EXPECT_EQ(solver.compute(s), 0);
    const KDL::Frame b = solver.bodyPose(r.contact.body);
    return KDL::Frame(b.M, b * r.contact.offset);
  };
  const KDL::Frame F0 = hand(r.state);
  for (const double s : {1e-4, 0.3, -0.7, 1.2}) {
    State moved = r.state;
    ASSERT_EQ(motion.move(moved, s), 0) << s;
    const KDL::Twist e = KDL::diff(hand(moved), F0);
    EXPECT_LT(e.vel.Norm() + e.rot.Norm(), 1e-10) << s;
    const double chord = (moved.q.data - r.state.q.data).norm();
    EXPECT_LE(chord, std::abs(s) * (1.0 + 1e-9)) << s;  // a chord of an arc of length |s|
    EXPECT_GT(chord, 0.8 * std::abs(s)) << s;
    // A short step is along J's null space (to first order in s).
    if (std::abs(s) < 0.05) {
      KDL::Jacobian J(r.model->nj());
      ASSERT_EQ(solver.compute(r.state), 0);
      ASSERT_EQ(solver.J(r.contact, J), 0);
      const Eigen::VectorXd dq = (moved.q.data - r.state.q.data) / s;
      EXPECT_LT((J.data * dq).norm(), 1e-3 * dq.norm());
    }
  }
}

/// The scenario's arm and its hand frame by the library's kinematics (FreeFloatingSolver).
struct ArmAtScenario {
  Scenario sc = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/tumbling_box_capture.yaml");
  const FloatingSystem& r = sc.capture.robot;
  FreeFloatingSolver solver{r.model};
  KDL::Frame hand(const State& s) {
    EXPECT_EQ(solver.compute(s), 0);
    const KDL::Frame b = solver.bodyPose(r.contact.body);
    return KDL::Frame(b.M, b * r.contact.offset);
  }
  State moved(SelfMotion& m, double s) {
    State x = r.state;
    EXPECT_EQ(m.move(x, s), 0) << s;
    return x;
  }
};

TEST(StudySelfMotion, HoldsTheHandToRoundOffAfterShortAndLongSteps) {
  // The angle by Eigen's quaternion of R0^T R (accurate at small angles): a walk's last short step
  // drifts the hand by ~1e-8 rad, below what KDL::diff reads (about 1e-6 rad).
  ArmAtScenario a;
  SelfMotion motion(a.r.model, a.r.contact, a.r.state);
  const KDL::Frame F0 = a.hand(a.r.state);
  for (const double s : {1e-4, 0.05 + 1e-5, 0.3 + 3e-6, -0.7 - 2e-5, 1.2, -1.5 + 1e-3}) {
    const KDL::Frame F = a.hand(a.moved(motion, s));
    const double angle = Eigen::AngleAxisd(toEigen(F0.M).transpose() * toEigen(F.M)).angle();
    EXPECT_LT(angle, 1e-12) << s;
    EXPECT_LT((toEigen(F.p) - toEigen(F0.p)).norm(), 1e-12) << s;
  }
}

TEST(StudySelfMotion, IsContinuousInTheArcLength) {
  // |q(s + d) - q(s)| ~ |d| across the walk's checkpoints (multiples of 0.05) and where s / 0.05
  // rounds either way (a walk in s / ceil(s / 0.05) steps jumped there by ~2e-6). A step's
  // pull back onto the hand's pose lengthens it by less than 1e-3 of it (second order in 0.05).
  ArmAtScenario a;
  SelfMotion motion(a.r.model, a.r.contact, a.r.state);
  for (const double s : {0.1, 0.30000000000000004, 0.3, -0.25, -1.0, 0.123}) {
    for (const double d : {1e-11, -1e-11, 1e-7, -1e-7, 1e-3}) {
      const Eigen::VectorXd q = a.moved(motion, s).q.data, p = a.moved(motion, s + d).q.data;
      EXPECT_LE((p - q).norm(), std::abs(d) * (1.0 + 1e-3) + 1e-13) << s << " + " << d;
    }
  }
}

TEST(StudySelfMotion, AWalkKeptIsTheWalkAFreshOneTakes) {
  // Moves from the same start reuse the walk's checkpoints: bit for bit what a new SelfMotion
  // gives, in any order; a move from elsewhere starts a new walk.
  ArmAtScenario a;
  SelfMotion kept(a.r.model, a.r.contact, a.r.state);
  for (const double s : {0.73, -0.41, 0.2, 1.3, -1.05, 0.0, 0.05}) {
    SelfMotion fresh(a.r.model, a.r.contact, a.r.state);
    EXPECT_EQ(a.moved(kept, s).q.data, a.moved(fresh, s).q.data) << s;
  }
  State elsewhere = a.moved(kept, 0.4);
  State twice = elsewhere;
  ASSERT_EQ(kept.move(twice, 0.3), 0);
  SelfMotion fresh(a.r.model, a.r.contact, elsewhere);
  ASSERT_EQ(fresh.move(elsewhere, 0.3), 0);
  EXPECT_EQ(twice.q.data, elsewhere.q.data);
}

TEST(StudySelfMotion, ItsParameterIsTheArcLengthInJointSpace) {
  // The polygon through 400 points of the walk from 0 to s is as long as s, to the midpoint
  // rule's error (second order in the 0.05 step).
  ArmAtScenario a;
  SelfMotion motion(a.r.model, a.r.contact, a.r.state);
  for (const double s : {1.0, -0.8}) {
    double length = 0.0;
    Eigen::VectorXd previous = a.r.state.q.data;
    for (int k = 1; k <= 400; ++k) {
      const Eigen::VectorXd q = a.moved(motion, s * k / 400.0).q.data;
      length += (q - previous).norm();
      previous = q;
    }
    EXPECT_NEAR(length, std::abs(s), 1e-4 * std::abs(s)) << s;
  }
}

TEST(StudySelfMotion, RefusesAnArmThatIsNotOnceRedundant) {
  const Scenario sc = loadScenario(std::string(KDL_SPACE_SOURCE_DIR) + "/scenarios/spacedyn_twolink_pd.yaml");
  const FloatingSystem& r = sc.capture.robot;
  try {
    SelfMotion motion(r.model, r.contact, r.state);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("one-parameter family only for 7"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kdl_space
