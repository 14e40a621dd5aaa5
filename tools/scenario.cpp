#include "scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <filesystem>
#include <map>

#include "cli_common.hpp"
#include "kdl_space/urdf_loader.hpp"

namespace kdl_space::cli {
namespace {

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
  bool has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull(); }
  Field at(const std::string& key) const {
    if (!node_.IsMap()) fail("expected a mapping");
    const std::string path = path_.empty() ? key : path_ + "." + key;
    if (!has(key)) Field(node_, path, file_).fail("missing");
    return Field(node_[key], path, file_);
  }
  void onlyKeys(std::initializer_list<const char*> keys) const {
    if (!node_.IsMap()) fail("expected a mapping");
    for (const auto& item : node_) {
      const std::string k = item.first.as<std::string>();
      bool known = false;
      for (const char* allowed : keys) known |= k == allowed;
      if (!known) Field(item.first, path_.empty() ? k : path_ + "." + k, file_).fail("unknown field");
    }
  }
  std::string text() const {
    if (!node_.IsScalar()) fail("expected a text value");
    return node_.as<std::string>();
  }
  double number() const {
    if (!node_.IsScalar()) fail("expected a number");
    double v = 0.0;
    try {
      v = node_.as<double>();
    } catch (const YAML::Exception&) {
      fail("'" + node_.as<std::string>() + "' is not a number");
    }
    if (!std::isfinite(v)) fail("must be finite");
    return v;
  }
  Eigen::VectorXd vector(int size) const {
    if (!node_.IsSequence() || static_cast<int>(node_.size()) != size)
      fail("expected a list of " + std::to_string(size) + " numbers");
    Eigen::VectorXd v(size);
    for (int i = 0; i < size; ++i) v(i) = Field(node_[i], path_ + "[" + std::to_string(i) + "]", file_).number();
    return v;
  }
  Matrix3d matrix3() const {
    if (!node_.IsSequence() || node_.size() != 3) fail("expected 3 rows of 3 numbers");
    Matrix3d m;
    for (int i = 0; i < 3; ++i) m.row(i) = Field(node_[i], path_ + "[" + std::to_string(i) + "]", file_).vector(3);
    return m;
  }
  std::map<std::string, double> namedNumbers() const {
    if (!node_.IsMap()) fail("expected a mapping NAME: VALUE");
    std::map<std::string, double> values;
    for (const auto& item : node_) {
      const std::string name = item.first.as<std::string>();
      values[name] = Field(item.second, path_ + "." + name, file_).number();
    }
    return values;
  }
  const std::string& path() const { return path_; }
  bool isScalar() const { return node_.IsScalar(); }
  /// The keys of a mapping, in file order.
  std::vector<std::string> keys() const {
    if (!node_.IsMap()) fail("expected a mapping");
    std::vector<std::string> k;
    for (const auto& item : node_) k.push_back(item.first.as<std::string>());
    return k;
  }

 private:
  YAML::Node node_;
  std::string path_;
  const std::string* file_;
};

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
    if (model.jointIndex(name) < 0) f.at(name).fail("the model has no movable joint '" + name + "'");
  return jointsByName(model, values);
}

ScenarioSystem system(const Field& f, const std::string& folder) {
  f.onlyKeys({"urdf", "contact", "base", "q", "qdot", "mode"});
  ScenarioSystem s;
  const Field urdf = f.at("urdf");
  s.urdf = urdf.text();
  if (std::filesystem::path(s.urdf).is_relative()) s.urdf = (std::filesystem::path(folder) / s.urdf).string();
  try {
    s.model = std::make_shared<const FloatingModel>(loadUrdfFile(s.urdf));
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
    contact.at("link").fail("the model has no link '" + s.contact_link + "'");
  s.contact = s.model->contact(s.contact_link, KDL::Vector(o(0), o(1), o(2)));
  if (f.has("mode")) {
    const std::string mode = f.at("mode").text();
    if (mode == "free") s.response = Response::FreeFloating;
    else if (mode == "grounded") s.response = Response::Grounded;
    else if (mode == "locked") s.response = Response::JointsLocked;
    else f.at("mode").fail("'" + mode + "' is not one of free, grounded, locked");
  }
  return s;
}

RigidBody rigidTarget(const Field& f) {
  f.onlyKeys({"mass", "inertia", "pose", "com", "twist"});
  RigidBody b;
  b.mass = f.at("mass").number();
  if (!(b.mass > 0.0)) f.at("mass").fail("must be > 0 kg");
  const Matrix3d I = f.at("inertia").matrix3();
  if ((I - I.transpose()).norm() > 1e-12 * I.norm()) f.at("inertia").fail("must be symmetric");
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(I, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()(0) > 0.0)) f.at("inertia").fail("must be positive definite");
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
  else f.at("type").fail("'" + type + "' is not one of capture, point, friction, translational");
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
    if (l.restitution < 0.0 || l.restitution > 1.0) f.at("restitution").fail("must lie in [0, 1]");
  } else if (point) {
    f.at("restitution");
  }
  if (f.has("friction")) {
    l.friction = f.at("friction").number();
    if (l.friction < 0.0) f.at("friction").fail("must be >= 0");
  } else if (l.kind == ImpactKind::FrictionalImpact) {
    f.at("friction");
  }
  return l;
}

SimulationSpec simulation(const Field& f, const FloatingModel& robot) {
  f.onlyKeys({"duration", "output_step", "integrator", "step", "rtol", "atol", "max_step", "gravity", "joints"});
  SimulationSpec s;
  const auto positive = [&](const char* key, double& value) {
    if (!f.has(key)) return;
    value = f.at(key).number();
    if (!(value > 0.0)) f.at(key).fail("must be > 0");
  };
  positive("duration", s.duration);
  positive("output_step", s.output_step);
  positive("step", s.options.step);
  positive("rtol", s.options.rtol);
  positive("atol", s.options.atol);
  positive("max_step", s.options.max_step);
  if (f.has("integrator")) {
    const std::string name = f.at("integrator").text();
    if (name == "rk4") s.options.integrator = Integrator::RK4;
    else if (name == "dopri5") s.options.integrator = Integrator::DormandPrince54;
    else f.at("integrator").fail("'" + name + "' is not one of rk4, dopri5");
  }
  if (f.has("gravity")) s.options.gravity = f.at("gravity").vector(3);
  if (f.has("joints")) {
    const Field joints = f.at("joints");
    for (const std::string& name : joints.keys()) {
      const Field j = joints.at(name);
      const int index = robot.jointIndex(name);
      if (index < 0) j.fail("the robot has no movable joint '" + name + "'");
      JointControl c;
      if (j.isScalar()) {
        const std::string mode = j.text();
        if (mode == "free") c.mode = JointControl::Mode::Free;
        else if (mode == "locked") c.mode = JointControl::Mode::Locked;
        else j.fail("'" + mode + "' is not one of free, locked, {pd: {kp, kd, set_point}}");
      } else {
        j.onlyKeys({"pd"});
        const Field pd = j.at("pd");
        pd.onlyKeys({"kp", "kd", "set_point"});
        c.mode = JointControl::Mode::PD;
        c.kp = pd.at("kp").number();
        c.kd = pd.at("kd").number();
        c.set_point = pd.at("set_point").number();
        if (c.kp < 0.0) pd.at("kp").fail("must be >= 0");
        if (c.kd < 0.0) pd.at("kd").fail("must be >= 0");
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
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw InputError(file + ": cannot open the file");
  } catch (const YAML::Exception& e) {
    throw InputError(file + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML or JSON: " + e.msg);
  }
  const Field top(root, "", &s.file);
  if (!root.IsMap()) top.fail("a scenario is a mapping with robot, target and law");
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
