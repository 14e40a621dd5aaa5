// The approach's pre-grasp move (ApproachSpec::pre_grasp): where the pre-grasp pose is when the
// move ends (the target moved on, a free base turned under the arm), its joints by the inverse
// kinematics, and the move itself.
#include "simulation/pre_grasp.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/multibody/poses.hpp"
#include "kdl_space/simulation/joint_move.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space::approach_phases {
namespace {

/// Where a free base is when `move` ends: its momentum (at s, conserved: nothing acts on it)
/// and the move's joint rates give its twist (FreeFloatingSolver::baseTwist, eq. 4), integrated
/// by the midpoint rule at 0.02 s steps at most. False where the dynamics cannot be computed.
bool predictBase(const std::shared_ptr<const FloatingModel>& robot, const SimulationState& s, const JointMove& move,
                 KDL::Frame& base) {
  const FloatingModel& model = *robot;
  FreeFloatingSolver solver(robot, FreeFloatingSolver::Extent::Jacobians);
  Vector6d PL_g;
  if (solver.compute(s.state) || solver.momentum(s.velocity.base_twist, s.velocity.qdot, PL_g)) return false;
  const int steps = std::max(1, static_cast<int>(std::ceil(move.duration() / 0.02)));
  const double h = move.duration() / steps;
  State x = s.state;
  KDL::JntArray qdot(model.nj());
  Eigen::VectorXd q, v;
  KDL::Twist twist;
  const auto twistAt = [&](double t, const KDL::Frame& pose) {
    move.at(t, q, v);
    x.world_T_base = pose;
    x.q.data = q;
    qdot.data = v;
    return solver.compute(x) == E_NOERROR && solver.baseTwist(PL_g, qdot, twist) == E_NOERROR;
  };
  const auto advance = [](const KDL::Frame& pose, const KDL::Twist& t, double dt) {
    // exp(dt [w]) by Eigen: KDL::Rot returns the identity below an angle of 1e-6 rad
    const Vector3d turn = toEigen(t.rot) * dt;
    const Matrix3d R = (turn.norm() > 0.0 ? Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix()
                                          : Matrix3d::Identity()) *
                       toEigen(pose.M);
    return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                      pose.p + t.vel * dt);
  };
  base = s.state.world_T_base;
  for (int k = 0; k < steps; ++k) {
    if (!twistAt(k * h, base)) return false;
    const KDL::Frame mid = advance(base, twist, 0.5 * h);
    if (!twistAt((k + 0.5) * h, mid)) return false;
    base = advance(base, twist, h);
  }
  return true;
}

/// The pre-grasp pose's joints: three passes of (grasp frame at t0 + T backed off, inverse
/// kinematics, the move's duration T). False (why in `why`) when the pose is out of reach.
bool preGraspMove(const FloatingModel& model, const Contact& hand, ApproachController& controller,
                  const SimulationState& s, JointMove& move, std::string& why) {
  const ApproachSpec& spec = controller.spec();
  const unsigned int n = model.nj();
  std::vector<double> rates(n), accelerations(n, spec.pre_grasp->acceleration);
  for (unsigned int j = 0; j < n; ++j) rates[j] = spec.pre_grasp->rate * spec.rate_limits[j];
  IkOptions o;
  o.preferred = s.state.q;  // among a redundant arm's solutions, the one nearest the start's posture
  double T = 0.0;
  State at_end = s.state;  // the base where the move will leave it (a free base turns under the arm)
  // Fixed-point passes: the grasp where the target will be when the move ends, the joints with
  // the base where the move will leave it; until the move stops changing (1 mm, 1 mrad, 1 ms).
  const bool free = controller.base() == ApproachBase::Free;
  for (int pass = 0; pass < 12; ++pass) {
    KDL::Frame G;
    Vector6d twist;
    if (const int rc = controller.grasp(s.t + T, G, twist)) {
      why = std::string("the target's motion cannot be followed to the pre-grasp: ") + strError(rc);
      return false;
    }
    const KDL::Frame pre = G * KDL::Frame(KDL::Vector(0.0, 0.0, -spec.pre_grasp->standoff));
    try {
      const IkResult r = solveInverseKinematics(model, at_end, hand, pre, o);
      move = JointMove(s.state.q.data, r.q.data, rates, accelerations);
    } catch (const InputError& e) {
      if (pass > 0) break;  // a later pass that went out of reach: the last move that was in reach
      why = std::string("the pre-grasp pose (") + detail::number(spec.pre_grasp->standoff) +
            " m back from the grasp) is out of reach within the joints' limits: " + e.what();
      return false;
    }
    KDL::Frame base = at_end.world_T_base;
    if (free && !predictBase(controller.model(), s, move, base)) {
      why = "the base's motion under the pre-grasp move cannot be predicted";
      return false;
    }
    const bool settled = (base.p - at_end.world_T_base.p).Norm() < 1e-3 &&
                         (base.M * at_end.world_T_base.M.Inverse()).GetRot().Norm() < 1e-3 &&
                         std::abs(move.duration() - T) < 1e-3;
    at_end.world_T_base = base;
    T = move.duration();
    if (settled) break;
  }
  return true;
}

}  // namespace

/// The pre-grasp move (ApproachSpec::pre_grasp): the joints velocity-servoed along a JointMove to
/// the pre-grasp pose's joints (rate = the profile's + gain x the position error, within the rate
/// limits); `rec` gets its duration, joints and miss, or its cause when it cannot be made.
int preGrasp(Simulator& sim, ApproachController& controller, SimulationState& s, double output_dt, ApproachRecord& rec,
             const std::function<void(const SimulationState&)>& watch) {
  const FloatingModel& model = sim.model();
  const ApproachSpec& spec = controller.spec();
  JointMove move;
  std::string why;
  if (!preGraspMove(model, controller.hand(), controller, s, move, why)) {
    rec.cause = why;
    return E_NOERROR;
  }
  if (move.duration() > spec.max_duration) {
    rec.cause = "the pre-grasp move takes " + detail::number(move.duration()) + " s at the joints' rate and "
                "acceleration limits, longer than approach.max_duration (" + detail::number(spec.max_duration) + " s)";
    return E_NOERROR;
  }
  rec.pre_grasp_q.assign(move.end().data(), move.end().data() + move.end().size());
  const double t_start = s.t;
  Eigen::VectorXd q_ref, qdot_ref;
  sim.setTorqueCallback([&](const SimulationState& x, KDL::JntArray& tau) {
    move.at(x.t - t_start, q_ref, qdot_ref);
    for (unsigned int j = 0; j < model.nj(); ++j) {
      const double limit = spec.rate_limits[j];
      const double command = std::clamp(qdot_ref(j) + spec.gain * (q_ref(j) - x.state.q(j)), -limit, limit);
      tau(j) += rec.kv[j] * (command - x.velocity.qdot(j));
    }
  });
  const int rc = sim.run(s, t_start + move.duration(), output_dt, watch);
  rec.pre_grasp_duration = s.t - t_start;
  KDL::Frame G;
  Vector6d twist;
  if (rc == E_NOERROR && controller.grasp(s.t, G, twist) == E_NOERROR) {
    const KDL::Frame pre = G * KDL::Frame(KDL::Vector(0.0, 0.0, -spec.pre_grasp->standoff));
    rec.pre_grasp_miss = (contactFrame(model, s.state, controller.hand()).p - pre.p).Norm();
  }
  return rc;
}

}  // namespace kdl_space::approach_phases
