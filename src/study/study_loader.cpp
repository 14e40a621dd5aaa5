// loadStudy: the study file's fields, each checked where it is read, in the words of the file.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <utility>

#include "spatial/message_text.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/study/study.hpp"
#include "parsers/scenario/scenario_fields.hpp"
#include "study/study_sampling.hpp"
#include "study/target_shape.hpp"
#include "kdl_space/algorithm/self_motion.hpp"

namespace kdl_space {
namespace {

using detail::number;
using fields::echo;
using fields::Field;

/// FNV-1a over a file's bytes, folded into h (a missing file folds in nothing). Each "\r\n" is
/// folded as "\n": a copy whose line endings were converted (git's autocrlf, an editor) is the
/// same study.
std::uint64_t fold(std::uint64_t h, const std::string& path) {
  if (path.empty()) return h;
  std::ifstream in(path, std::ios::binary);
  const auto byte = [&h](unsigned char c) {
    h ^= c;
    h *= 0x100000001b3ULL;
  };
  bool carriage_return = false;  // a '\r' held until the next byte says whether it ends a line
  for (std::istreambuf_iterator<char> it(in), end; it != end; ++it) {
    const unsigned char c = static_cast<unsigned char>(*it);
    if (carriage_return && c != '\n') byte('\r');
    carriage_return = c == '\r';
    if (!carriage_return) byte(c);
  }
  if (carriage_return) byte('\r');
  return h;
}

/// A whole number 0 <= n <= `most`, written in digits (no sign, point or exponent).
std::uint64_t whole(const Field& f, std::uint64_t most, const std::string& what) {
  const std::string text = f.text();
  bool digits = !text.empty() && text.size() <= 20;
  for (const char c : text) digits = digits && std::isdigit(static_cast<unsigned char>(c));
  if (!digits) f.fail("must be " + what + ", got " + echo(text));
  try {
    const unsigned long long n = std::stoull(text);
    if (n > most) f.fail("must be at most " + std::to_string(most) + ", got " + text);
    return n;
  } catch (const std::out_of_range&) {
    f.fail("must be at most " + std::to_string(most) + ", got " + echo(text));
  }
}

Distribution distribution(const Field& f) {
  if (f.isScalar() || f.isSequence() || f.keys().size() != 1)
    f.fail("give one distribution: {uniform: [low, high]}, {normal: {mean: m, std: s}} (with min and max: truncated), "
           "{log_normal: {median: m, factor: f}} or {grid: [from, to, count]}");
  f.onlyKeys({"uniform", "normal", "log_normal", "grid"});
  Distribution d;
  if (f.has("uniform")) {
    const Field u = f.at("uniform");
    const Eigen::VectorXd v = u.vector(2);
    if (!(v(0) < v(1))) u.fail("is an empty range: low must be < high, got [" + number(v(0)) + ", " + number(v(1)) + "]");
    d.kind = Distribution::Kind::Uniform, d.a = v(0), d.b = v(1);
  } else if (f.has("normal")) {
    const Field n = f.at("normal");
    n.onlyKeys({"mean", "std", "min", "max"});
    d.kind = Distribution::Kind::Normal, d.a = n.at("mean").number(), d.b = n.at("std").number();
    if (!(d.b > 0.0)) n.at("std").fail("must be > 0, got " + number(d.b));
    if (n.has("min")) d.min = n.at("min").number();
    if (n.has("max")) d.max = n.at("max").number();
    if (!(d.min < d.max)) n.fail("is truncated to an empty range: min must be < max, got [" + number(d.min) + ", " + number(d.max) + "]");
    // The draws between the bounds must have a probability a double resolves (Phi^-1 of it finite).
    const double alpha = (d.min - d.a) / d.b, beta = (d.max - d.a) / d.b;
    const double p = alpha > 0.0 ? sampling::normalCdf(-alpha) - sampling::normalCdf(-beta)
                                  : sampling::normalCdf(beta) - sampling::normalCdf(alpha);
    if (!(p > 1e-250))
      n.fail("[min, max] = [" + number(d.min) + ", " + number(d.max) + "] has a probability below 1e-250 under this normal "
             "(far in its tail, more than ~33 standard deviations from the mean): use {uniform: [min, max]}");
  } else if (f.has("log_normal")) {
    const Field n = f.at("log_normal");
    n.onlyKeys({"median", "factor"});
    d.kind = Distribution::Kind::LogNormal, d.a = n.at("median").number(), d.b = n.at("factor").number();
    if (!(d.a > 0.0)) n.at("median").fail("must be > 0, got " + number(d.a));
    if (!(d.b > 1.0)) n.at("factor").fail("must be > 1 (the spread: 68 % of the draws lie within median / factor and "
                                          "median * factor), got " + number(d.b));
  } else {
    const Field g = f.at("grid");
    const std::vector<Field> items = g.items("from, to, count");
    if (items.size() != 3) g.fail("expected [from, to, count], got a list of " + std::to_string(items.size()));
    d.kind = Distribution::Kind::Grid, d.a = items[0].number(), d.b = items[1].number();
    d.count = static_cast<long>(whole(items[2], 1000000, "a whole number of points >= 1"));
    if (d.count < 1) items[2].fail("must be >= 1 point, got 0");
    if (d.count > 1 && !(d.a != d.b)) g.fail("is an empty range: from and to are both " + number(d.a));
  }
  return d;
}

/// What to draw instead of `d` for an input that takes values > 0 (`positive`: a mass) or >= 0.
std::string positiveAdvice(const Distribution& d, bool positive) {
  if (d.kind == Distribution::Kind::LogNormal) return "give a smaller factor";
  const std::string normal = "{normal: {mean: " + number(d.a) + ", std: " + number(d.b) + ", min: " +
                             (positive ? "M}} with M > 0" : "0}}") + " (truncated)";
  const std::string log_normal = "{log_normal: {median: " + number(d.a > 0.0 ? d.a : 1.0) + ", factor: F}}";
  return "use " + normal + " or " + log_normal;
}

/// Refuses a distribution that can draw outside its input's domain, before any sample: values
/// that are not finite, and for target.mass and a principal moment's factor (> 0), target.tumble
/// and timing (>= 0) values below.
void checkDomain(const Field& f, const StudyInput& in) {
  using F = StudyInput::Field;
  const Distribution& d = in.distribution;
  const auto [low, high] = sampling::drawnRange(d);
  const std::string how = d.kind == Distribution::Kind::Normal ? "this normal" : d.kind == Distribution::Kind::LogNormal
                                                                                     ? "this log-normal" : "this range";
  if (!std::isfinite(low) || !std::isfinite(high))
    f.fail(how + " draws values that are not finite numbers (from " + number(low) + " to " + number(high) +
           "): give bounds whose difference is finite, e.g. within +-1e307");
  const bool mass = in.field == F::TargetMass || in.field == F::TargetPrincipalInertia;
  if (!mass && in.field != F::TargetTumble && in.field != F::Timing) return;
  if (mass ? low > 0.0 : low >= 0.0) return;
  const std::string what = in.field == F::TargetPrincipalInertia ? "a factor" : mass ? "a mass" : in.field == F::Timing ? "a delay" : "a rate";
  if (d.kind == Distribution::Kind::Uniform || d.kind == Distribution::Kind::Grid)
    f.fail(mass && low == 0.0 ? what + " must be > 0" + (in.field == F::TargetMass ? " kg" : "") + ", but the range reaches 0"
                              : "takes values >= 0 (" + what + "), but the range reaches " + number(low));
  f.fail("takes values " + std::string(mass ? "> 0" : ">= 0") + " (" + what + "), but " + how + " draws down to " +
         number(low) + ": " + positiveAdvice(d, mass));
}

/// A distribution given in degrees ({deg: DIST} for an angle, {deg_per_s: DIST} for a rate) in radians.
void toRadians(Distribution& d) {
  const double k = M_PI / 180.0;
  if (d.kind == Distribution::Kind::LogNormal) {
    d.a *= k;  // the median; the factor is a ratio
    return;
  }
  d.a *= k, d.b *= k;  // the ends of a range or a grid; a normal's mean and std
  d.min *= k, d.max *= k;
}

/// Whether `in` takes an angle ("deg") or an angular rate ("deg_per_s"): a revolute joint's
/// position or rate, the target's angular velocity components and its tumble rate, the self-motion.
const char* angularUnit(const StudyInput& in, const FloatingModel& robot) {
  using F = StudyInput::Field;
  const bool revolute = (in.field == F::JointPosition || in.field == F::JointRate) &&
                        robot.bodies()[robot.jointBody()[in.index]].joint_twist.tail<3>().norm() > 0.0;
  if ((in.field == F::JointPosition && revolute) || in.field == F::SelfMotion || in.field == F::TargetInertiaTilt ||
      in.field == F::TargetTumbleCone)
    return "deg";
  if ((in.field == F::JointRate && revolute) || in.field == F::TargetTumble || (in.field == F::TargetTwist && in.index >= 3))
    return "deg_per_s";
  return "";
}

/// The input a field name sets, checked against the scenario.
StudyInput input(const Field& given, const std::string& name, const Scenario& sc) {
  StudyInput in;
  in.name = name;
  // {deg: DIST} / {deg_per_s: DIST}: the distribution in degrees, converted once here
  std::string unit;
  const bool in_degrees = given.isMap() && given.keys().size() == 1 && (given.has("deg") || given.has("deg_per_s"));
  if (in_degrees) unit = given.has("deg") ? "deg" : "deg_per_s";
  const Field f = in_degrees ? given.at(unit) : given;
  in.distribution = distribution(f);
  const FloatingModel& robot = *sc.capture.robot.model;
  const bool rigid = std::holds_alternative<RigidTarget>(sc.capture.target);
  const auto component = [&](const std::string& prefix, std::initializer_list<const char*> names) {
    int k = 0;
    for (const char* c : names) {
      if (name == prefix + c) return k;
      ++k;
    }
    std::string list;
    for (const char* c : names) list += (list.empty() ? "" : ", ") + prefix + c;
    f.fail("is no input of a study (" + list + ")");
  };
  const auto joint = [&](const std::string& prefix) {
    const std::string joint_name = name.substr(prefix.size());
    const int j = robot.jointIndex(joint_name);
    if (j < 0)
      f.fail("the robot has no movable joint " + echo(joint_name) + " (its movable joints: " +
             detail::listNames(robot.jointNames()) + ")");
    return j;
  };
  const bool target_field = name.rfind("target.", 0) == 0 || name == "timing";
  if (target_field && !sc.impact) f.fail("the scenario has no target");
  if (target_field && !rigid)
    f.fail("the target is a free-floating system (target.urdf): a study varies a rigid target's inputs only");
  using F = StudyInput::Field;
  if (name.rfind("target.twist.", 0) == 0) {
    in.field = F::TargetTwist, in.index = component("target.twist.", {"vx", "vy", "vz", "wx", "wy", "wz"});
  } else if (name == "target.tumble") {
    in.field = F::TargetTumble;
  } else if (name == "target.mass") {
    in.field = F::TargetMass;
  } else if (name.rfind("target.inertia.", 0) == 0 && name != "target.inertia.tilt") {
    in.field = F::TargetPrincipalInertia, in.index = component("target.inertia.", {"I1", "I2", "I3"});
  } else if (name == "target.inertia.tilt") {
    in.field = F::TargetInertiaTilt;
  } else if (name == "target.tumble_cone") {
    in.field = F::TargetTumbleCone;
  } else if (name.rfind("target.grasp.", 0) == 0) {
    in.field = F::TargetGrasp, in.index = component("target.grasp.", {"x", "y", "z"});
  } else if (name == "timing") {
    in.field = F::Timing;
  } else if (name.rfind("robot.q.", 0) == 0) {
    in.field = F::JointPosition, in.index = joint("robot.q.");
  } else if (name.rfind("robot.qdot.", 0) == 0) {
    in.field = F::JointRate, in.index = joint("robot.qdot.");
  } else if (name == "robot.self_motion") {
    in.field = F::SelfMotion;
    try {
      SelfMotion check(sc.capture.robot.model, sc.capture.robot.contact, sc.capture.robot.state);
    } catch (const InputError& e) {
      f.fail(std::string(e.what()).substr(std::string("robot.self_motion: ").size()));
    }
  } else if (name.rfind("robot.contact.offset.", 0) == 0) {
    in.field = F::ContactOffset, in.index = component("robot.contact.offset.", {"x", "y", "z"});
  } else {
    f.fail("is no input of a study (target.twist.{vx,vy,vz,wx,wy,wz}, target.tumble, target.tumble_cone, target.mass, "
           "target.inertia.{I1,I2,I3}, target.inertia.tilt, "
           "target.grasp.{x,y,z}, timing, robot.q.JOINT, robot.qdot.JOINT, robot.self_motion, "
           "robot.contact.offset.{x,y,z})");
  }
  if (in_degrees) {
    const std::string expected = angularUnit(in, robot);
    if (expected != unit)
      given.fail(expected.empty() ? "is not an angle or an angular rate: give its distribution in SI units, without " + unit
                                  : "is " + std::string(expected == "deg" ? "an angle: {deg: ...}" : "an angular rate: {deg_per_s: ...}") +
                                        ", not {" + unit + ": ...}");
    toRadians(in.distribution);
  }
  checkDomain(f, in);
  return in;
}

/// A limit per joint: a number for all, or `urdf` (the URDF's limit of each joint, which all must have).
std::vector<double> jointLimit(const Field& f, const FloatingModel& robot, bool torque) {
  std::vector<double> limit(robot.nj());
  if (f.isScalar() && f.text() == "urdf") {
    for (unsigned int j = 0; j < robot.nj(); ++j) {
      const JointProperties& p = robot.jointProperties()[j];
      limit[j] = torque ? p.effort : p.velocity;
      if (!(limit[j] > 0.0) || !std::isfinite(limit[j]))
        f.fail("joint " + echo(robot.jointNames()[j]) + " has no " + (torque ? "effort" : "velocity") +
               " limit in the URDF: give a number");
    }
    return limit;
  }
  const double v = f.number();
  if (!(v > 0.0)) f.fail("must be > 0 (or urdf), got " + number(v));
  std::fill(limit.begin(), limit.end(), v);
  return limit;
}

void checkColumn(const Field& f, const std::vector<std::string>& columns, const std::string& what) {
  const std::string name = f.text();
  if (std::find(columns.begin(), columns.end(), name) == columns.end())
    f.fail("is no " + what + " of this study (its columns: " + detail::listNames(columns) + ")");
}

bool isGrid(const StudyInput& in) { return in.distribution.kind == Distribution::Kind::Grid; }

/// An aggregate of an outcome at a grid point: mean, q95, max; probability for an exceeds.* column.
std::string statistic(const Field& f, const std::string& outcome) {
  const std::string s = f.text();
  const bool limit = outcome.rfind("exceeds.", 0) == 0;
  if (limit ? s != "probability" : (s != "mean" && s != "q95" && s != "max"))
    f.fail(echo(s) + " is no statistic of " + outcome + ": " +
           (limit ? "an exceeds.* column has `probability`" : "one of mean, q95, max"));
  return s;
}

/// `motion`: the motion after each sample's capture (duration, output_step), checked against the
/// scenario's step budget and refused when no motion follows its capture.
void readMotion(const Field& m, Study& st) {
  const Scenario& sc = st.scenario;
  m.onlyKeys({"duration", "output_step"});
  st.motion_duration = m.at("duration").number();
  if (!(st.motion_duration > 0.0)) m.at("duration").fail("must be > 0 s, got " + number(st.motion_duration));
  st.motion_output_step = m.has("output_step") ? m.at("output_step").number() : st.motion_duration / 100.0;
  if (!(st.motion_output_step > 0.0)) m.at("output_step").fail("must be > 0 s, got " + number(st.motion_output_step));
  // As `simulate`: a motion that cannot fit the step budget would spend it in every sample.
  const StepEstimate e = fewestSteps(sc.simulation, st.motion_duration, st.motion_output_step);
  const long budget = sc.simulation.options.max_steps;
  if (e.steps > static_cast<double>(budget)) {
    const std::string by = std::string(e.limited_by) == "output_step" ? "motion.output_step" : "the scenario's simulation." + std::string(e.limited_by);
    m.at("duration").fail(number(st.motion_duration) + " s in steps of at most " + number(e.longest) + " s (" + by +
                          ") needs " + number(e.steps) + " steps, more than the scenario's simulation.max_steps = " +
                          std::to_string(budget) + ": give a duration of at most " +
                          number(e.longest * static_cast<double>(budget)) + " s (or raise simulation.max_steps in " +
                          detail::shownPath(sc.file) + ")");
  }
  try {
    CaptureResult probe;
    probe.contact_body_pose = KDL::Frame::Identity();
    if (sc.capture.law.kind == ImpactKind::TranslationalCapture || !std::holds_alternative<RigidTarget>(sc.capture.target))
      attachTarget(sc.capture, probe);  // refuses what no motion follows
  } catch (const Error& e) {
    e.rethrowWithContext(m.where() + "no motion follows this scenario's capture: ");
  }
}

/// `heat_map`: x and y, the study's two grid inputs, and an outcome's statistic over each point.
void readHeatMap(const Field& h, const std::vector<std::string>& columns, Study& st) {
  h.onlyKeys({"x", "y", "outcome", "statistic"});
  for (const char* k : {"x", "y", "outcome"}) checkColumn(h.at(k), columns, "column");
  st.heat_map = StudyHeatMap{h.at("x").text(), h.at("y").text(), h.at("outcome").text(), "mean"};
  if (h.at("outcome").text().rfind("exceeds.", 0) == 0) st.heat_map->statistic = "probability";
  if (h.has("statistic")) st.heat_map->statistic = statistic(h.at("statistic"), st.heat_map->outcome);
  // One value a cell: the cells are the grid's points, so x and y are its grid inputs, all of them.
  std::vector<std::string> grid;
  for (const StudyInput& in : st.inputs)
    if (isGrid(in)) grid.push_back(in.name);
  for (const char* k : {"x", "y"})
    if (std::find(grid.begin(), grid.end(), h.at(k).text()) == grid.end())
      h.at(k).fail("is no grid input of this study: a heat map's cells are the grid's points (one value a cell); "
                   "give " + h.at(k).text() + " a grid: [from, to, count]" +
                   (grid.empty() ? std::string() : " (its grid inputs: " + detail::listNames(grid) + ")"));
  if (h.at("x").text() == h.at("y").text()) h.at("y").fail("is x too: give two grid inputs");
  if (grid.size() != 2)
    h.fail("the study has " + std::to_string(grid.size()) + " grid inputs (" + detail::listNames(grid) +
           "): a heat map's cells are its grid points, so it needs exactly two (x and y)");
}

}  // namespace

Study loadStudy(const std::string& path) {
  Study st;
  st.file = path;
  const YAML::Node root = fields::parseFile(path, "study file (YAML or JSON)");
  const Field top(root, "", &st.file);
  if (!root.IsMap()) top.fail("a study is a mapping with scenario, samples, seed and inputs, not " + fields::kindOf(root));
  top.onlyKeys({"scenario", "samples", "seed", "sampling", "inputs", "motion", "limits", "objective", "heat_map"});
  std::string scenario_path = top.at("scenario").text();
  if (std::filesystem::path(scenario_path).is_relative())
    scenario_path = (std::filesystem::path(path).parent_path() / scenario_path).lexically_normal().string();
  try {
    st.scenario = loadScenario(scenario_path);
  } catch (const Error& e) {  // its own InputError, or a URDF's ModelError: the kind kept
    e.rethrowWithContext(top.at("scenario").where());
  }
  const Scenario& sc = st.scenario;
  if (!sc.impact) top.at("scenario").fail("is a plain motion: a study samples captures (give the scenario a target and a law)");
  if (sc.compliant)  // not its impulsive limit in disguise
    top.at("scenario").fail("has law type compliant: a study samples the paper's impulsive captures (give law.type "
                            "capture, the compliant contact's limit; kdl_space capture and simulate integrate the "
                            "compliant contact)");
  if (sc.approach)
    top.at("scenario").fail("has an approach: a study samples the captures themselves (remove the approach; vary "
                            "`timing` for when along the tumble the hand closes)");
  st.seed = whole(top.at("seed"), ~std::uint64_t{0}, "a whole number (0 to 2^64 - 1)");
  if (top.has("sampling")) {
    const std::string s = top.at("sampling").text();
    if (s == "latin_hypercube") st.latin_hypercube = true;
    else if (s != "random") top.at("sampling").fail(echo(s) + " is not one of random, latin_hypercube");
  }
  const Field inputs = top.at("inputs");
  for (const Field::Entry& e : inputs.entries()) st.inputs.push_back(input(e.required(), e.name, sc));
  if (st.inputs.empty()) inputs.fail("a study varies at least one input");
  checkTargetShape(inputs, st);
  const std::uint64_t grid = sampling::gridSize(st);
  if (grid > Study::max_samples) inputs.fail("its grid has " + std::to_string(grid) + " points, more than a study's 1e9 samples");
  if (top.has("samples")) {
    st.samples = whole(top.at("samples"), ~std::uint64_t{0}, "a whole number of samples >= 1");
    if (st.samples == 0) top.at("samples").fail("must be >= 1, got 0");
    if (st.samples > Study::max_samples)
      top.at("samples").fail("must be at most 1e9 (split a larger study into several), got " + top.at("samples").text());
  } else if (std::any_of(st.inputs.begin(), st.inputs.end(),
                         [](const StudyInput& in) { return in.distribution.kind == Distribution::Kind::Grid; })) {
    st.samples = grid;  // one sample per grid point
  } else {
    top.at("samples");  // reports it missing
  }
  if (top.has("motion")) readMotion(top.at("motion"), st);
  const FloatingModel& robot = *sc.capture.robot.model;
  if (top.has("limits")) {
    const Field l = top.at("limits");
    l.onlyKeys({"joint_rate", "joint_torque", "base_rate"});
    if (l.has("joint_rate")) st.limits.joint_rate = jointLimit(l.at("joint_rate"), robot, false);
    if (l.has("joint_torque")) {
      if (st.motion_duration <= 0.0) l.at("joint_torque").fail("the torques are those of the motion: give `motion` too");
      st.limits.joint_torque = jointLimit(l.at("joint_torque"), robot, true);
    }
    if (l.has("base_rate")) {
      st.limits.base_rate = l.at("base_rate").number();
      if (!(*st.limits.base_rate > 0.0)) l.at("base_rate").fail("must be > 0 rad/s, got " + number(*st.limits.base_rate));
    }
  }
  const std::vector<std::string> columns = studyColumns(st);
  if (top.has("objective")) {
    const Field o = top.at("objective");
    if (o.isScalar()) {  // a column: the samples ranked by it
      checkColumn(o, columns, "outcome");
      st.objective = o.text();
    } else {  // {outcome, statistic}: the grid points ranked by that aggregate
      o.onlyKeys({"outcome", "statistic"});
      checkColumn(o.at("outcome"), columns, "outcome");
      st.objective = o.at("outcome").text();
      st.objective_statistic = statistic(o.at("statistic"), st.objective);
      if (!std::any_of(st.inputs.begin(), st.inputs.end(), isGrid))
        o.fail("ranks grid points, and the study has no grid input: give one (grid: [from, to, count]), or "
               "rank the samples with `objective: " + st.objective + "`");
    }
  }
  if (top.has("heat_map")) readHeatMap(top.at("heat_map"), columns, st);
  std::uint64_t h = 0xcbf29ce484222325ULL;
  std::vector<std::string> files{path, scenario_path};  // a mounted robot: its bus's and arms' files
  files.insert(files.end(), sc.robot_files.begin(), sc.robot_files.end());
  files.push_back(sc.target_urdf);
  for (const std::string& file : files) h = fold(h, file);
  st.fingerprint = h;
  return st;
}

}  // namespace kdl_space
