// The compliant capture inside the operation (law type compliant, issue 28): the contact
// integrated over its duration from the contact instant, then what moves on after it.
#include <iomanip>
#include <sstream>

#include "spatial/message_text.hpp"
#include "operation/phases.hpp"

namespace kdl_space::operation {

void compliantCapture(const Scenario& sc, const CaptureProblem& problem, const std::optional<CaptureResult>& limit,
                      const OperationOptions& o, OperationResult& r) {
  r.duration = o.duration.value_or(sc.simulation.duration);
  r.output_step = o.output_step.value_or(sc.simulation.output_step);
  r.at_contact = problem;
  r.capture = limit;
  r.model = problem.robot.model;
  const double t0 = r.t_capture;
  CompliantRun run;
  run.options = sc.simulation.options;  // (rk4 runs as dopri5 in the contact)
  bool cancelled = false;
  run.cancelled = [&] { return cancelled = o.cancelled && o.cancelled(); };
  int sample_rc = E_NOERROR;
  run.observer = [&](Simulator& sim, const SimulationState& x, const ContactSample& c) {
    MotionSample smp;
    if (const int rc = sampleOf(sim, x, Phase::Contact, smp)) sample_rc = rc;
    smp.t += t0;
    smp.contact_wrench = smp.grasp_wrench = c.wrench;
    r.contact_samples.push_back(std::move(smp));
  };
  try {
    r.compliant = solveCompliantCapture(problem, *sc.compliant, run);
  } catch (const OperationError&) {
    throw;
  } catch (const Error& e) {
    r.compliant.reset();
    if (cancelled)
      throw OperationError(sc.file + ": the simulation was cancelled in the compliant contact, after t = " +
                               detail::number(t0) + " s",
                           E_CANCELLED, std::make_shared<const OperationResult>(r));
    e.rethrowWithContext(sc.file + ": ");
  }
  const CompliantCaptureResult& c = *r.compliant;
  if (sample_rc)
    throw OperationError(sc.file + ": the compliant contact's samples cannot be evaluated: " + strError(sample_rc),
                         sample_rc, std::make_shared<const OperationResult>(r));
  const bool compliant_after = sc.compliant->lock == GraspLock::Never && c.end != ContactEnd::Opened;
  if (c.end == ContactEnd::TimedOut && !compliant_after) {
    std::ostringstream why;
    why << std::setprecision(6) << sc.file << ": law.max_duration: the compliant contact was neither caught nor opened in "
        << sc.compliant->max_duration << " s (relative speed still above law.catch_tolerance = "
        << sc.compliant->catch_tolerance << " of its start): raise law.max_duration, the damping "
        << "(law.damping_time or law.damping), or law.catch_tolerance, or leave the grasp compliant (law.lock: never)";
    throw OperationError(why.str(), E_NOERROR, std::make_shared<const OperationResult>(r));
  }
  if (c.end == ContactEnd::Opened && c.duration <= 1e-9)  // the located end's resolution is 1e-10 s
    r.warnings.push_back(Diagnostic{"law.normal",
                                    "the compliant contact opened at the touch (after " + detail::number(c.duration) +
                                        " s): the target's contact point does not close on the robot's along the "
                                        "normal, so nothing was captured; the robot and the target move on apart",
                                    "contact_opened_at_touch"});
  SimulationState s;
  s.t = t0 + c.duration;
  s.wheel_momentum = wheelsAtContact(sc, r);  // (the contact's own run carries no wheels: unchanged)
  std::optional<FloatingSystem> separated;
  if (c.end == ContactEnd::Caught || compliant_after) {  // one system moves on, the grasp locked or compliant
    r.joined = c.joined;
    r.model = c.joined.model;
    s.state = c.joined.state;
    s.velocity = c.joined.velocity;
  } else {  // opened: the robot alone; a free-floating target by itself
    s.state = c.robot_end.state;
    s.velocity = c.robot_end.velocity;
    if (std::holds_alternative<FloatingSystem>(problem.target)) separated = c.target_end;
  }
  r.payload_attached = r.model != problem.robot.model;
  runMotion(sc, problem, s, separated, o, r);
}

}  // namespace kdl_space::operation
