#include "scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <sstream>

#include "cli_common.hpp"
#include "kdl_space/urdf_loader.hpp"

namespace kdl_space::cli {
namespace {

/// A number as a message shows it (shortest form that reads back).
std::string show(double x) {
  std::ostringstream s;
  s << std::setprecision(6) << x;
  return s.str();
}

/// A text from the file, quoted for a message: at most 40 characters, anything but printable
/// ASCII shown as '?' (a binary file must not flood the terminal).
std::string echo(const std::string& text) {
  std::string shown;
  for (std::size_t i = 0; i < text.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    shown += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  return "'" + shown + (text.size() > 40 ? "...'" : "'");
}

/// What a YAML node is, for messages ("expected a number, got a list of 2").
std::string kindOf(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "no value";
  if (node.IsSequence()) return "a list of " + std::to_string(node.size());
  if (node.IsMap()) return "a mapping";
  return echo(node.Scalar());
}

/// A YAML node with its dotted path, for messages that name the field.
class Field {
 public:
  Field(YAML::Node node, std::string path, const std::string* file)
      : node_(std::move(node)), path_(std::move(path)), file_(file) {}

  [[noreturn]] void fail(const std::string& what) const {
    std::string where = *file_;
    if (node_.IsDefined() && node_.Mark().line >= 0) where += ":" + std::to_string(node_.Mark().line + 1);
    throw InputError(where + ": " + (path_.empty() ? "" : path_ + ": ") + what);
  }
  /// The key is present (with a value or without: at() reports "has no value").
  bool has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined(); }
  Field at(const std::string& key) const {
    if (!node_.IsMap()) fail("expected a mapping, got " + kindOf(node_));
    const std::string path = path_.empty() ? key : path_ + "." + key;
    if (!has(key)) Field(node_, path, file_).fail("missing (a required field)");
    const Field f(node_[key], path, file_);
    if (node_[key].IsNull()) {
      for (const auto& item : node_)  // the key's line: a missing value has none of its own
        if (item.first.IsScalar() && item.first.Scalar() == key) Field(item.first, path, file_).fail("has no value");
      f.fail("has no value");
    }
    return f;
  }
  /// Refuses keys not in `keys`, keys given twice and keys that are not names.
  void onlyKeys(std::initializer_list<const char*> keys) const {
    std::string expected;
    for (const char* k : keys) expected += (expected.empty() ? "" : ", ") + std::string(k);
    this->keys();  // a mapping, no key twice
    for (const auto& item : node_) {
      const std::string k = item.first.Scalar();
      bool known = false;
      for (const char* allowed : keys) known |= k == allowed;
      if (!known)
        Field(item.first, path_.empty() ? k : path_ + "." + k, file_).fail("unknown field (expected one of " + expected + ")");
    }
  }
  std::string text() const {
    if (!node_.IsScalar()) fail("expected a text value, got " + kindOf(node_));
    return node_.Scalar();
  }
  double number() const {
    if (!node_.IsScalar()) fail("expected a number, got " + kindOf(node_));
    double v = 0.0;
    try {
      v = node_.as<double>();  // YAML's forms too: .inf, .nan
    } catch (const YAML::Exception&) {
      std::string why;
      if (!parseFiniteNumber(node_.Scalar(), v, why))
        fail(echo(node_.Scalar()) + (why.find("too large") != std::string::npos ? " is too large (not a finite number)"
                                                                                 : " is not a number"));
    }
    if (!std::isfinite(v)) fail(echo(node_.Scalar()) + " is not a finite number");
    return v;
  }
  Eigen::VectorXd vector(int size) const {
    if (!node_.IsSequence() || static_cast<int>(node_.size()) != size)
      fail("expected a list of " + std::to_string(size) + " numbers, got " + kindOf(node_));
    Eigen::VectorXd v(size);
    for (int i = 0; i < size; ++i) v(i) = Field(node_[i], path_ + "[" + std::to_string(i) + "]", file_).number();
    return v;
  }
  Matrix3d matrix3() const {
    if (!node_.IsSequence() || node_.size() != 3) fail("expected 3 rows of 3 numbers, got " + kindOf(node_));
    Matrix3d m;
    for (int i = 0; i < 3; ++i) m.row(i) = Field(node_[i], path_ + "[" + std::to_string(i) + "]", file_).vector(3);
    return m;
  }
  std::map<std::string, double> namedNumbers() const {
    if (!node_.IsMap()) fail("expected a mapping NAME: VALUE, got " + kindOf(node_));
    std::map<std::string, double> values;
    for (const std::string& name : keys()) values[name] = at(name).number();
    return values;
  }
  const std::string& path() const { return path_; }
  bool isScalar() const { return node_.IsScalar(); }
  /// The keys of a mapping, in file order; refuses a key given twice or one that is not a name.
  std::vector<std::string> keys() const {
    if (!node_.IsMap()) fail("expected a mapping, got " + kindOf(node_));
    std::vector<std::string> k;
    for (const auto& item : node_) {
      if (!item.first.IsScalar()) Field(item.first, path_, file_).fail("a field name must be a text, got " + kindOf(item.first));
      const std::string name = item.first.Scalar();
      const std::string path = path_.empty() ? name : path_ + "." + name;
      if (std::find(k.begin(), k.end(), name) != k.end()) Field(item.first, path, file_).fail("given twice");
      k.push_back(name);
    }
    return k;
  }

 private:
  YAML::Node node_;
  std::string path_;
  const std::string* file_;
};

/// "a, b, c" of names, for messages that list what the model has.
std::string listNames(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list.empty() ? "none" : list;
}

std::vector<std::string> linkNames(const FloatingModel& model) {
  std::vector<std::string> names;
  for (const Body& b : model.bodies()) names.push_back(b.name);
  return names;
}

/// A pose from optional `position` and `rpy` fields of f (URDF convention).
KDL::Frame pose(const Field& f) {
  const Eigen::VectorXd p = f.has("position") ? f.at("position").vector(3) : Eigen::VectorXd::Zero(3);
  const Eigen::VectorXd r = f.has("rpy") ? f.at("rpy").vector(3) : Eigen::VectorXd::Zero(3);
  return basePose(KDL::Vector(p(0), p(1), p(2)), r(0), r(1), r(2));
}

/// Joint values by name; an unknown name is reported at its field.
KDL::JntArray joints(const Field& f, const FloatingModel& model) {
  const std::map<std::string, double> values = f.namedNumbers();
  for (const auto& [name, value] : values)
    if (model.jointIndex(name) < 0)
      f.at(name).fail("the model has no movable joint " + echo(name) + " (its movable joints: " +
                      listNames(model.jointNames()) + ")");
  return jointsByName(model, values);
}

ScenarioSystem system(const Field& f, const std::string& folder) {
  f.onlyKeys({"urdf", "contact", "base", "q", "qdot", "mode"});
  ScenarioSystem s;
  const Field urdf = f.at("urdf");
  s.urdf = urdf.text();
  if (s.urdf.empty()) urdf.fail("the file name is empty");
  if (std::filesystem::path(s.urdf).is_relative())
    s.urdf = (std::filesystem::path(folder) / s.urdf).lexically_normal().string();
  try {
    checkInputFile(s.urdf, "URDF file");
    s.model = std::make_shared<const FloatingModel>(loadUrdfFile(s.urdf));
  } catch (const InputError& e) {
    urdf.fail(e.what());
  } catch (const ModelError& e) {
    urdf.fail(e.what());
  }
  s.state = State(*s.model);
  s.velocity.qdot = KDL::JntArray(s.model->nj());
  if (f.has("base")) {
    const Field base = f.at("base");
    base.onlyKeys({"position", "rpy", "twist"});
    s.state.world_T_base = pose(base);
    if (base.has("twist")) s.velocity.base_twist = toTwist(Vector6d(base.at("twist").vector(6)));
  }
  if (f.has("q")) s.state.q = joints(f.at("q"), *s.model);
  if (f.has("qdot")) s.velocity.qdot = joints(f.at("qdot"), *s.model);
  const Field contact = f.at("contact");
  contact.onlyKeys({"link", "offset"});
  s.contact_link = contact.at("link").text();
  const Eigen::VectorXd o = contact.has("offset") ? contact.at("offset").vector(3) : Eigen::VectorXd::Zero(3);
  if (s.model->bodyIndex(s.contact_link) < 0)
    contact.at("link").fail("the model has no link " + echo(s.contact_link) + " (its links: " +
                            listNames(linkNames(*s.model)) + ")");
  s.contact = s.model->contact(s.contact_link, KDL::Vector(o(0), o(1), o(2)));
  if (f.has("mode")) {
    const std::string mode = f.at("mode").text();
    if (mode == "free") s.response = Response::FreeFloating;
    else if (mode == "grounded") s.response = Response::Grounded;
    else if (mode == "locked") s.response = Response::JointsLocked;
    else f.at("mode").fail(echo(mode) + " is not one of free, grounded, locked");
  }
  return s;
}

RigidBody rigidTarget(const Field& f) {
  f.onlyKeys({"mass", "inertia", "pose", "com", "twist"});
  RigidBody b;
  b.mass = f.at("mass").number();
  if (!(b.mass > 0.0)) f.at("mass").fail("must be > 0 kg, got " + show(b.mass));
  const Matrix3d I = f.at("inertia").matrix3();
  if ((I - I.transpose()).norm() > 1e-12 * I.norm()) {
    Eigen::Index i = 0, j = 0;
    (I - I.transpose()).cwiseAbs().maxCoeff(&i, &j);
    f.at("inertia").fail("must be symmetric, but row " + std::to_string(i + 1) + " column " + std::to_string(j + 1) +
                         " is " + show(I(i, j)) + " and row " + std::to_string(j + 1) + " column " +
                         std::to_string(i + 1) + " is " + show(I(j, i)));
  }
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(I, Eigen::EigenvaluesOnly);
  const Vector3d l = eig.eigenvalues();  // ascending
  const std::string moments = "(principal moments " + show(l(0)) + ", " + show(l(1)) + ", " + show(l(2)) + " kg m^2)";
  if (!(l(0) > 0.0)) f.at("inertia").fail("must be positive definite " + moments);
  if (l(0) + l(1) < l(2) * (1.0 - 1e-9))
    f.at("inertia").fail("is no rigid body's inertia: its principal moments break the triangle inequality "
                         "I1 + I2 >= I3 " + moments);
  KDL::Frame world_T_target = KDL::Frame::Identity();
  if (f.has("pose")) {
    f.at("pose").onlyKeys({"position", "rpy"});
    world_T_target = pose(f.at("pose"));
  }
  const Matrix3d R = toEigen(world_T_target.M);
  b.I_com = R * I * R.transpose();
  const Eigen::VectorXd c = f.has("com") ? f.at("com").vector(3) : Eigen::VectorXd::Zero(3);
  b.com = toEigen(world_T_target * KDL::Vector(c(0), c(1), c(2)));
  if (f.has("twist")) b.twist = f.at("twist").vector(6);
  return b;
}

ImpactLaw law(const Field& f, bool& has_normal) {
  f.onlyKeys({"type", "normal", "restitution", "friction"});
  ImpactLaw l;
  const std::string type = f.at("type").text();
  if (type == "capture") l.kind = ImpactKind::Capture;
  else if (type == "point") l.kind = ImpactKind::PointImpact;
  else if (type == "friction") l.kind = ImpactKind::FrictionalImpact;
  else if (type == "translational") l.kind = ImpactKind::TranslationalCapture;
  else f.at("type").fail(echo(type) + " is not one of capture, point, friction, translational");
  const bool point = l.kind == ImpactKind::PointImpact || l.kind == ImpactKind::FrictionalImpact;
  has_normal = f.has("normal");
  if (point && !has_normal) f.at("normal");  // reports "missing"
  if (has_normal) {
    const Vector3d n = f.at("normal").vector(3);
    if (!(n.norm() > 1e-12)) f.at("normal").fail("has zero length");
    l.normal = n.normalized();
  }
  if (f.has("restitution")) {
    l.restitution = f.at("restitution").number();
    if (l.restitution < 0.0 || l.restitution > 1.0) f.at("restitution").fail("must lie in [0, 1], got " + show(l.restitution));
  } else if (point) {
    f.at("restitution");
  }
  if (f.has("friction")) {
    l.friction = f.at("friction").number();
    if (l.friction < 0.0) f.at("friction").fail("must be >= 0, got " + show(l.friction));
  } else if (l.kind == ImpactKind::FrictionalImpact) {
    f.at("friction");
  }
  return l;
}

SimulationSpec simulation(const Field& f, const FloatingModel& robot) {
  f.onlyKeys({"duration", "output_step", "integrator", "step", "rtol", "atol", "max_step", "max_steps", "gravity",
              "joints"});
  SimulationSpec s;
  const auto positive = [&](const char* key, double& value) {
    if (!f.has(key)) return;
    value = f.at(key).number();
    if (!(value > 0.0)) f.at(key).fail("must be > 0, got " + show(value));
  };
  positive("duration", s.duration);
  positive("output_step", s.output_step);
  positive("step", s.options.step);
  positive("rtol", s.options.rtol);
  positive("atol", s.options.atol);
  positive("max_step", s.options.max_step);
  if (f.has("max_steps")) {
    const double budget = f.at("max_steps").number();
    if (!(budget >= 1.0) || budget != std::floor(budget) || budget > 1e12)
      f.at("max_steps").fail("must be a whole number of steps from 1 to 1e12, got " + show(budget));
    s.options.max_steps = static_cast<long>(budget);
  }
  if (f.has("integrator")) {
    const std::string name = f.at("integrator").text();
    if (name == "rk4") s.options.integrator = Integrator::RK4;
    else if (name == "dopri5") s.options.integrator = Integrator::DormandPrince54;
    else f.at("integrator").fail(echo(name) + " is not one of rk4, dopri5");
  }
  if (f.has("gravity")) s.options.gravity = f.at("gravity").vector(3);
  if (f.has("joints")) {
    const Field joints = f.at("joints");
    for (const std::string& name : joints.keys()) {
      const Field j = joints.at(name);
      const int index = robot.jointIndex(name);
      if (index < 0)
        j.fail("the robot has no movable joint " + echo(name) + " (its movable joints: " + listNames(robot.jointNames()) + ")");
      JointControl c;
      if (j.isScalar()) {
        const std::string mode = j.text();
        if (mode == "free") c.mode = JointControl::Mode::Free;
        else if (mode == "locked") c.mode = JointControl::Mode::Locked;
        else j.fail(echo(mode) + " is not one of free, locked, {pd: {kp, kd, set_point}}");
      } else {
        j.onlyKeys({"pd"});
        const Field pd = j.at("pd");
        pd.onlyKeys({"kp", "kd", "set_point"});
        c.mode = JointControl::Mode::PD;
        c.kp = pd.at("kp").number();
        c.kd = pd.at("kd").number();
        c.set_point = pd.at("set_point").number();
        if (c.kp < 0.0) pd.at("kp").fail("must be >= 0, got " + show(c.kp));
        if (c.kd < 0.0) pd.at("kd").fail("must be >= 0, got " + show(c.kd));
      }
      s.joints.emplace_back(static_cast<unsigned int>(index), c);
    }
  }
  return s;
}

}  // namespace

Scenario loadScenario(const std::string& file) {
  Scenario s;
  s.file = file;
  checkInputFile(file, "scenario file (YAML or JSON)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw InputError(file + ": cannot open the file");
  } catch (const YAML::Exception& e) {
    std::string msg;  // yaml-cpp quotes the offending byte: keep it printable
    for (const char c : e.msg) msg += static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f ? c : '?';
    throw InputError(file + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML or JSON: " + msg);
  } catch (const std::exception& e) {
    throw InputError(file + ": cannot read the file: " + e.what());
  }
  const Field top(root, "", &s.file);
  if (root.IsNull()) throw InputError(file + ": holds no data; a scenario is a mapping with robot, target and law");
  if (!root.IsMap()) top.fail("a scenario is a mapping with robot, target and law, not " + kindOf(root));
  top.onlyKeys({"robot", "target", "law", "simulation"});
  const std::string folder = std::filesystem::path(file).parent_path().string();
  s.robot = system(top.at("robot"), folder);
  const Field target = top.at("target");
  if (target.has("urdf")) s.floating_target = system(target, folder);
  else s.rigid_target = rigidTarget(target);
  s.law = law(top.at("law"), s.has_normal);
  if (top.has("simulation")) s.simulation = simulation(top.at("simulation"), *s.robot.model);
  return s;
}

}  // namespace kdl_space::cli
