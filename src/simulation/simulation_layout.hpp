// Private to the simulator: where each part of the integrated state lies in its vector, and the
// clock the scheduled wrenches read during a step.
#pragma once

#include <limits>

namespace kdl_space::detail {

/// x = (p_b (3), quaternion x y z w (4), q (n), h_O = (P; L about the origin) of the system with
/// its wheels (6), qdot (n), the wheels' momenta (m), work (6: EnergySplit's order), external
/// impulse (6)).
struct StateLayout {
  explicit StateLayout(unsigned int joints, long wheel_count = 0)
      : n(static_cast<int>(joints)), m(static_cast<int>(wheel_count)), q(7), h(7 + n), qdot(13 + n),
        wheels(13 + 2 * n), work(13 + 2 * n + m), impulse(19 + 2 * n + m), size(25 + 2 * n + m) {}
  int n, m, q, h, qdot, wheels, work, impulse, size;
};

/// Sets Simulator's wrench clock to a step's midpoint for the step's duration (NaN after it).
struct WrenchClock {
  double& clock;
  WrenchClock(double& c, double t, double h) : clock(c) { clock = t + 0.5 * h; }
  ~WrenchClock() { clock = std::numeric_limits<double>::quiet_NaN(); }
  WrenchClock(const WrenchClock&) = delete;
  WrenchClock& operator=(const WrenchClock&) = delete;
};

}  // namespace kdl_space::detail
