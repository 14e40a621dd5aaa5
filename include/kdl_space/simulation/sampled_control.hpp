// A controller sampled at a control rate: the joint torques it returns at the control instants
// t0 + k / rate are held until the next one (a zero-order hold, as a digital controller's), or,
// without a rate, it is called at every evaluation of the dynamics (a continuous controller).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/simulation/simulation.hpp"

namespace kdl_space {

/// The user's controller: the joint torques (model order, size nj) at a state. It may throw; the
/// run stops there and the exception propagates.
using SampledController = std::function<void(const SimulationState& s, Eigen::VectorXd& tau)>;

/// \brief The output instants of a sampled run: one grid of step `delta` on which both the control
/// instants (every `a` grid steps; 0: no control instants) and the samples (every `b`) lie, so that
/// no step straddles a control instant.
struct ControlGrid {
  double delta = 0.0;
  long a = 0, b = 1;
};

/// \brief The grid for samples every `output_dt` and controls every `period` (> 0), or without
/// control instants when period is 0. \throws InputError when the two are not commensurate (their
/// ratio is no fraction a / b with b <= 1000) or period is negative or not finite.
KDL_SPACE_EXPORT ControlGrid controlGrid(double output_dt, double period);

/// \brief Runs `sim` from s to t_end with `controller` (may be empty: the joint modes alone) called
/// at `control_rate` [Hz] with a zero-order hold, or at every evaluation when control_rate is 0
/// (without a controller the rate is not used).
/// Its torques add to those of the joint modes. `observer` sees s.t, every multiple of output_dt
/// after it and t_end, as Simulator::run's; at a control instant it sees the new command
/// (Simulator::actuation). The simulator's torque callback is set for the run and cleared after it,
/// however it ends. \return as Simulator::run, or E_SIZE_MISMATCH for a controller that returns a
/// torque of the wrong size, E_NOT_FINITE for one that is not finite (s then at the last state
/// accepted). \throws InputError as controlGrid; what the controller or the observer throws.
KDL_SPACE_EXPORT int runSampled(Simulator& sim, SimulationState& s, double t_end, double output_dt,
                                const SampledController& controller, double control_rate,
                                const std::function<void(const SimulationState&)>& observer);

/// Above this kd dt / m a sampled rate feedback overshoots (sampledGainWarnings); 2 is the limit.
inline constexpr double kSampledGainMargin = 1.0;

/// \brief Whether a controller sampled at `control_rate` [Hz] with a zero-order hold can be stable
/// at the state s: its rate gains are probed (kd_j = -d tau_j / d qdot_j by a central difference
/// of +-delta on joint j's rate, 2 calls per joint not braked) and each compared with the joint's
/// apparent inertia m_j = 1 / (H*^-1)_jj (Simulator::apparentInertia: the base free, or
/// grounded, as `sim` runs it). A joint with kd_j dt / m_j > kSampledGainMargin (dt = 1 / rate)
/// gets a warning {kind "sampled_gain_unstable", element: its name, message: the numbers, the
/// rate or gain that would do}. Why this bound: joint j alone is m qddot = u with u_k = -kp q_k -
/// kd qdot_k held over [t_k, t_k + dt); the exact discretisation, with a = kp dt^2 / m and
/// b = kd dt / m, has the characteristic polynomial z^2 - (2 - a/2 - b) z + (1 - b + a/2), whose
/// roots lie in the unit circle (Jury) iff a > 0, a/2 < b and b < 2. So b < 2 is necessary
/// whatever kp; past b = 1 the rate changes sign every sample (a ringing at the Nyquist rate).
/// For the coupled system b_j = kd_j dt (H*^-1)_jj is a diagonal entry of dt D^1/2 H*^-1 D^1/2,
/// whose largest eigenvalue is at least as large: b_j > 2 is unstable for the whole arm too (the
/// diagonal of H* instead of 1 / (H*^-1)_jj would miss some). Set-up call: it allocates and calls
/// the controller; the simulator's controls are unchanged.
/// \return 0; E_SIZE_MISMATCH for a state of another model or a controller's torque of another
/// size; E_NOT_FINITE for a non-finite torque; what apparentInertia returns. \throws what the
/// controller throws.
KDL_SPACE_EXPORT int sampledGainWarnings(Simulator& sim, const SimulationState& s, const SampledController& controller,
                                         double control_rate, std::vector<Diagnostic>& warnings);

}  // namespace kdl_space
