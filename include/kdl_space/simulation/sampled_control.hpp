// A controller sampled at a control rate: the joint torques it returns at the control instants
// t0 + k / rate are held until the next one (a zero-order hold, as a digital controller's), or,
// without a rate, it is called at every evaluation of the dynamics (a continuous controller).
#pragma once

#include <Eigen/Core>
#include <functional>

#include "kdl_space/export.hpp"
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

}  // namespace kdl_space
