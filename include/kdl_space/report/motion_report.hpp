// What `kdl_space simulate` reports about a motion beyond its samples: limit excursions, torque
// saturation, the energy split, the base control's momentum balance, stiffness; as JSON and text.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/operation/motion_record.hpp"

namespace kdl_space::report {

Json limitViolationsJson(const MotionRecord& r);
Json saturationJson(const MotionRecord& r);
/// The work of each agent, the kinetic energy change and the bookkeeping's residual.
Json energySplitJson(const MotionRecord& r);
/// null without a base control; else its set points, final errors and the momentum balance.
Json baseControlJson(const MotionRecord& r);
Json stiffnessJson(const MotionRecord& r);
/// null without reaction wheels; else per wheel its axis, torque limit, capacity, momentum at the
/// start and the end, peak momentum (and its fraction of the capacity) and peak torque, and how
/// long the cluster was saturated.
Json wheelsJson(const MotionRecord& r);
/// What the motion did to the stack's tumble: `detumble_rate` (the threshold), `time_to_detumble`
/// (null: not detumbled in the run), `peak_base_rate`, `final_base_rate`, `attitude_excursion`,
/// `wheel_momentum_fraction` (null without wheels), `energy_dissipated`.
Json detumbleJson(const MotionRecord& r);
/// Per joint of the system that moved: its peak |tau| over the samples against its URDF effort
/// limit ({joint, peak_torque, effort_limit, fraction_of_effort}; null where no limit is given).
Json jointTorquesJson(const MotionRecord& r);
/// The load the grasp carried in the motion (MotionRecord::grasp) against the law's
/// max_grasp_wrench (infinite: null): peak force and moment, when, and their fractions of the
/// limits; null when nothing was held.
Json graspLoadJson(const MotionRecord& r, double max_force, double max_moment);
/// The joints with damping or Coulomb friction: their values and the regularisation v_s used.
Json frictionJson(const MotionRecord& r);

/// The readable lines: one warning per joint that left its limits, saturation, energy split,
/// base control, stiffness advice.
void printMotionReport(std::ostream& out, const MotionRecord& r);

}  // namespace kdl_space::report
