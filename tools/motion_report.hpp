// What `kdl_space simulate` reports about a motion beyond its samples: limit excursions, torque
// saturation, the energy split, the base control's momentum balance, stiffness; as JSON and text.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "kdl_space/simulation/simulation.hpp"
#include "sample.hpp"

namespace kdl_space::cli {

/// Everything the report reads: the simulator after its run, the samples, the stiffness at the
/// start.
struct MotionRecord {
  const Simulator& sim;
  const std::vector<Sample>& samples;
  const Stiffness& stiffness;
  double output_step;
  double t_start, t_reached;  ///< the run's start, and how far it got [s]
};

/// Whether the run was held back by a stiff servo, and what to try (empty: it was not).
std::string stiffnessAdvice(const MotionRecord& r);

Json limitViolationsJson(const MotionRecord& r);
Json saturationJson(const MotionRecord& r);
/// The work of each agent, the kinetic energy change and the bookkeeping's residual.
Json energySplitJson(const MotionRecord& r);
/// null without a base control; else its set points, final errors and the momentum balance.
Json baseControlJson(const MotionRecord& r);
Json stiffnessJson(const MotionRecord& r);
/// The joints with damping or Coulomb friction: their values and the regularisation v_s used.
Json frictionJson(const MotionRecord& r);
/// Largest |h - h_0 - impulse| over the samples (P and L parts); the momentum balance.
std::pair<double, double> momentumBalance(const std::vector<Sample>& samples);

/// The readable lines: one warning per joint that left its limits, saturation, energy split,
/// base control, stiffness advice.
void printMotionReport(std::ostream& out, const MotionRecord& r);

}  // namespace kdl_space::cli
