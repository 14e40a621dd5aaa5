#include "kdl_space/impact/joined_system.hpp"

#include <Eigen/LU>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "spatial/message_text.hpp"
#include "multibody/model_build.hpp"

namespace kdl_space {
namespace {

using detail::quoted;
using Element = KDL::SegmentMap::const_iterator;

bool isRotational(KDL::Joint::JointType t) {
  return t == KDL::Joint::RotAxis || t == KDL::Joint::RotX || t == KDL::Joint::RotY || t == KDL::Joint::RotZ;
}
bool isTranslational(KDL::Joint::JointType t) {
  return t == KDL::Joint::TransAxis || t == KDL::Joint::TransX || t == KDL::Joint::TransY || t == KDL::Joint::TransZ;
}

/// Every link (segment) name and every named joint of a tree but the root's.
std::set<std::string> namesOf(const KDL::Tree& tree) {
  std::set<std::string> names;
  for (const auto& [name, element] : tree.getSegments()) {
    names.insert(name);
    if (name == tree.getRootSegment()->first) continue;
    const KDL::Joint& j = GetTreeElementSegment(element).getJoint();
    if (!(j.getType() == KDL::Joint::None && j.getName() == "NoName")) names.insert(j.getName());
  }
  return names;
}

/// A name not in `used` (`base`, else base_2, base_3...), then marked used.
std::string unique(const std::string& base, std::set<std::string>& used) {
  std::string name = base;
  for (int k = 2; used.count(name) > 0; ++k) name = base + "_" + std::to_string(k);
  used.insert(name);
  return name;
}

KDL::Joint renamed(const KDL::Joint& j, const std::string& name) {
  if (j.getType() == KDL::Joint::None) return KDL::Joint(name, KDL::Joint::None);
  if (isRotational(j.getType())) return KDL::Joint(name, j.JointOrigin(), j.JointAxis(), KDL::Joint::RotAxis);
  return KDL::Joint(name, j.JointOrigin(), j.JointAxis(), KDL::Joint::TransAxis);
}

/// The segment from the child link back to its parent link: the same joint line, reversed
/// (coordinate negated); it carries the parent link (name, inertia in its own frame).
KDL::Segment reversed(const KDL::Segment& s, const std::string& parent_name, const std::string& joint_name,
                      const KDL::RigidBodyInertia& parent_inertia) {
  const KDL::Joint& j = s.getJoint();
  const KDL::Frame f0_inv = s.pose(0.0).Inverse();
  KDL::Joint joint(joint_name, KDL::Joint::None);
  if (isRotational(j.getType()) || isTranslational(j.getType()))
    joint = KDL::Joint(joint_name, f0_inv * j.JointOrigin(), f0_inv.M * j.JointAxis(),
                       isRotational(j.getType()) ? KDL::Joint::RotAxis : KDL::Joint::TransAxis);
  else if (j.getType() != KDL::Joint::None)
    detail::fail("joint", j.getName(), "cannot be reversed to re-root the target (a KDL joint type other than "
                                       "revolute, prismatic or fixed)");
  const KDL::Segment back(parent_name, joint, f0_inv, parent_inertia);
  // The reversed segment at -x undoes the original at x (catches a scaled KDL joint).
  const double x = 0.7;
  const KDL::Frame round_trip = s.pose(x) * back.pose(-x);
  if (!KDL::Equal(round_trip, KDL::Frame::Identity(), 1e-9 * (1.0 + s.pose(0.0).p.Norm())))
    detail::fail("joint", j.getName(), "cannot be reversed to re-root the target (a scaled KDL joint)");
  return back;
}

/// The link and joint names the target's get in the joined tree.
struct Naming {
  std::string prefix;
  std::string link(const std::string& n) const { return prefix + n; }
};

/// Copies the subtree below `from` (children but `skip`) under `hook`, names prefixed.
void hangChildren(Element from, const std::string& skip, const std::string& hook, const Naming& nm,
                  KDL::Tree& joined) {
  for (const Element child : GetTreeElementChildren(from->second)) {
    if (child->first == skip) continue;
    const KDL::Segment& s = GetTreeElementSegment(child->second);
    const KDL::Segment copy(nm.link(s.getName()), renamed(s.getJoint(), nm.link(s.getJoint().getName())),
                            s.pose(0.0), s.getInertia());
    if (!KDL::Equal(copy.pose(0.7), s.pose(0.7), 1e-9 * (1.0 + s.pose(0.0).p.Norm())))
      detail::fail("joint", s.getJoint().getName(), "cannot be copied into the joined tree (a scaled KDL joint)");
    if (!joined.addSegment(copy, hook)) detail::fail("link", copy.getName(), "cannot be added to the joined tree");
    hangChildren(child, "", copy.getName(), nm, joined);
  }
}

void add(KDL::Tree& joined, const KDL::Segment& s, const std::string& hook) {
  if (!joined.addSegment(s, hook)) detail::fail("link", s.getName(), "cannot be added to the joined tree");
}

/// Columns: the ball joint's axes (rz, ry, rx) in the robot contact link's axes at angles q1, q2.
Matrix3d ballAxes(double q1, double q2) {
  const KDL::Rotation R1 = KDL::Rotation::RotZ(q1), R2 = R1 * KDL::Rotation::RotY(q2);
  Matrix3d A;
  A.col(0) = Vector3d::UnitZ();
  A.col(1) = toEigen(R1 * KDL::Vector(0, 1, 0));
  A.col(2) = toEigen(R2 * KDL::Vector(1, 0, 0));
  return A;
}

/// Kinematics and contact twist of one side (its state, a velocity after), or InputError.
struct SideView {
  Kinematics kin;
  Vector6d t = Vector6d::Zero();  ///< contact twist after
  Vector3d point = Vector3d::Zero();
};
SideView view(const FloatingSystem& s, const FloatingVelocity& after, const std::string& who) {
  if (!s.model) throw InputError(who + ": no model");
  const FloatingModel& m = *s.model;
  if (s.contact.body < 0 || s.contact.body >= static_cast<int>(m.bodies().size()) || !allFinite(s.contact.offset))
    throw InputError(who + ".contact: " + strError(E_BAD_CONTACT));
  SideView v{Kinematics(m)};
  if (const int rc = forwardKinematics(m, s.state, v.kin))
    throw InputError(who + ": the state (" + who + ".base, " + who + ".q) cannot be used: " + strError(rc));
  MomentumSolver momentum(s.model);
  if (const int rc = momentum.compute(v.kin, after))
    throw InputError(who + ": the velocity after the capture cannot be used: " + strError(rc));
  momentum.contactTwist(s.contact, v.t);
  v.point = v.kin.point(s.contact);
  return v;
}

/// The grasp and the touch tolerance asked for, and a target the join supports (no mimic joints).
void checkGrasp(const FloatingSystem& target, GraspJoint grasp, double touch_tolerance) {
  if (grasp != GraspJoint::Rigid && grasp != GraspJoint::Spherical && grasp != GraspJoint::Compliant)
    throw InputError("grasp: not one of the grasp joints");
  if (!(touch_tolerance >= 0.0) || !std::isfinite(touch_tolerance))
    throw InputError("target.contact: the touch tolerance must be a finite length >= 0, got " +
                     detail::number(touch_tolerance));
  if (target.model && !target.model->mimic().empty()) {
    std::vector<std::string> names;
    for (const Mimic& m : target.model->mimic()) names.push_back(quoted(m.joint));
    throw InputError("target: the model has mimic joints (" + detail::listNames(names) +
                     "): joining a target with mimic joints to the robot is not supported yet");
  }
}

/// The contact points touch, and (but for a compliant grasp) move together after the capture, as
/// the capture law leaves them (else the joined velocity would not continue both motions).
void checkTouching(const SideView& r, const SideView& t, GraspJoint grasp, double touch_tolerance) {
  const double gap = (t.point - r.point).norm();
  if (!(gap <= touch_tolerance))
    throw InputError("target.contact: the target's contact point is " + detail::number(gap) +
                     " m from the robot's; they must touch (within " + detail::number(touch_tolerance) + " m)");
  const Vector6d dt = t.t - r.t;
  const double scale = r.t.norm() + t.t.norm();
  const double mismatch = grasp == GraspJoint::Rigid ? dt.norm() : dt.head<3>().norm();
  if (grasp != GraspJoint::Compliant && !(mismatch <= 1e-6 * scale + 1e-12))
    throw InputError(std::string("grasp: the contact points do not move together after the capture (") +
                     (grasp == GraspJoint::Rigid ? "twists" : "linear velocities") + " differ by " +
                     detail::number(mismatch) + "): give the velocities after a " +
                     (grasp == GraspJoint::Rigid ? "capture" : "translational capture"));
}

/// Each joint's armature in the joined tree's joint order (the target's by their prefixed names).
std::vector<double> jointArmature(const KDL::Tree& joined, const FloatingModel& rm, const FloatingModel& tm,
                                  const Naming& nm) {
  std::map<std::string, double> armature_by_name;
  for (unsigned int j = 0; j < rm.nj(); ++j) armature_by_name[rm.jointNames()[j]] = rm.armature()[j];
  for (unsigned int j = 0; j < tm.nj(); ++j) armature_by_name[nm.link(tm.jointNames()[j])] = tm.armature()[j];
  std::vector<double> armature(joined.getNrOfJoints(), 0.0);
  for (const auto& [name, element] : joined.getSegments()) {
    const KDL::Joint& j = GetTreeElementSegment(element).getJoint();
    if (j.getType() == KDL::Joint::None) continue;
    const auto a = armature_by_name.find(j.getName());
    if (a != armature_by_name.end()) armature[GetTreeElementQNr(element)] = a->second;
  }
  return armature;
}

/// The joints' properties by name in the joined model; a reversed target joint's limits negated.
std::map<std::string, JointProperties> jointProperties(const FloatingModel& rm, const FloatingModel& tm, const Naming& nm,
                                                       const std::map<std::string, double>& sign_of) {
  std::map<std::string, JointProperties> props;
  for (unsigned int j = 0; j < rm.nj(); ++j) props[rm.jointNames()[j]] = rm.jointProperties()[j];
  for (unsigned int j = 0; j < tm.nj(); ++j) {
    JointProperties p = tm.jointProperties()[j];
    if (sign_of.count(tm.jointNames()[j])) {  // q negated: [lower, upper] -> [-upper, -lower]
      const double lower = p.lower;
      p.lower = -p.upper;
      p.upper = -lower;
    }
    props[nm.link(tm.jointNames()[j])] = p;
  }
  return props;
}

/// The grasp joints' rates after the capture (js.grasp_joints set): a ball's, the relative angular
/// velocity in the robot contact link's axes; a compliant grasp's slides too.
void graspRates(JoinedSystem& js, const KDL::Frame& W_r, const SideView& r, const SideView& t) {
  if (js.grasp == GraspJoint::Spherical) {
    // The relative angular velocity in the robot contact link's axes = ballAxes * rates.
    const Vector3d w_rel = toEigen(W_r.M).transpose() * (t.t.tail<3>() - r.t.tail<3>());
    const Vector3d rates = ballAxes(0.0, 0.0).fullPivLu().solve(w_rel);
    for (int k = 0; k < 3; ++k) js.velocity.qdot(js.grasp_joints[k]) = rates(k);
  }
  if (js.grasp == GraspJoint::Compliant) {
    // The target's material point at the robot's contact point, relative to the robot's, in the
    // robot contact link's axes (the slides' rates); the relative rotation in the ball's axes.
    const Matrix3d R = toEigen(W_r.M);
    const Vector3d v_t = t.t.head<3>() + t.t.tail<3>().cross(r.point - t.point);
    const Vector3d slide_rates = R.transpose() * (v_t - r.t.head<3>());
    const Vector3d ball_rates = ballAxes(0.0, 0.0).fullPivLu().solve(R.transpose() * (t.t.tail<3>() - r.t.tail<3>()));
    for (int k = 0; k < 3; ++k) {
      js.velocity.qdot(js.grasp_joints[k]) = slide_rates(k);
      js.velocity.qdot(js.grasp_joints[3 + k]) = ball_rates(k);
    }
  }
}

}  // namespace

JoinedSystem joinAtGrasp(const FloatingSystem& robot, const FloatingVelocity& robot_after,
                         const FloatingSystem& target, const FloatingVelocity& target_after, GraspJoint grasp,
                         double touch_tolerance) {
  checkGrasp(target, grasp, touch_tolerance);
  const SideView r = view(robot, robot_after, "robot"), t = view(target, target_after, "target");
  checkTouching(r, t, grasp, touch_tolerance);

  const FloatingModel& rm = *robot.model;
  const FloatingModel& tm = *target.model;
  const KDL::Tree& rtree = rm.tree();
  const KDL::Tree& ttree = tm.tree();
  std::set<std::string> used = namesOf(rtree);
  Naming nm;
  const std::set<std::string> target_names = namesOf(ttree);
  for (const std::string& n : target_names)
    if (used.count(n)) nm.prefix = "target/";
  for (const std::string& n : target_names)
    if (used.count(nm.link(n)))
      detail::fail("link", nm.link(n), "is a name of both the robot and the target, even prefixed");
  for (const std::string& n : target_names) used.insert(nm.link(n));

  // The robot's tree, then the grasp.
  KDL::Tree joined = rtree;
  const std::string& robot_link = rm.bodies()[robot.contact.body].name;
  const KDL::Frame W_r = r.kin.pose(robot.contact.body), W_t = t.kin.pose(target.contact.body);
  std::string hook = robot_link;
  KDL::Frame hook_pose = W_r;  // world pose of the hook's frame at the join
  JoinedSystem js;
  js.grasp = grasp;
  js.target_prefix = nm.prefix;
  std::vector<std::string> ball;
  if (grasp == GraspJoint::Spherical || grasp == GraspJoint::Compliant) {
    // Compliant: x, y, z prismatic, then the ball's rz, ry, rx, all through the contact point.
    const KDL::Vector o = robot.contact.offset;
    const bool slide = grasp == GraspJoint::Compliant;
    const char* axes[6] = {"x", "y", "z", "rz", "ry", "rx"};
    const KDL::Vector dirs[6] = {KDL::Vector(1, 0, 0), KDL::Vector(0, 1, 0), KDL::Vector(0, 0, 1),
                                 KDL::Vector(0, 0, 1), KDL::Vector(0, 1, 0), KDL::Vector(1, 0, 0)};
    for (int k = slide ? 0 : 3; k < 6; ++k) {
      const std::string joint = unique(std::string("grasp_") + axes[k], used);
      const std::string link = unique(joint + "_link", used);
      const KDL::Vector origin = k == (slide ? 0 : 3) ? o : KDL::Vector::Zero();
      const KDL::Joint::JointType type = k < 3 ? KDL::Joint::TransAxis : KDL::Joint::RotAxis;
      add(joined, KDL::Segment(link, KDL::Joint(joint, origin, dirs[k], type), KDL::Frame(origin)), hook);
      ball.push_back(joint);
      hook = link;
    }
    hook_pose = W_r * KDL::Frame(o);
  }
  const std::string grasp_name = unique("grasp", used);

  // The target re-rooted: its contact link on the hook, then up the path to its old base.
  const std::vector<Body>& tb = tm.bodies();
  const auto inertiaOf = [&](int body) {
    return body == 0 ? detail::kdlInertia(tb[0]) : tb[body].segment.getInertia();
  };
  std::map<std::string, double> sign_of;  // by the target's joint name
  int body = target.contact.body;
  add(joined, KDL::Segment(nm.link(tb[body].name), KDL::Joint(grasp_name, KDL::Joint::None), hook_pose.Inverse() * W_t,
                           inertiaOf(body)),
      hook);
  std::string skip;
  while (true) {
    const Element element = ttree.getSegment(tb[body].name);
    hangChildren(element, skip, nm.link(tb[body].name), nm, joined);
    if (body == 0) break;
    const KDL::Segment& s = tb[body].segment;
    const int parent = tb[body].parent;
    add(joined, reversed(s, nm.link(tb[parent].name), nm.link(s.getJoint().getName()), inertiaOf(parent)),
        nm.link(tb[body].name));
    sign_of[s.getJoint().getName()] = -1.0;
    skip = tb[body].name;
    body = parent;
  }

  // Armature (tree joint order), the robot's mimic joints, then the properties by name.
  const std::vector<double> armature = jointArmature(joined, rm, tm, nm);
  std::vector<Diagnostic> notes{{"", "joined after a capture: the target re-rooted at its contact link " +
                                         quoted(nm.link(tb[target.contact.body].name)) + ", hung on " +
                                         quoted(robot_link) +
                                         (grasp == GraspJoint::Rigid       ? " by a fixed joint"
                                          : grasp == GraspJoint::Spherical ? " by a ball joint"
                                                                           : " by a compliant 6-joint grasp"),
                                 "joined", Severity::Note}};
  FloatingModel model(joined, detail::kdlInertia(rm.bodies()[0]), armature, notes, rm.mimic());
  js.model = std::make_shared<const FloatingModel>(model.withJointProperties(jointProperties(rm, tm, nm, sign_of)));
  const FloatingModel& jm = *js.model;

  // Where each joint went; the state and velocity.
  const auto indexOf = [&](const std::string& name, const std::string& side) {
    const int i = jm.jointIndex(name);
    if (i < 0) detail::fail("joint", name, "of the " + side + " is no coordinate of the joined model");
    return i;
  };
  js.state = State(jm);
  js.state.world_T_base = robot.state.world_T_base;
  js.velocity = FloatingVelocity(jm);
  js.velocity.base_twist = robot_after.base_twist;
  for (unsigned int j = 0; j < rm.nj(); ++j) {
    js.robot_joints.push_back(indexOf(rm.jointNames()[j], "robot"));
    js.state.q(js.robot_joints[j]) = robot.state.q(j);
    js.velocity.qdot(js.robot_joints[j]) = robot_after.qdot(j);
  }
  for (unsigned int j = 0; j < tm.nj(); ++j) {
    js.target_joints.push_back(indexOf(nm.link(tm.jointNames()[j]), "target"));
    js.target_joint_sign.push_back(sign_of.count(tm.jointNames()[j]) ? -1.0 : 1.0);
    js.state.q(js.target_joints[j]) = js.target_joint_sign[j] * target.state.q(j);
    js.velocity.qdot(js.target_joints[j]) = js.target_joint_sign[j] * target_after.qdot(j);
  }
  if (grasp != GraspJoint::Rigid) {
    for (const std::string& b : ball) js.grasp_joints.push_back(indexOf(b, "grasp"));
    graspRates(js, W_r, r, t);
  }
  return js;
}

double sphericalChartMargin(const JoinedSystem& joined, const State& state) {
  if (joined.grasp_joints.empty()) return 1.0;
  if (!joined.model || state.q.rows() != joined.model->nj())
    throw InputError("state.q: " + std::string(strError(E_SIZE_MISMATCH)) + " (the joined model's joints)");
  return std::abs(std::cos(state.q(joined.grasp_joints[joined.grasp_joints.size() - 2])));  // ry
}

}  // namespace kdl_space
