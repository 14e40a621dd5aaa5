// DetumbleTime (operation/motion_record.hpp), the time to detumble streamed over a run's samples,
// on rate histories whose answer is read off by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kdl_space/operation/motion_record.hpp"

namespace kdl_space::test {
namespace {

double timeOf(const std::vector<double>& t, const std::vector<double>& rate, double threshold) {
  DetumbleTime d;
  d.threshold = threshold;
  for (std::size_t k = 0; k < t.size(); ++k) d.add(t[k], rate[k]);
  return d.value();
}

TEST(DetumbleTime, TheFirstSampleAfterTheLastOneAboveTheThreshold) {
  const std::vector<double> t{2.0, 2.5, 3.0, 3.5, 4.0, 4.5};
  // Below from the start: 0.
  EXPECT_EQ(timeOf(t, {0.1, 0.2, 0.1, 0.0, 0.1, 0.1}, 0.5), 0.0);
  // Above, below, above again (at the threshold counts as above), then below for good: 3.5 - 2.
  EXPECT_EQ(timeOf(t, {0.9, 0.4, 0.5, 0.3, 0.2, 0.1}, 0.5), 1.5);
  // Still above at the end: not detumbled.
  EXPECT_TRUE(std::isnan(timeOf(t, {0.9, 0.4, 0.3, 0.2, 0.1, 0.6}, 0.5)));
  // Above only at the first sample: the second one.
  EXPECT_EQ(timeOf(t, {0.9, 0.1, 0.1, 0.1, 0.1, 0.1}, 0.5), 0.5);
  // No sample: NaN.
  EXPECT_TRUE(std::isnan(DetumbleTime{}.value()));
}

}  // namespace
}  // namespace kdl_space::test
