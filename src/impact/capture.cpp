#include "kdl_space/impact/capture.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "spatial/message_text.hpp"
#include "kdl_space/multibody/kinematics.hpp"

namespace kdl_space {
namespace {

/// A free-floating side; its refusal names the part (`who`: "robot" or "target"). A state whose
/// kinematics cannot be computed is an InputError, anything else the side refuses (a ModelError)
/// keeps its kind and its own words.
std::unique_ptr<FloatingSide> floatingSide(const FloatingSystem& s, ExIITMethod method, const std::string& who) {
  if (!s.model) throw InputError(who + ": no model");
  Kinematics kin(*s.model);
  if (const int rc = forwardKinematics(*s.model, s.state, kin))
    throw InputError(who + ": the free-floating quantities cannot be computed at this state (" + who + ".base, " + who +
                     ".q): " + strError(rc));
  try {
    return std::make_unique<FloatingSide>(s.model, std::move(kin), s.contact, s.velocity, s.response, method,
                                          s.locked);
  } catch (const Error& e) {
    e.rethrowWithContext(who + ": ");
  }
}

/// The contact point of a side, checked (a finite state and offset can still overflow).
Vector3d contactPoint(const FloatingSide& side, const std::string& who) {
  const Vector3d p = side.contactPoint();
  if (!p.allFinite())
    throw InputError(who + ": the contact point cannot be computed: " + std::string(strError(E_NOT_FINITE)));
  return p;
}

/// A side's state before and after, written over r (no allocation once r has the sizes).
void sideResult(const FloatingSide& side, FloatingSideResult& r) {
  r.before = side.before();
  r.after = side.after();
  r.contact_twist_before = side.contactTwistBefore();
  r.contact_twist_after = side.contactTwistAfter();
  r.centroid_twist_before = side.centroidTwistBefore();
  r.centroid_twist_after = side.centroidTwistAfter();
}

/// collide()'s refusal in the words of the part that refused.
[[noreturn]] void refuseImpact(ImpactFault fault, int rc) {
  switch (fault) {
    case ImpactFault::SideA:
      throw InputError("robot: the impulse cannot be applied to the robot: " + std::string(strError(rc)));
    case ImpactFault::SideB:
      throw InputError("target: the impulse cannot be applied to the target: " + std::string(strError(rc)));
    default:
      throw InputError("law: the impact cannot be solved: " + std::string(strError(rc)) +
                       (rc == E_NOT_POSITIVE_DEFINITE ? " (the robot's and the target's inverse inertias at the "
                                                        "contact point, G_robot + G_target, are singular there)"
                                                      : ""));
  }
}

}  // namespace

RigidBody RigidTarget::toWorld() const {
  RigidBody b;
  b.mass = mass;
  const Matrix3d R = toEigen(pose.M);  // world_R_target
  b.I_com = R * inertia * R.transpose();
  b.com = toEigen(pose * toKDL(com));
  b.twist = twist;
  return b;
}

RigidTarget rigidSubtree(const FloatingModel& model, const State& state, int body, const KDL::Twist& base_twist) {
  const std::vector<Body>& bodies = model.bodies();
  if (body < 0 || body >= static_cast<int>(bodies.size())) throw InputError("target: " + std::string(strError(E_BAD_CONTACT)));
  Kinematics kin(model);
  if (const int rc = forwardKinematics(model, state, kin)) throw InputError("target: the state: " + std::string(strError(rc)));
  // The subtree: bodies come parents first, so one pass marks it.
  std::vector<char> in(bodies.size(), 0);
  in[body] = 1;
  for (std::size_t j = body + 1; j < bodies.size(); ++j) in[j] = bodies[j].parent >= 0 && in[bodies[j].parent];
  double m = 0.0;
  Vector3d first_moment = Vector3d::Zero();
  for (std::size_t j = 0; j < bodies.size(); ++j)
    if (in[j]) m += bodies[j].mass, first_moment += bodies[j].mass * kin.com[j];
  if (!(m > 0.0)) throw InputError("target: the links from " + detail::quoted(bodies[body].name) + " down have no mass");
  const Vector3d c = first_moment / m;
  Matrix3d I = Matrix3d::Zero();  // about c, world axes (parallel axes)
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    if (!in[j]) continue;
    const Vector3d r = kin.com[j] - c;
    I += kin.I_com[j] + bodies[j].mass * (r.squaredNorm() * Matrix3d::Identity() - r * r.transpose());
  }
  RigidTarget t;
  t.mass = m;
  t.pose = kin.pose(body);
  const Matrix3d R = toEigen(t.pose.M);
  t.inertia = R.transpose() * I * R;
  t.inertia = 0.5 * (t.inertia + t.inertia.transpose());
  t.com = toEigen(t.pose.Inverse() * toKDL(c));
  const Vector6d V = toEigen(base_twist);  // the whole moves as the base: v_c = v_o + w x (c - p_o)
  t.twist << V.head<3>() + V.tail<3>().cross(c - kin.p_b), V.tail<3>();
  return t;
}

CaptureResult solveCapture(const CaptureProblem& problem) {
  CaptureSolver solver;
  return solver.solve(problem);
}

CaptureSolver::CaptureSolver() = default;
CaptureSolver::~CaptureSolver() = default;

bool CaptureSolver::reusable(const CaptureProblem& problem) const {
  const FloatingSystem& r = problem.robot;
  if (!robot_ || robot_->sharedModel() != r.model || method_ != problem.method || robot_->response() != r.response)
    return false;
  const Contact& h = robot_->contact();
  if (h.body != r.contact.body || h.offset.x() != r.contact.offset.x() || h.offset.y() != r.contact.offset.y() ||
      h.offset.z() != r.contact.offset.z())
    return false;
  const std::vector<bool>& kept = robot_->locked();  // size nj(), all false for none
  if (r.locked.empty()) return std::find(kept.begin(), kept.end(), true) == kept.end();
  return r.locked == kept;
}

const CaptureResult& CaptureSolver::solve(const CaptureProblem& problem) {
  if (!(problem.touch_tolerance >= 0.0) || !std::isfinite(problem.touch_tolerance))
    throw InputError("target.contact: the touch tolerance must be a finite length >= 0, got " +
                     detail::number(problem.touch_tolerance));
  CaptureResult& result = result_;
  // The kept side, reset; a new one (whose refusal names the problem) when it cannot be.
  if (!reusable(problem) || robot_->reset(problem.robot.state, problem.robot.velocity) != E_NOERROR) {
    robot_.reset();
    robot_ = floatingSide(problem.robot, problem.method, "robot");
    method_ = problem.method;
  }
  FloatingSide& robot = *robot_;
  result.contact_point = contactPoint(robot, "robot");
  result.contact_body_pose = robot.kinematics().pose(problem.robot.contact.body);

  std::unique_ptr<FloatingSide> floating_target;
  std::optional<RigidBodySide> rigid_target;
  ImpactSide* target = nullptr;
  if (const RigidTarget* rigid = std::get_if<RigidTarget>(&problem.target)) {
    target = &rigid_target.emplace(rigid->toWorld(), result.contact_point);  // or ModelError "target: ..."
  } else {
    floating_target = floatingSide(std::get<FloatingSystem>(problem.target), problem.method, "target");
    const double gap = (contactPoint(*floating_target, "target") - result.contact_point).norm();
    if (gap > problem.touch_tolerance)
      throw InputError("target.contact: the target's contact point is " + detail::number(gap) +
                       " m from the robot's; they must touch (within " + detail::number(1e3 * problem.touch_tolerance) +
                       " mm)");
    target = floating_target.get();
  }

  ImpactFault fault = ImpactFault::None;
  if (const int rc = collide(robot, *target, problem.law, result.impulse, &fault)) refuseImpact(fault, rc);

  sideResult(robot, result.robot);
  if (rigid_target) {
    result.floating_target.reset();
    result.target_twist_before = rigid_target->twistBefore();
    result.target_twist_after = rigid_target->twistAfter();
  } else {
    // Another free-floating system: its locked twist at its CoM, and its whole state.
    if (!result.floating_target) result.floating_target.emplace();
    sideResult(*floating_target, *result.floating_target);
    result.target_twist_before = floating_target->centroidTwistBefore();
    result.target_twist_after = floating_target->centroidTwistAfter();
  }
  result.G_robot = robot.G();
  result.G_target = target->G();
  result.momentum_before = robot.momentumBefore() + target->momentumBefore();
  result.momentum_after = robot.momentumAfter() + target->momentumAfter();
  result.energy_before = robot.energyBefore() + target->energyBefore();
  result.energy_after = robot.energyAfter() + target->energyAfter();
  double m_v = 0.0;
  result.virtual_mass.reset();
  if (problem.has_normal && virtualMass(result.G_robot, problem.law.normal, m_v) == E_NOERROR) result.virtual_mass = m_v;
  return result;
}

LinkPayload payloadInLink(const RigidTarget& target, const KDL::Frame& world_T_link) {
  const RigidBody b = target.toWorld();
  const Matrix3d R = toEigen(world_T_link.M);
  LinkPayload p;
  p.mass = b.mass;
  p.com = toEigen(world_T_link.Inverse() * toKDL(b.com));
  p.I_com = R.transpose() * b.I_com * R;
  return p;
}

std::shared_ptr<const FloatingModel> attachTarget(const CaptureProblem& problem, const CaptureResult& result) {
  switch (problem.law.kind) {
    case ImpactKind::PointImpact:
    case ImpactKind::FrictionalImpact:
      return problem.robot.model;  // the target separates
    case ImpactKind::TranslationalCapture:
      throw InputError("law.type: simulate does not model a translational capture (the target would turn freely "
                       "about the contact point, a spherical joint); `capture` solves its impact");
    case ImpactKind::Capture:
      break;
    default:
      throw InputError("law.type: not one of the impact laws");
  }
  const RigidTarget* rigid = std::get_if<RigidTarget>(&problem.target);
  if (!rigid)
    throw InputError("target.urdf: simulate does not join two free-floating systems into one after a capture yet; "
                     "`capture` solves the impact");
  const FloatingModel* model = problem.robot.model.get();
  const int link = problem.robot.contact.body;
  if (!model || link < 0 || link >= static_cast<int>(model->bodies().size()))
    throw InputError("robot.contact: " + std::string(strError(E_BAD_CONTACT)));
  const std::string& link_name = model->bodies()[link].name;
  // The target's inertia in the contact link's frame at the capture instant.
  const LinkPayload b = payloadInLink(*rigid, result.contact_body_pose);
  const Matrix3d& I = b.I_com;
  try {
    return std::make_shared<const FloatingModel>(model->withPayload(
        link_name, KDL::RigidBodyInertia(b.mass, toKDL(b.com),
                                         KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)))));
  } catch (const Error& e) {
    e.rethrowWithContext("target: cannot attach the captured target to link " + detail::quoted(link_name) + ": ");
  }
}

}  // namespace kdl_space
