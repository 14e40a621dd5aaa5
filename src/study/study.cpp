// A study's rows: sample i's inputs drawn (study_sampling), set in the scenario's capture problem,
// the capture solved (CaptureSolver, its robot side kept between samples), and the outcomes.
#include "kdl_space/study/study.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "spatial/message_text.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/operation/motion_measures.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"
#include "study/study_sampling.hpp"
#include "kdl_space/algorithm/self_motion.hpp"
#include "study/target_shape.hpp"

namespace kdl_space {

std::vector<std::string> studyColumns(const Study& study) {
  std::vector<std::string> c{"sample", "status"};
  for (const StudyInput& in : study.inputs) {
    c.push_back(in.name);
    if (sampling::valuesOf(in) == 4)  // the value and its axis (target.tumble, target.inertia.tilt, target.tumble_cone)
      for (const char* a : {".axis_x", ".axis_y", ".axis_z"}) c.push_back(in.name + a);
  }
  for (const char* f : {"impulse.fx", "impulse.fy", "impulse.fz", "impulse.nx", "impulse.ny", "impulse.nz",
                        "impulse.force", "impulse.moment", "base.vx", "base.vy", "base.vz", "base.wx", "base.wy",
                        "base.wz", "base_rate"})
    c.emplace_back(f);
  const std::vector<std::string>& joints = study.scenario.capture.robot.model->jointNames();
  for (const std::string& j : joints) c.push_back("dqdot." + j);
  c.emplace_back("max_dqdot");
  c.emplace_back("energy_lost");
  if (study.motion_duration > 0.0) {
    for (const std::string& j : joints) c.push_back("peak_torque." + j);
    c.emplace_back("peak_base_rate");
  }
  if (study.limits.joint_rate) c.emplace_back("exceeds.joint_rate");
  if (study.limits.joint_torque) c.emplace_back("exceeds.joint_torque");
  if (study.limits.base_rate) c.emplace_back("exceeds.base_rate");
  if (study.limits.joint_rate || study.limits.joint_torque || study.limits.base_rate) c.emplace_back("exceeds.any");
  // Added after the columns above (whose positions stay): the configuration a self-motion value
  // gives (no other column says it), and the joint rates after the capture (the jumps alone do
  // not say what exceeds.joint_rate tests).
  const bool self_motion = std::any_of(study.inputs.begin(), study.inputs.end(),
                                       [](const StudyInput& in) { return in.field == StudyInput::Field::SelfMotion; });
  if (self_motion)
    for (const std::string& j : joints) c.push_back("q." + j);
  for (const std::string& j : joints) c.push_back("qdot." + j);
  if (study.motion_duration > 0.0)  // what the motion did to the tumble (issue 39)
    for (const char* f : {"time_to_detumble", "attitude_excursion", "wheel_momentum_fraction", "energy_dissipated",
                          "peak_grasp_force", "peak_grasp_moment", "peak_torque_ratio"})
      c.emplace_back(f);
  return c;
}

/// What one evaluator keeps between samples.
struct StudyEvaluator::Work {
  CaptureSolver capture;
  CaptureProblem problem;        ///< the sample's (reset from the scenario's each time)
  std::vector<double> drawn;     ///< the sample's inputs
  std::unique_ptr<SelfMotion> self_motion;
  std::unique_ptr<Kinematics> kin;  ///< the hand's pose, when an input moves it
  KDL::Frame hand_nominal;          ///< the contact frame (body axes, at the contact point) at the scenario's state
  Vector3d grasp = Vector3d::Zero();  ///< the nominal grasp point in the target's frame
  bool moves_hand = false, places_target = false;
  std::optional<TargetShape> shape;  ///< the target's principal frame and tumble, with shape or cone inputs
  bool reshapes = false;             ///< a principal moment's factor or the axes' tilt is an input
};

namespace {

/// The contact frame: the contact body's axes, at the contact point.
KDL::Frame handFrame(const Kinematics& kin, const Contact& h) {
  const KDL::Frame body = kin.pose(h.body);
  return KDL::Frame(body.M, body * h.offset);
}

/// The motion after the capture (runMotionAfterCapture: the scenario's simulation section, its PD
/// servos holding the capture configuration): each joint's largest |torque|, the base's largest
/// |w| and the largest |qdot_j| / limit_j, at the output steps. A run that fails: its code.
int motionPeaks(const Study& st, const CaptureProblem& problem, const CaptureResult& r, std::vector<double>& peak,
                double& peak_base_rate, double& rate_ratio, MotionMeasures& detumble) {
  const FloatingModel& robot = *problem.robot.model;
  MotionMeasurer measurer(robot, 0.05, st.scenario.simulation.detumble_rate);  // the peaks, as `plan` reads them
  std::vector<int> in_model;       // the robot's joints in the system after the capture
  OperationOptions o;
  o.duration = st.motion_duration;
  o.output_step = st.motion_output_step;
  o.hold_servos = true;
  o.keep_samples = false;
  o.observer = [&](const OperationResult& so_far, const MotionSample& x) {
    measurer.add(so_far, x);
    if (!st.limits.joint_rate) return;
    if (in_model.size() != robot.nj())
      for (unsigned int j = 0; j < robot.nj(); ++j) in_model.push_back(so_far.model->jointIndex(robot.jointNames()[j]));
    for (unsigned int j = 0; j < robot.nj(); ++j)
      rate_ratio = std::max(rate_ratio, std::abs(x.qd(in_model[j])) / (*st.limits.joint_rate)[j]);
  };
  OperationResult motion;
  try {
    runMotionAfterCapture(st.scenario, problem, r, 0.0, o, motion);
  } catch (const OperationError& e) {  // a run that failed: its code; a refused set-up throws on
    if (e.code() == E_NOERROR) throw;   // (evaluate reports it as the sample's failure, in its words)
    return e.code();
  }
  MotionMeasures m;
  if (const int rc = measurer.finish(motion, m)) return rc;  // the effort ratio with the peaks
  for (unsigned int j = 0; j < robot.nj(); ++j) peak[j] = std::max(peak[j], m.peak_torque[j]);
  peak_base_rate = std::max(peak_base_rate, m.peak_base_rate);
  detumble = m;
  return E_NOERROR;
}

/// The detumble and load columns (studyColumns' last) from the motion's measures.
template <typename Out>
Out detumbleColumns(const MotionMeasures& m, Out out) {
  for (const double v : {m.time_to_detumble, m.attitude_excursion, m.wheel_momentum_fraction, m.energy_dissipated,
                         m.peak_grasp_force, m.peak_grasp_moment, m.peak_torque_ratio})
    *out++ = v;
  return out;
}

}  // namespace

StudyEvaluator::StudyEvaluator(std::shared_ptr<const Study> study)
    : study_(std::move(study)), columns_(studyColumns(*study_).size()), work_(std::make_unique<Work>()) {
  Work& w = *work_;
  const Scenario& sc = study_->scenario;
  w.problem = sc.capture;
  using F = StudyInput::Field;
  for (const StudyInput& in : study_->inputs) {
    w.moves_hand |= in.field == F::JointPosition || in.field == F::SelfMotion || in.field == F::ContactOffset;
    w.places_target |= in.field == F::TargetGrasp || in.field == F::Timing;
    w.reshapes |= in.field == F::TargetPrincipalInertia || in.field == F::TargetInertiaTilt;
    if ((w.reshapes || in.field == F::TargetTumbleCone) && !w.shape)
      w.shape.emplace(std::get<RigidTarget>(sc.capture.target));
    if (in.field == F::SelfMotion && !w.self_motion)
      w.self_motion = std::make_unique<SelfMotion>(sc.capture.robot.model, sc.capture.robot.contact, sc.capture.robot.state);
    w.drawn.resize(w.drawn.size() + static_cast<std::size_t>(sampling::valuesOf(in)));
  }
  const auto* target = std::get_if<RigidTarget>(&sc.capture.target);
  if (target && (w.moves_hand || w.places_target)) {
    w.kin = std::make_unique<Kinematics>(*sc.capture.robot.model);
    if (forwardKinematics(*sc.capture.robot.model, sc.capture.robot.state, *w.kin) != E_NOERROR)
      throw InputError(study_->file + ": the scenario's state cannot be computed");
    w.hand_nominal = handFrame(*w.kin, sc.capture.robot.contact);
    w.grasp = toEigen(target->pose.Inverse() * w.hand_nominal.p);
  }
}

StudyEvaluator::~StudyEvaluator() = default;

std::size_t studyInputCount(const Study& study) {
  std::size_t n = 0;
  for (const StudyInput& in : study.inputs) n += static_cast<std::size_t>(sampling::valuesOf(in));
  return n;
}

std::vector<double> studyDraws(const Study& study, std::uint64_t i) {
  std::vector<double> v(studyInputCount(study));
  sampling::draw(study, i, v.data());
  return v;
}

void StudyEvaluator::evaluate(std::uint64_t i, double* row) { evaluate(i, nullptr, row); }

void StudyEvaluator::evaluate(std::uint64_t i, const double* drawn, double* row) {
  failure_.clear();
  try {
    sample(i, drawn, row);
  } catch (const std::exception& e) {  // a set-up the library refused (an Error): its status, its words
    row[1] = E_BAD_ARGUMENT;
    failure_ = e.what();
  }
}

void StudyEvaluator::sample(std::uint64_t i, const double* drawn, double* row) {
  const Study& st = *study_;
  const Scenario& sc = st.scenario;
  Work& w = *work_;
  std::fill(row, row + columns_, std::numeric_limits<double>::quiet_NaN());
  row[0] = static_cast<double>(i);
  if (drawn)
    std::copy(drawn, drawn + w.drawn.size(), w.drawn.begin());
  else
    sampling::draw(st, i, w.drawn.data());
  std::copy(w.drawn.begin(), w.drawn.end(), row + 2);
  double* out = row + 2 + w.drawn.size();
  // A compute call's code: the status, and what could not be computed for the summary.
  const auto fail = [&](int code, const std::string& what) {
    row[1] = code;
    failure_ = what + ": " + strError(code);
  };

  // The inputs, set in a copy of the scenario's problem: the robot's first, then the target's.
  FloatingSystem& robot = w.problem.robot;
  robot.state = sc.capture.robot.state;
  robot.velocity = sc.capture.robot.velocity;
  robot.contact = sc.capture.robot.contact;
  const auto* target0 = std::get_if<RigidTarget>(&sc.capture.target);
  RigidTarget target = target0 ? *target0 : RigidTarget{};
  double self_motion = 0.0, timing = 0.0, tilt = 0.0;
  Vector3d grasp_shift = Vector3d::Zero(), factor = Vector3d::Ones(), tilt_axis = Vector3d::UnitZ();
  bool tumble = false;
  const double* v = w.drawn.data();
  using F = StudyInput::Field;
  for (const StudyInput& in : st.inputs) {
    const double x = *v;
    switch (in.field) {
      case F::TargetTwist: target.twist(in.index) = x; break;
      case F::TargetTumble: target.twist.tail<3>() = x * Vector3d(v[1], v[2], v[3]), tumble = true; break;
      case F::TargetMass: target.inertia *= x / target.mass, target.mass = x; break;
      case F::TargetGrasp: grasp_shift(in.index) = x; break;
      case F::Timing: timing = x; break;
      case F::JointPosition: robot.state.q(in.index) = x; break;
      case F::JointRate: robot.velocity.qdot(in.index) = x; break;
      case F::SelfMotion: self_motion = x; break;
      case F::ContactOffset: robot.contact.offset.data[in.index] = x; break;
      case F::TargetPrincipalInertia: factor(in.index) = x; break;
      case F::TargetInertiaTilt: tilt = x, tilt_axis = Vector3d(v[1], v[2], v[3]); break;
      case F::TargetTumbleCone:  // the scenario's rate about the cone's axis (with target.tumble: its rate, draw())
        if (!tumble) target.twist.tail<3>() = w.shape->w.norm() * Vector3d(v[1], v[2], v[3]);
        break;
    }
    v += sampling::valuesOf(in);
  }
  if (w.reshapes) target.inertia = w.shape->inertia(factor, tilt, tilt_axis, target.mass);
  if (w.self_motion && self_motion != 0.0)
    if (const int rc = w.self_motion->move(robot.state, self_motion))
      return fail(rc, "robot.self_motion: the arm cannot move " + detail::number(self_motion) + " rad along its self-motion");
  if (target0) {
    if (timing > 0.0) {  // later along the tumble: the attitude and twist then
      FreeRigidMotion motion(target);  // or ModelError "FreeRigidMotion: ..." (a mass drawn <= 0)
      if (const int rc = motion.at(timing, target))
        return fail(rc, "timing: the target's tumble cannot be followed for " + detail::number(timing) + " s");
    }
    if (w.kin) {  // the target rides with the hand: the grasp point (moved by target.grasp) at the contact point
      if (const int rc = forwardKinematics(*robot.model, robot.state, *w.kin))
        return fail(rc, "robot.q: the hand's pose cannot be computed at the sample's joint positions");
      const KDL::Frame hand = handFrame(*w.kin, robot.contact);
      target.pose.M = hand.M * w.hand_nominal.M.Inverse() * target.pose.M;
      target.pose.p = hand.p - target.pose.M * toKDL(w.grasp + grasp_shift);
    }
    w.problem.target = target;
  }
  const CaptureResult* r = &w.capture.solve(w.problem);  // or its Error ("robot: ...", "target: ...")
  const Vector6d F_h = r->impulse.F;
  for (int k = 0; k < 6; ++k) *out++ = F_h(k);
  *out++ = F_h.head<3>().norm();
  *out++ = F_h.tail<3>().norm();
  const Vector6d base = toEigen(r->robot.after.base_twist);
  for (int k = 0; k < 6; ++k) *out++ = base(k);
  const double base_rate = base.tail<3>().norm();
  *out++ = base_rate;
  const unsigned int n = robot.model->nj();
  double max_jump = 0.0;
  for (unsigned int j = 0; j < n; ++j) {
    const double jump = r->robot.after.qdot(j) - r->robot.before.qdot(j);
    *out++ = jump;
    max_jump = std::max(max_jump, std::abs(jump));
  }
  *out++ = max_jump;
  *out++ = r->energyLost();
  // The limits: rates after the impact; the motion's peaks too.
  double rate_ratio = 0.0, torque_ratio = 0.0, peak_base_rate = base_rate;
  MotionMeasures detumble;
  if (st.limits.joint_rate)
    for (unsigned int j = 0; j < n; ++j)
      rate_ratio = std::max(rate_ratio, std::abs(r->robot.after.qdot(j)) / (*st.limits.joint_rate)[j]);
  if (st.motion_duration > 0.0) {
    std::vector<double> peak(n, 0.0);
    if (const int rc = motionPeaks(st, w.problem, *r, peak, peak_base_rate, rate_ratio, detumble))
      return fail(rc, "motion: the motion after the capture cannot be simulated for " + detail::number(st.motion_duration) + " s");
    for (unsigned int j = 0; j < n; ++j) {
      *out++ = peak[j];
      if (st.limits.joint_torque) torque_ratio = std::max(torque_ratio, peak[j] / (*st.limits.joint_torque)[j]);
    }
    *out++ = peak_base_rate;
  }
  bool any = false;
  const auto flag = [&](bool exceeded) {
    *out++ = exceeded ? 1.0 : 0.0;
    any |= exceeded;
  };
  if (st.limits.joint_rate) flag(rate_ratio > 1.0);
  if (st.limits.joint_torque) flag(torque_ratio > 1.0);
  if (st.limits.base_rate) flag(peak_base_rate > *st.limits.base_rate);
  if (st.limits.joint_rate || st.limits.joint_torque || st.limits.base_rate) flag(any);
  if (w.self_motion)
    for (unsigned int j = 0; j < n; ++j) *out++ = robot.state.q(j);
  for (unsigned int j = 0; j < n; ++j) *out++ = r->robot.after.qdot(j);
  if (st.motion_duration > 0.0) out = detumbleColumns(detumble, out);
  row[1] = E_NOERROR;
}

std::vector<double> selfMotionJoints(const Scenario& scenario, double s) {
  const FloatingSystem& robot = scenario.capture.robot;
  SelfMotion motion(robot.model, robot.contact, robot.state);  // or InputError "robot.self_motion: ..."
  State state = robot.state;
  if (const int rc = motion.move(state, s))
    throw InputError("robot.self_motion: the arm cannot move " + detail::number(s) + " rad along its self-motion (" +
                     strError(rc) + "): a singularity lies on the way; give a value closer to 0");
  std::vector<double> q(robot.model->nj());
  for (unsigned int j = 0; j < robot.model->nj(); ++j) q[j] = state.q(j);
  return q;
}

}  // namespace kdl_space
