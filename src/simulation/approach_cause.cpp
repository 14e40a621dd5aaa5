// Why an approach did not reach its grasp, in words, from its record.
#include "simulation/pre_grasp.hpp"

#include <iomanip>
#include <sstream>

#include "kdl_space/multibody/kinematics.hpp"

namespace kdl_space::approach_phases {
namespace {

/// The arm's reach from its first joint (the sum of the offsets from that joint to the hand: no
/// configuration puts the hand farther), and where that joint is (world); 0 without a joint.
double armReach(const FloatingModel& model, const Kinematics& kin, const Contact& hand, Vector3d& shoulder) {
  double reach = hand.offset.Norm(), first = 0.0;
  shoulder = toEigen(kin.pose(0).p);
  for (int b = hand.body; b > 0;) {
    const Body& body = model.bodies()[static_cast<std::size_t>(b)];
    reach += body.segment.getFrameToTip().p.Norm();
    if (body.joint >= 0) {
      shoulder = toEigen(kin.pose(body.parent) * body.segment.getJoint().JointOrigin());
      first = reach;
    }
    b = body.parent;
  }
  return first;
}

}  // namespace

std::string approachCause(const ApproachRecord& r, ApproachController& controller, const FloatingModel& model,
                          const SimulationState& s) {
  const ApproachSpec& spec = controller.spec();
  Kinematics kin(model);
  KDL::Frame G;
  Vector6d twist;
  Vector3d shoulder;
  double reach = 0.0, shoulder_distance = 0.0;
  if (forwardKinematics(model, s.state, kin) == E_NOERROR && controller.grasp(s.t, G, twist) == E_NOERROR) {
    reach = armReach(model, kin, controller.hand(), shoulder);
    shoulder_distance = (toEigen(G.p) - shoulder).norm();
  }
  std::ostringstream why;
  why << std::setprecision(4);
  const double active = std::max(r.duration - r.pre_grasp_duration, r.output_step);
  std::size_t worst = 0;
  for (std::size_t j = 0; j < r.time_at_limit.size(); ++j)
    if (r.time_at_limit[j] > r.time_at_limit[worst]) worst = j;
  if (reach > 0.0 && shoulder_distance > reach)
    why << "out of reach: the grasp point is " << shoulder_distance << " m from the arm's first joint, beyond its reach "
        << reach << " m";
  else if (!r.time_at_limit.empty() && r.time_at_limit[worst] > 0.25 * active)
    why << "joint " << model.jointNames()[worst] << " held at its limit for " << r.time_at_limit[worst] << " s of "
        << active << " s: from this start the hand needs it beyond its range (a pre-grasp move, approach.pre_grasp, "
        << "starts it on another branch)";
  else if (r.time_near_singular > 0.25 * active) {
    why << "near a singularity: the smallest singular value of the Jacobian was below " << spec.threshold << " for "
        << r.time_near_singular << " s (smallest " << r.min_sigma << ")";
    // With the bus free to move, the hand's Jacobian is a virtual manipulator's about the stack's
    // centre of mass (Vafa and Dubowsky): its links shortened by the bus's share of the mass, it
    // stretches out short of the grounded arm's reach; a free attitude adds the dynamic
    // singularities (Papadopoulos and Dubowsky) inside it.
    if (r.base == ApproachBase::AttitudeHeld)
      why << ": with only the bus's attitude held it recoils along the arm's pull, which shortens the arm's "
          << "reach; hold its position too (base_control.position) or grasp nearer";
    else if (r.base == ApproachBase::Free)
      why << ": the free bus turns and recoils under the arm, which shortens its reach; hold the bus "
          << "(base_control attitude and position) or grasp nearer";
  } else if (r.time_rate_limited > 0.5 * active)
    why << "rates saturated: the joints' rate limits scaled the command down (to " << r.min_scale << ") for "
        << r.time_rate_limited << " s: give it longer (approach.max_duration) or faster joints";
  else
    why << "too slow: the hand closed to " << r.closest_distance << " m but the time ran out: a higher gain, a longer "
        << "approach.max_duration, or a slower target";
  return why.str();
}

}  // namespace kdl_space::approach_phases
