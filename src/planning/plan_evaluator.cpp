// The capture plan's chart, one configuration at a time: the target at the capture instant, the
// hand's goal rolled about the contact frame's z, the inverse kinematics, the self-motion, the
// capture (CaptureSolver, the study's solver), its terms and the limits.
#include "planning/plan_evaluator.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>

#include "spatial/message_text.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/operation/capture_operation.hpp"

namespace kdl_space {
namespace {

constexpr double kPenalty = 1e6;

void checkRange(const PlanRange& r, const char* name, double lowest) {
  if (!std::isfinite(r.lower) || !std::isfinite(r.upper) || r.lower > r.upper)
    throw InputError(std::string(name) + ": the range [" + detail::number(r.lower) + ", " + detail::number(r.upper) +
                     "] is not finite lower <= upper");
  if (r.lower < lowest)
    throw InputError(std::string(name) + ": must be >= " + detail::number(lowest) + ", got " + detail::number(r.lower));
}

}  // namespace

const std::vector<std::string>& planObjectiveTerms() {
  static const std::vector<std::string> terms{
      "base_rate",         "impulse",          "joint_rate_jump",  "peak_base_rate",    "final_base_rate",
      "attitude_excursion", "settling_time",   "peak_torque_ratio", "peak_grasp_force", "peak_grasp_moment",
      "time_to_detumble",  "wheel_momentum_fraction"};
  return terms;
}

bool isOperationTerm(const std::string& term) {
  return term != "base_rate" && term != "impulse" && term != "joint_rate_jump";
}

namespace {

/// A term's value at a configuration (an operation term's from its measures). A stack not
/// detumbled within the horizon scores the horizon times its final rate over the threshold (more
/// than the horizon, and growing with what is left to take out).
double termValue(const std::string& name, const PlanTerms& t, double horizon, double detumble_rate) {
  if (name == "base_rate") return t.base_rate;
  if (name == "impulse") return t.impulse;
  if (name == "joint_rate_jump") return t.joint_rate_jump;
  const MotionMeasures& m = *t.motion;
  if (name == "peak_base_rate") return m.peak_base_rate;
  if (name == "final_base_rate") return m.final_base_rate;
  if (name == "attitude_excursion") return m.attitude_excursion;
  if (name == "settling_time") return m.settling_time;
  if (name == "peak_torque_ratio") return m.peak_torque_ratio;
  if (name == "peak_grasp_force") return m.peak_grasp_force;
  if (name == "time_to_detumble")
    return std::isnan(m.time_to_detumble) ? horizon * m.final_base_rate / detumble_rate : m.time_to_detumble;
  if (name == "wheel_momentum_fraction") return m.wheel_momentum_fraction;
  return m.peak_grasp_moment;
}

}  // namespace

const std::vector<std::string>& planParameters() {
  static const std::vector<std::string> names{"self_motion", "wrist_roll", "timing", "closing_speed"};
  return names;
}

PlanEvaluator::PlanEvaluator(const Scenario& scenario, const PlanOptions& options)
    : scenario_(scenario), options_(options) {
  const std::vector<std::string>& terms = planObjectiveTerms();
  if (options_.weights.empty()) throw InputError("objective: no term given (" + detail::listNames(terms) + ")");
  for (const auto& [name, weight] : options_.weights) {
    if (std::find(terms.begin(), terms.end(), name) == terms.end())
      throw InputError("objective: unknown term '" + name + "' (terms: " + detail::listNames(terms) + ")");
    if (!(weight > 0.0) || !std::isfinite(weight))
      throw InputError("objective: the weight of " + name + " must be finite and > 0, got " + detail::number(weight));
  }
  if (!scenario.impact)
    throw InputError("plan: the scenario has no target and no law: there is no capture to plan");
  if (scenario.capture.robot.model->nj() == 0)
    throw InputError("plan: the robot has no movable joint (a rigid body): there is no configuration to choose; "
                     "`kdl_space capture` solves its capture as it is");
  const FloatingSystem& robot = scenario.capture.robot;
  const auto* rigid = std::get_if<RigidTarget>(&scenario.capture.target);
  // A redundant arm: its self-motion exists at the scenario's state (SelfMotion refuses otherwise).
  try {
    SelfMotion probe(robot.model, robot.contact, robot.state);
    redundant_ = true;
  } catch (const InputError& e) {
    if (options_.self_motion && options_.self_motion->searched())
      throw InputError(std::string("self_motion: cannot be searched: ") + e.what());
  }
  if (!options_.self_motion) options_.self_motion = redundant_ ? PlanRange{-1.0, 1.0} : PlanRange{};
  checkRange(*options_.self_motion, "self_motion", -1e300);
  if (!redundant_ && (options_.self_motion->lower != 0.0 || options_.self_motion->upper != 0.0))
    throw InputError("self_motion: the arm has no one-parameter self-motion: leave its range at 0");
  checkRange(options_.wrist_roll, "wrist_roll", -1e300);
  checkRange(options_.timing, "timing", 0.0);
  if (options_.timing.upper > 0.0 && !rigid)
    throw InputError("timing: only a rigid target's tumble can be followed (the target is free-floating)");
  if (options_.closing_speed) checkRange(*options_.closing_speed, "closing_speed", 0.0);
  if (!options_.self_motion->searched() && !options_.wrist_roll.searched() && !options_.timing.searched() &&
      !(options_.closing_speed && options_.closing_speed->searched()))
    throw InputError("plan: nothing to plan: no parameter has a range (self_motion, wrist_roll, timing, closing_speed)");
  if (options_.scan < 2) throw InputError("scan: at least 2 points per parameter, got " + std::to_string(options_.scan));
  if (options_.scan_limit < 2) throw InputError("scan_limit: at least 2 points, got " + std::to_string(options_.scan_limit));
  hand0_ = contactFrame(*robot.model, robot.state, robot.contact);
  if (rigid && options_.timing.upper > 0.0) tumble_.emplace(*rigid);  // or ModelError "FreeRigidMotion: ..."
  problem_ = scenario.capture;
  if (rigid) target_at_ = *rigid;
  if (options_.closing_speed) setUpClosing();
  setUpMotion();
}

void PlanEvaluator::setUpMotion() {
  for (const auto& [name, weight] : options_.weights) score_motion_ |= isOperationTerm(name);
  if (options_.horizon && !(*options_.horizon > 0.0 && std::isfinite(*options_.horizon)))
    throw InputError("horizon: must be finite and > 0 [s], got " + detail::number(*options_.horizon));
  if (options_.output_step && !(*options_.output_step > 0.0 && std::isfinite(*options_.output_step)))
    throw InputError("output_step: must be finite and > 0 [s], got " + detail::number(*options_.output_step));
  if (!score_motion_ && !options_.horizon) return;
  horizon_ = options_.horizon.value_or(scenario_.simulation.duration);
  const FloatingModel& robot = *scenario_.capture.robot.model;
  for (const auto& [name, weight] : options_.weights) {
    if ((name == "peak_grasp_force" || name == "peak_grasp_moment") && !holdsTarget(scenario_))
      throw InputError("objective: " + name + " is the load of a grasp that holds the target; the scenario's law "
                       "lets it go (a point or frictional impact: its load is an impulse, the term impulse): give "
                       "law.type capture or compliant, or another term");
    if (name == "peak_torque_ratio" &&
        std::none_of(robot.jointProperties().begin(), robot.jointProperties().end(), [](const JointProperties& p) {
          return p.effort > 0.0 && std::isfinite(p.effort);
        }))
      throw InputError("objective: peak_torque_ratio: no joint of the robot has an effort limit (the URDF's "
                       "<limit effort=...>): give them, or another term");
  }
  measurer_.emplace(robot, options_.settling_band, scenario_.simulation.detumble_rate);  // or InputError "settling_band: ..."
}

bool PlanEvaluator::measured(PlanTerms& t) {
  OperationOptions o;
  o.duration = horizon_;
  o.output_step = options_.output_step;
  o.hold_servos = true;  // the servos hold the planned configuration, not the scenario's set points
  o.keep_samples = false;
  o.cancelled = options_.cancelled;
  measurer_->reset();
  o.observer = [this](const OperationResult& so_far, const MotionSample& x) { measurer_->add(so_far, x); };
  MotionMeasures m;
  try {
    const OperationResult r = runOperationFrom(scenario_, problem_, o);
    if (const int rc = measurer_->finish(r, m)) {
      t.infeasible = std::string("the motion after the capture: the stack's momentum rate: ") + strError(rc);
      return false;
    }
  } catch (const Error& e) {  // a motion that failed (blew up, out of steps, cancelled), or refused
    t.infeasible = std::string("the motion after the capture: ") + e.what();
    return false;
  }
  t.motion = m;
  return true;
}

void PlanEvaluator::setUpClosing() {
  const FloatingSystem& robot = scenario_.capture.robot;
  if (robot.response == Response::JointsLocked)
    throw InputError("closing_speed: the robot's joints are locked at the capture (its response): the hand cannot be "
                     "moved to close on the grasp; plan with free joints");
  // The system's momentum is what the scenario's state gives: the arm's rates before the capture
  // change, the servicer's momentum does not (the base moves as they make it: MATH.md eq. 4).
  dynamics_ = std::make_unique<FreeFloatingSolver>(robot.model, FreeFloatingSolver::Extent::Jacobians);
  if (const int rc = dynamics_->compute(robot.state))
    throw ModelError(std::string("closing_speed: the robot's dynamics at the scenario's state: ") + strError(rc));
  if (const int rc = dynamics_->momentum(robot.velocity.base_twist, robot.velocity.qdot, PL_g_))
    throw ModelError(std::string("closing_speed: the robot's momentum at the scenario's state: ") + strError(rc));
  if (const auto* other = std::get_if<FloatingSystem>(&scenario_.capture.target)) {
    // A free-floating target stays where the scenario puts it (timing is for a rigid one): its
    // grasp point's twist, once.
    FreeFloatingSolver target(other->model, FreeFloatingSolver::Extent::Jacobians);
    Vector6d PL_g;
    KDL::Twist t;
    int rc = target.compute(other->state);
    if (!rc) rc = target.momentum(other->velocity.base_twist, other->velocity.qdot, PL_g);
    if (!rc) rc = target.handTwist(other->contact, other->velocity.qdot, PL_g, t);
    if (rc) throw ModelError(std::string("closing_speed: the target's grasp point twist: ") + strError(rc));
    floating_target_twist_ = toEigen(t);
  }
}

bool PlanEvaluator::closing(FloatingSystem& robot, double speed, std::string& why) {
  const FloatingModel& model = *robot.model;
  const unsigned int n = model.nj();
  if (const int rc = dynamics_->compute(robot.state)) {
    why = std::string("closing_speed: the robot's dynamics cannot be computed here (") + strError(rc) + ")";
    return false;
  }
  // The twist the hand must have: the grasp point's on the target, plus the closing speed along
  // the contact frame's z (the approach axis); no rotation relative to the target.
  const KDL::Frame hand = contactFrame(model, robot.state, robot.contact);
  Vector6d t_h = floating_target_twist_;
  if (std::holds_alternative<RigidTarget>(problem_.target)) {
    const RigidTarget& target = std::get<RigidTarget>(problem_.target);
    const Vector3d com = toEigen(target.pose * toKDL(target.com));
    t_h = target.twist;
    t_h.head<3>() += target.twist.tail<3>().cross(toEigen(hand.p) - com);
  }
  t_h.head<3>() += speed * toEigen(hand.M.UnitZ());
  // What the joints must add to the twist the hand has with them still: the momentum's share
  // R_h M_a^-1 (P_g; L_g) free-floating (eq. 4), the base's twist carried to h when grounded.
  KDL::Jacobian jac(n);
  KDL::Twist still;
  int rc = 0;
  const bool grounded = robot.response == Response::Grounded;
  if (grounded) {
    rc = dynamics_->J(robot.contact, jac);
    still = robot.velocity.base_twist.RefPoint(hand.p - robot.state.world_T_base.p);
  } else {
    rc = dynamics_->J_star(robot.contact, jac);
    if (!rc) rc = dynamics_->handTwist(robot.contact, KDL::JntArray(n), PL_g_, still);
  }
  if (rc) {
    why = std::string("closing_speed: the hand's Jacobian cannot be computed here (") + strError(rc) + ")";
    return false;
  }
  Eigen::MatrixXd A = jac.data;
  for (unsigned int j = 0; j < n && !robot.locked.empty(); ++j)
    if (robot.locked[j]) A.col(j).setZero();  // braked: its rate stays 0
  const Vector6d b = t_h - toEigen(still);
  // The smallest joint rates that give it (J*+; a redundant arm's self-motion rate is 0).
  const Eigen::VectorXd qdot = A.completeOrthogonalDecomposition().solve(b);
  const double miss = (A * qdot - b).norm();
  if (!qdot.allFinite() || miss > 1e-9 * std::max(1.0, b.norm())) {
    why = "closing_speed: the arm cannot give the hand the grasp point's twist (it misses by " + detail::number(miss) +
          "): fewer than 6 free joints, or a singular configuration";
    return false;
  }
  robot.velocity.qdot.data = qdot;
  if (!grounded && (rc = dynamics_->baseTwist(PL_g_, robot.velocity.qdot, robot.velocity.base_twist))) {
    why = std::string("closing_speed: the base's twist cannot be computed (") + strError(rc) + ")";
    return false;
  }
  return true;
}

bool PlanEvaluator::handPlaced(const PlanPoint& x, std::string& why) {
  const std::pair<double, double> key{x.wrist_roll, x.timing};
  if (placed_key_ && *placed_key_ == key) {
    why = placed_why_;
    return placed_ok_;
  }
  placed_key_ = key;
  placed_ok_ = false;
  placed_why_.clear();
  self_motion_.reset();
  const FloatingSystem& robot = scenario_.capture.robot;
  placed_ = robot.state;
  KDL::Frame grasp = hand0_;  // G(t): the grasp frame riding with the target
  if (const auto* rigid = std::get_if<RigidTarget>(&scenario_.capture.target)) {
    target_at_ = *rigid;
    if (x.timing > 0.0) {
      if (tumble_->at(x.timing, target_at_) != E_NOERROR) {
        placed_why_ = "timing: the target's tumble cannot be followed to " + detail::number(x.timing) + " s";
        why = placed_why_;
        return false;
      }
      grasp = target_at_.pose * rigid->pose.Inverse() * hand0_;
    }
  }
  if (x.wrist_roll != 0.0 || x.timing != 0.0) {
    IkOptions o;  // the scenario's branch: from its state, no restarts elsewhere (capture_plan.hpp)
    o.preferred = robot.state.q;
    o.restarts = 0;
    o.measure_reaction = false;
    try {
      placed_.q = solveInverseKinematics(*robot.model, robot.state, robot.contact, grasp * KDL::Frame(KDL::Rotation::RotZ(x.wrist_roll)), o).q;
    } catch (const InputError& e) {  // IkUnreachable: out of reach within the limits
      placed_why_ = std::string("the hand cannot reach the grasp: ") + e.what();
      why = placed_why_;
      return false;
    }
  }
  placed_ok_ = true;
  return true;
}

double PlanEvaluator::violation(const FloatingSystem& robot, const KDL::JntArray& qdot_after, bool rates_before,
                                std::string& why) const {
  const FloatingModel& model = *robot.model;
  double v = 0.0;
  for (unsigned int j = 0; j < model.nj(); ++j) {
    const JointProperties& p = model.jointProperties()[j];
    const double q = robot.state.q(j);
    const double outside = std::max(p.lower - q, q - p.upper);
    const double over = std::abs(qdot_after(j)) - p.velocity;
    // The rates before the capture are the scenario's unless the plan sets them (closing_speed).
    const double before = rates_before ? std::abs(robot.velocity.qdot(j)) - p.velocity : 0.0;
    if (outside > 0.0 && why.empty())
      why = "joint " + model.jointNames()[j] + " at " + detail::number(q) + ", outside its limits [" +
            detail::number(p.lower) + ", " + detail::number(p.upper) + "]";
    if (before > 0.0 && why.empty())
      why = "joint " + model.jointNames()[j] + ": rate " + detail::number(robot.velocity.qdot(j)) +
            " before the capture (closing on the grasp), over its velocity limit " + detail::number(p.velocity);
    if (over > 0.0 && why.empty())
      why = "joint " + model.jointNames()[j] + ": rate " + detail::number(qdot_after(j)) +
            " after the capture, over its velocity limit " + detail::number(p.velocity);
    v += std::max(outside, 0.0) + std::max(over, 0.0) + std::max(before, 0.0);
  }
  return v;
}

PlanTerms PlanEvaluator::evaluate(const PlanPoint& x, CapturePlan* joints, bool measure) {
  PlanTerms t;
  t.objective = std::numeric_limits<double>::quiet_NaN();
  if (!handPlaced(x, t.infeasible)) return t;
  FloatingSystem& robot = problem_.robot;
  robot.state = placed_;
  if (x.self_motion != 0.0 && !self_motion_) {  // built at the placed joints (selfMotionJoints' start)
    try {
      self_motion_ = std::make_unique<SelfMotion>(robot.model, robot.contact, placed_);
    } catch (const InputError& e) {
      t.infeasible = e.what();
      return t;
    }
  }
  if (x.self_motion != 0.0)
    if (const int rc = self_motion_->move(robot.state, x.self_motion)) {
      t.infeasible = "self_motion: the arm cannot move " + detail::number(x.self_motion) + " rad along its self-motion (" +
                     strError(rc) + ")";
      return t;
    }
  if (std::holds_alternative<RigidTarget>(problem_.target)) problem_.target = target_at_;
  robot.velocity = scenario_.capture.robot.velocity;
  const bool closes = dynamics_ && !std::isnan(x.closing_speed);
  if (closes && !closing(robot, x.closing_speed, t.infeasible)) return t;
  const CaptureResult* r = nullptr;
  try {
    r = &capture_.solve(problem_);
  } catch (const Error& e) {
    t.infeasible = std::string("the capture cannot be computed: ") + e.what();
    return t;
  }
  const unsigned int n = robot.model->nj();
  std::vector<double> q(n);
  for (unsigned int j = 0; j < n; ++j) {
    q[j] = robot.state.q(j);
    t.joint_rate_jump = std::max(t.joint_rate_jump, std::abs(r->robot.after.qdot(j) - r->robot.before.qdot(j)));
  }
  t.base_rate = toEigen(r->robot.after.base_twist).tail<3>().norm();
  t.impulse = r->impulse.F.head<3>().norm();
  if ((score_motion_ || (measure && measurer_)) && !measured(t)) return t;
  t.objective = 0.0;
  for (const auto& [name, weight] : options_.weights)
    t.objective += weight * termValue(name, t, horizon_, scenario_.simulation.detumble_rate);
  t.violation = violation(robot, r->robot.after.qdot, closes, t.infeasible);
  t.feasible = t.violation == 0.0 && std::isfinite(t.objective);
  if (joints) {
    joints->q = q;
    joints->qdot_before.assign(robot.velocity.qdot.data.data(), robot.velocity.qdot.data.data() + n);
    const Vector6d base = toEigen(robot.velocity.base_twist);
    joints->base_twist_before.assign(base.data(), base.data() + 6);
    joints->qdot_after.assign(r->robot.after.qdot.data.data(), r->robot.after.qdot.data.data() + n);
  }
  return t;
}

double PlanEvaluator::score(const PlanTerms& t) {
  if (t.feasible) return t.objective;
  // Outside the limits: the penalty grows with the excess, which leads the optimiser back inside;
  // a configuration that cannot be reached or computed scores above every computed one.
  return std::isfinite(t.objective) ? kPenalty + t.violation : 2.0 * kPenalty;
}

}  // namespace kdl_space
