#include "kdl_space/parsers/scenario/scenario.hpp"

#include <cmath>
#include <filesystem>

#include "spatial/message_text.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "multibody/model_rules.hpp"
#include "parsers/scenario/scenario_actuators.hpp"
#include "parsers/scenario/scenario_approach.hpp"
#include "parsers/scenario/scenario_fields.hpp"
#include "parsers/scenario/scenario_mount.hpp"
#include "parsers/scenario/scenario_law.hpp"
#include "parsers/scenario/scenario_sections.hpp"

namespace kdl_space {
namespace {

using detail::listNames;
using detail::number;
using fields::echo;
using fields::Field;
using fields::pose;

std::vector<std::string> linkNames(const FloatingModel& model) {
  std::vector<std::string> names;
  for (const Body& b : model.bodies()) names.push_back(b.name);
  return names;
}

/// Joint values (`rate`: rates) by name; an unknown name is reported at its field. A revolute
/// joint's value may be given in degrees ({deg: 30}; a rate {deg_per_s: 5}); a prismatic one's is a length.
KDL::JntArray joints(const Field& f, const FloatingModel& model, bool rate = false) {
  if (!f.isMap()) f.failKind("a mapping NAME: VALUE");
  std::map<std::string, double> values;
  for (const Field::Entry& e : f.entries()) {
    const int j = model.jointIndex(e.name);
    if (j < 0)
      e.key.fail("the model has no movable joint " + echo(e.name) + " (its movable joints: " +
                 listNames(model.jointNames()) + ")");
    const Field& v = e.required();
    const KDL::Joint::JointType type = model.bodies()[model.jointBody()[j]].segment.getJoint().getType();
    const bool prismatic = type >= KDL::Joint::TransAxis && type <= KDL::Joint::TransZ;
    if (prismatic && v.isMap())
      v.fail("joint " + echo(e.name) + " is prismatic: its " + (rate ? "rate is a speed in m/s" : "value is a length in m") +
             ", not an angle");
    values[e.name] = v.angle(rate);
  }
  return jointsByName(model, values);
}

/// The joints braked at the impact (`locked: [joint, ...]`), as flags in model order: each a
/// movable joint of the model, named once, whose rate `qdot` is 0 (a braked joint does not move).
std::vector<bool> lockedJoints(const Field& f, const FloatingModel& model, const KDL::JntArray& qdot,
                               const std::string& qdot_path) {
  std::vector<bool> locked(model.nj(), false);
  for (const Field& item : f.items("joint names")) {
    const std::string name = item.text();
    const int j = model.jointIndex(name);
    if (j < 0)
      item.fail("the model has no movable joint " + echo(name) + " (its movable joints: " +
                listNames(model.jointNames()) + ")");
    if (locked[j]) item.fail("joint " + echo(name) + " is listed twice");
    if (qdot(j) != 0.0)
      item.fail("joint " + echo(name) + " is braked, so its rate " + qdot_path + "." + name + " must be 0, got " +
                number(qdot(j)));
    locked[j] = true;
  }
  return locked;
}

/// A joint's armature: a reflected inertia [kg m^2 or kg], or {rotor_inertia: I, gear_ratio: n}
/// for n^2 I.
double rotorInertia(const Field& f) {
  if (f.isScalar()) {
    const double a = f.number();
    if (a < 0.0) f.fail("must be >= 0, got " + number(a));
    return a;
  }
  f.onlyKeys({"rotor_inertia", "gear_ratio"});
  const double I = f.at("rotor_inertia").number(), n = f.at("gear_ratio").number();
  if (I < 0.0) f.at("rotor_inertia").fail("must be >= 0, got " + number(I));
  if (!(n > 0.0)) f.at("gear_ratio").fail("must be > 0, got " + number(n));
  return n * n * I;
}

/// A free-floating system (the robot, or a target with a URDF); `urdf_path` gets the resolved path.
/// `mount` (the robot's: its arms on a bus, robot.mount) gets the joined document; null: refused.
/// `document` gets the URDF document of a description in another format (SDF, MJCF, SpaceDyn's LP:
/// readRobotDocument), its notes and its file; untouched for a URDF file.
FloatingSystem system(const Field& f, const std::string& folder, std::string& urdf_path, MountedRobot& document,
                      MountedRobot* mount = nullptr) {
  f.onlyKeys({"urdf", "contact", "base", "q", "qdot", "mode", "locked", "armature", "place", "link", "grasp", "mount",
              "base_actuators"});
  if (f.has("base_actuators") && !mount) f.at("base_actuators").fail("only the robot (the servicer) has base actuators here");
  FloatingSystem s;
  if (f.has("mount")) {
    if (!mount) f.at("mount").fail("only the robot is mounted (its arms on a bus): give the target's urdf");
    *mount = sections::mounted(f, folder);
    try {
      s.model = std::make_shared<const FloatingModel>(loadUrdfString(mount->urdf, "the mounted robot"));
    } catch (const Error& e) {  // the joined model broken (a bus's inertia, an arm's rule)
      e.rethrowWithContext(f.at("mount").where());
    }
  } else {
    const Field urdf = f.at("urdf");
    urdf_path = sections::filePath(urdf, folder);
    try {
      checkInputFile(urdf_path, robotFileKind(urdf_path));
      RobotDocument d = readRobotDocument(urdf_path);
      if (d.format == RobotFormat::Urdf) {
        s.model = std::make_shared<const FloatingModel>(loadUrdfFile(urdf_path));
      } else {
        s.model = std::make_shared<const FloatingModel>(loadUrdfString(d.urdf, urdf_path));
        document = MountedRobot{std::move(d.urdf), std::move(d.notes), {urdf_path}};
      }
    } catch (const Error& e) {  // the file unreadable (InputError) or its model broken (ModelError)
      e.rethrowWithContext(urdf.where());
    }
  }
  if (f.has("armature")) {  // rotor inertias, reflected: a number, or n^2 I_rotor
    std::vector<double> armature = s.model->armature();
    for (const auto& [j, value] : sections::byJoint<double>(f.at("armature"), *s.model, rotorInertia)) armature[j] = value;
    s.model = std::make_shared<const FloatingModel>(s.model->withArmature(armature));
  }
  s.state = State(*s.model);
  s.velocity = FloatingVelocity(*s.model);
  if (f.has("base")) {
    const Field base = f.at("base");
    base.onlyKeys({"position", "rpy", "twist"});
    s.state.world_T_base = pose(base);
    if (base.has("twist")) s.velocity.base_twist = toTwist(Vector6d(base.at("twist").vector(6)));
  }
  if (f.has("q")) s.state.q = joints(f.at("q"), *s.model);
  if (f.has("qdot")) s.velocity.qdot = joints(f.at("qdot"), *s.model, true);
  if (f.has("locked"))
    s.locked = lockedJoints(f.at("locked"), *s.model, s.velocity.qdot, (f.path().empty() ? "" : f.path() + ".") + "qdot");
  if (f.has("contact")) {  // required for an impact (loadScenario); a plain motion has none: the base
    const Field contact = f.at("contact");
    contact.onlyKeys({"link", "offset"});
    const std::string link = contact.at("link").text();
    const Eigen::VectorXd o = contact.has("offset") ? contact.at("offset").vector(3) : Eigen::VectorXd::Zero(3);
    if (s.model->bodyIndex(link) < 0)
      contact.at("link").fail("the model has no link " + echo(link) + " (its links: " + listNames(linkNames(*s.model)) + ")");
    s.contact = s.model->contact(link, KDL::Vector(o(0), o(1), o(2)));
  } else {
    s.contact.body = 0;  // the base's origin
  }
  if (f.has("mode")) {
    const std::string mode = f.at("mode").text();
    if (mode == "free") s.response = Response::FreeFloating;
    else if (mode == "grounded") s.response = Response::Grounded;
    else if (mode == "locked") s.response = Response::JointsLocked;
    else f.at("mode").fail(echo(mode) + " is not one of free, grounded, locked");
  }
  return s;
}

/// A rigid target in the file's terms; its mass and inertia those of a rigid body.
RigidTarget rigidTarget(const Field& f) {
  if (f.has("place"))
    f.at("place").fail("a rigid target has no contact point of its own (the point hit is the robot's contact point): "
                       "place it with pose");
  f.onlyKeys({"mass", "inertia", "pose", "com", "twist"});
  RigidTarget b;
  b.mass = f.at("mass").number();
  if (!(b.mass > 0.0)) f.at("mass").fail("must be > 0 kg, got " + number(b.mass));
  const Field inertia = f.at("inertia");
  const Matrix3d I = inertia.matrix3();
  const rules::InertiaVerdict verdict = rules::judgeInertia(I);
  if (!verdict.symmetric) {
    Eigen::Index i = 0, j = 0;
    (I - I.transpose()).cwiseAbs().maxCoeff(&i, &j);
    inertia.fail("must be symmetric, but row " + std::to_string(i + 1) + " column " + std::to_string(j + 1) + " is " +
                 number(I(i, j)) + " and row " + std::to_string(j + 1) + " column " + std::to_string(i + 1) + " is " +
                 number(I(j, i)));
  }
  const Vector3d& l = verdict.moments;  // ascending
  const std::string moments = "(principal moments " + number(l(0)) + ", " + number(l(1)) + ", " + number(l(2)) + " kg m^2)";
  if (verdict.kind == rules::InertiaVerdict::NotPositiveDefinite) inertia.fail("must be positive definite " + moments);
  if (verdict.kind == rules::InertiaVerdict::TriangleInequality)
    inertia.fail("is no rigid body's inertia: its principal moments break the triangle inequality I1 + I2 >= I3 " +
                 moments);
  b.inertia = I;
  if (f.has("pose")) {
    f.at("pose").onlyKeys({"position", "rpy"});
    b.pose = pose(f.at("pose"));
  }
  if (f.has("com")) b.com = f.at("com").vector(3);
  if (f.has("twist")) b.twist = f.at("twist").vector(6);
  return b;
}

/// A target URDF read as one rigid body: a file without movable joints, or the links from
/// `link` down (its joints held at `q`); placed and moved by `base` as a rigid body given by numbers.
RigidTarget rigidUrdfTarget(const Field& f, const FloatingSystem& t) {
  for (const char* key : {"contact", "place", "qdot", "mode", "locked", "armature"})
    if (f.has(key))
      f.at(key).fail(std::string("the target is read as one rigid body (") +
                     (f.has("link") ? "the links from target.link down" : "its file has no movable joint") +
                     "): the point hit is the robot's contact point, and it moves as a whole (give its pose and twist in "
                     "target.base)");
  int body = 0;
  if (f.has("link")) {
    const std::string link = f.at("link").text();
    body = t.model->bodyIndex(link);
    if (body < 0)
      f.at("link").fail("the model has no link " + echo(link) + " (its links: " + listNames(linkNames(*t.model)) + ")");
  }
  try {
    return rigidSubtree(*t.model, t.state, body, t.velocity.base_twist);
  } catch (const Error& e) {
    e.rethrowWithContext(f.where());
  }
}

/// `place: touch`: the target's base moved (translated) so that its contact point is the robot's.
void place(const Field& f, const FloatingSystem& robot, FloatingSystem& target) {
  if (f.text() != "touch") f.fail(echo(f.text()) + " is not touch (the target's base moved so that its contact point is the robot's)");
  Kinematics a(*robot.model), b(*target.model);
  if (forwardKinematics(*robot.model, robot.state, a) || forwardKinematics(*target.model, target.state, b))
    f.fail("the contact points cannot be computed at the given states");
  target.state.world_T_base.p += toKDL(a.point(robot.contact) - b.point(target.contact));
}

/// `robot.place: grasp`: the robot's joints solved (inverse kinematics from robot.q, preferring
/// it) so that its contact frame holds the target's grasp frame `robot.grasp.target_frame`
/// (position, rpy in the frame `world_T_target`); the base stays where robot.base puts it.
IkResult placeAtGrasp(const Field& robot_f, FloatingSystem& robot, const KDL::Frame& world_T_target) {
  const Field f = robot_f.at("place");
  if (f.text() != "grasp")
    f.fail(echo(f.text()) + " is not grasp (the robot's joints solved so that its contact frame holds "
           "robot.grasp.target_frame; a free-floating target is moved by target.place: touch)");
  robot_f.at("contact");  // reports it missing: the frame that holds the grasp
  const Field grasp = robot_f.at("grasp");
  grasp.onlyKeys({"target_frame"});
  const Field frame = grasp.at("target_frame");
  frame.onlyKeys({"position", "rpy"});
  try {
    const IkResult r = solveInverseKinematics(*robot.model, robot.state, robot.contact, world_T_target * pose(frame));
    robot.state.q = r.q;
    return r;
  } catch (const Error& e) {
    e.rethrowWithContext(f.where() + "the grasp frame: ");
  }
}

// --- The approach of a free-floating robot target (issue 28) -----------------------------------

/// `approach` for a free-floating robot target: the grasp frame in the frame of the target's
/// contact link (target.contact.link), its origin the contact point (target.contact.offset: the
/// capture joins the two contact points, which must touch within the capture's touch tolerance,
/// so the position tolerance is that tolerance unless a smaller one is given).
ApproachSpec robotTargetApproach(const Field& approach, const Field& target, const CaptureProblem& capture) {
  const FloatingSystem& t = std::get<FloatingSystem>(capture.target);
  if (target.has("place"))
    target.at("place").fail("puts the target's contact at the robot's hand before anything moves, so the approach "
                            "would have nothing to reach: remove target.place, or the approach section");
  const KDL::Vector offset = t.contact.offset;
  ApproachSpec a = sections::approach(approach, *capture.robot.model, &offset);
  const Field grasp = approach.at("grasp");
  if (grasp.has("position") && !((a.grasp.p - offset).Norm() <= 1e-9))
    grasp.at("position").fail("is where the hand grasps the target, in the frame of target.contact.link '" +
                              t.model->bodies()[t.contact.body].name +
                              "': it must be the target's contact point target.contact.offset [" + number(offset.x()) + ", " +
                              number(offset.y()) + ", " + number(offset.z()) + "]" +
                              " (the capture joins the two contact points): leave it out or give that");
  const double touch = capture.touch_tolerance;
  const bool given = approach.has("tolerance") && approach.at("tolerance").has("position");
  // Half the touch by default: the approach ends where the distance first falls to its tolerance
  // (located to round-off), and the capture checks the touch by its own route; at the touch itself
  // that check could fail by round-off.
  if (!given) a.position_tolerance = 0.5 * touch;
  else if (!(a.position_tolerance < touch))
    approach.at("tolerance").at("position").fail(
        "must be less than " + number(touch) + " m for a robot target: the capture joins the hand to the target's "
        "contact point, which must touch within " + number(touch) + " m, got " + number(a.position_tolerance));
  return a;
}

/// The grasp frame (in the contact link's frame) in the target's base frame at its scenario
/// state: what the pictures draw (Scenario::grasp_frame).
KDL::Frame graspInBaseFrame(const FloatingSystem& t, const KDL::Frame& grasp) {
  Kinematics kin(*t.model);
  if (forwardKinematics(*t.model, t.state, kin) != E_NOERROR) return grasp;  // the state is checked elsewhere
  return t.state.world_T_base.Inverse() * kin.pose(t.contact.body) * grasp;
}

// -------------------------------------------------------------------------------------------------

}  // namespace

Scenario loadScenario(const std::string& path) {
  Scenario s;
  s.file = path;
  const YAML::Node root = fields::parseFile(path, "scenario file (YAML or JSON)");
  const Field top(root, "", &s.file);
  if (root.IsNull())
    throw InputError(path + ": holds no data; a scenario is a mapping with robot, target and law (or robot and simulation)");
  if (!root.IsMap())
    top.fail("a scenario is a mapping with robot, target and law (or robot and simulation), not " + fields::kindOf(root));
  top.onlyKeys({"robot", "target", "law", "approach", "simulation"});
  const std::string folder = std::filesystem::path(path).parent_path().string();
  MountedRobot mount;
  MountedRobot converted;  // a robot file in another format, as a URDF document
  s.capture.robot = system(top.at("robot"), folder, s.robot_urdf, converted, &mount);
  if (!converted.urdf.empty()) mount = std::move(converted);
  s.robot_document = std::move(mount.urdf);
  s.robot_files = s.robot_urdf.empty() ? std::move(mount.files) : std::vector<std::string>{s.robot_urdf};
  s.robot_notes = std::move(mount.notes);
  const Field robot = top.at("robot");
  if (robot.has("grasp") && !robot.has("place"))
    robot.at("grasp").fail("is the grasp frame that robot.place: grasp solves the arm for: add robot.place: grasp");
  if (robot.has("place") && top.has("approach"))  // before the solve: it need not be reachable to be refused
    robot.at("place").fail("puts the hand at the grasp before anything moves, so the approach would have nothing to "
                           "reach: remove robot.place and robot.grasp (the approach starts from robot.q and reaches "
                           "approach.grasp), or the approach section");
  if (robot.has("place") && !(top.has("target") || top.has("law")))
    robot.at("place").fail("a plain motion has no target to grasp: give target and law");
  // A plain motion has neither target nor law; an impact needs both.
  s.impact = top.has("target") || top.has("law");
  if (s.impact) {
    top.at("robot").at("contact");  // reports it missing: an impact needs the robot's contact point
    const Field target = top.at("target");
    if (target.has("urdf")) {
      MountedRobot converted;
      FloatingSystem t = system(target, folder, s.target_urdf, converted);
      s.target_document = std::move(converted.urdf);
      if (target.has("link") || t.model->nj() == 0) {
        s.capture.target = rigidUrdfTarget(target, t);  // one rigid body: the robot's contact point is hit
        s.rigid_target_body = target.has("link") ? t.model->bodyIndex(target.at("link").text()) : 0;
        s.rigid_target_system = std::move(t);
      } else {
        if (!target.has("contact")) target.at("contact");  // reports it missing
        if (target.has("place") && robot.has("place"))
          target.at("place").fail("the robot is placed at the grasp (robot.place: grasp): the target stays where "
                                  "target.base puts it; remove one of them");
        if (robot.has("place")) s.grasp_solution = placeAtGrasp(robot, s.capture.robot, t.state.world_T_base);
        if (target.has("place")) place(target.at("place"), s.capture.robot, t);
        s.capture.target = std::move(t);
      }
    } else {
      s.capture.target = rigidTarget(target);
    }
    if (robot.has("place") && !s.grasp_solution) {  // a rigid target: its frame (pose, or its link's)
      s.grasp_solution = placeAtGrasp(robot, s.capture.robot, std::get<RigidTarget>(s.capture.target).pose);
    }
    if (s.grasp_solution) s.grasp_frame = pose(robot.at("grasp").at("target_frame"));
    if (target.has("grasp")) target.at("grasp").fail("the grasp frame is the robot's field: robot.grasp.target_frame");
    s.capture.law = laws::law(top.at("law"), s.capture.has_normal);
    if (top.at("law").at("type").text() == "compliant") s.compliant = laws::compliantLaw(top.at("law"));
    laws::graspLimit(top.at("law"), s.max_grasp_force, s.max_grasp_moment);
  } else if (!top.has("simulation")) {
    top.fail("a scenario without target and law is a plain motion: it needs a simulation section");
  }
  if (top.has("approach")) {
    const Field approach = top.at("approach");
    if (!s.impact) approach.fail("an approach reaches a target: give target and law too");
    if (const auto* floating = std::get_if<FloatingSystem>(&s.capture.target)) {
      s.approach = robotTargetApproach(approach, top.at("target"), s.capture);
      s.grasp_frame = graspInBaseFrame(*floating, s.approach->grasp);
    } else {
      s.approach = sections::approach(approach, *s.capture.robot.model);
      s.grasp_frame = s.approach->grasp;
    }
  }
  if (top.has("simulation")) {
    const auto* floating = std::get_if<FloatingSystem>(&s.capture.target);
    s.simulation = sections::simulation(top.at("simulation"), *s.capture.robot.model,
                                        s.impact && floating ? floating->model.get() : nullptr);
    if (s.impact && s.simulation.grounded.value_or(false) && s.capture.robot.response == Response::FreeFloating)
      sections::groundForTheCapture(top.at("simulation").at("base"), s.capture.robot);
  }
  if (robot.has("base_actuators")) {
    s.base_actuators = sections::baseActuators(robot.at("base_actuators"));
    if (s.simulation.grounded.value_or(s.capture.robot.response == Response::Grounded))
      robot.at("base_actuators").fail("the base is grounded (held still): its actuators have nothing to move; "
                                      "remove them, or let the base float (simulation.base: free)");
    if (top.has("simulation") && top.at("simulation").has("base_control"))
      sections::checkBaseControlHardware(s.base_actuators, s.simulation.base_control,
                                         top.at("simulation").at("base_control"));
  }
  return s;
}

}  // namespace kdl_space
