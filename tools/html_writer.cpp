#include "html_writer.hpp"

#include <cerrno>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "capture.hpp"
#include "html_page.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/report/scene_writer.hpp"

namespace kdl_space::cli {
namespace {

/// Base64 of raw bytes (the page decodes it with atob into typed arrays).
std::string base64(const void* bytes, std::size_t n) {
  static const char* const abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(bytes);
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  for (std::size_t i = 0; i < n; i += 3) {
    const unsigned v = (p[i] << 16) | ((i + 1 < n ? p[i + 1] : 0) << 8) | (i + 2 < n ? p[i + 2] : 0);
    out += abc[(v >> 18) & 63];
    out += abc[(v >> 12) & 63];
    out += i + 1 < n ? abc[(v >> 6) & 63] : '=';
    out += i + 2 < n ? abc[v & 63] : '=';
  }
  return out;
}

std::string readText(const std::string& path, const std::string& where) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().empty())
    throw InputError(where + "cannot read " + path + " (Debian package libjs-three; tools/deps.sh installs it)");
  return text.str();
}

/// Position and quaternion (x y z w) of a frame, appended as floats.
void pushPose(std::vector<float>& out, const KDL::Frame& f) {
  double x, y, z, w;
  f.M.GetQuaternion(x, y, z, w);
  for (double v : {f.p.x(), f.p.y(), f.p.z(), x, y, z, w}) out.push_back(static_cast<float>(v));
}

void pushHidden(std::vector<float>& out) {
  for (int k = 0; k < 7; ++k) out.push_back(std::nanf(""));
}

Json poseJson(const KDL::Frame& f) {
  double x, y, z, w;
  f.M.GetQuaternion(x, y, z, w);
  return Json::array({f.p.x(), f.p.y(), f.p.z(), x, y, z, w});
}

/// A body's box of inertia in its own frame (what a link without a drawable visual shows).
Json inertiaBoxJson(const Body& b) {
  const SceneBox box = equivalentBox(b.mass, b.I_com, b.com);
  const Vector3d size = box.size.cwiseMax(1e-3);  // a point mass still shows
  return {{"shape", "box"}, {"size", {size.x(), size.y(), size.z()}}, {"origin", poseJson(box.pose)},
          {"rgba", {0.75, 0.75, 0.78, 0.5}}, {"inertia_box", true}};
}

Json visualJson(const LinkVisual& v) {
  static const char* const shapes[] = {"box", "cylinder", "sphere", "mesh"};
  Json j = {{"shape", shapes[static_cast<int>(v.shape)]},
            {"size", {v.size.x(), v.size.y(), v.size.z()}},
            {"origin", poseJson(v.origin)}};
  if (v.rgba) j["rgba"] = {(*v.rgba)(0), (*v.rgba)(1), (*v.rgba)(2), (*v.rgba)(3)};
  return j;
}

// --- meshes (STL, COLLADA) --------------------------------------------------------------------

/// "stl" or "dae" by the file's extension (any case); "" for a format the page does not read.
std::string meshFormat(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".stl" ? "stl" : ext == ".dae" ? "dae" : "";
}

/// A mesh visual drawn from the page's mesh `index` (D.meshes), scaled by the URDF's scale.
Json meshVisualJson(const LinkVisual& v, int index) {
  Json j = visualJson(v);
  j["mesh"] = index;
  j["scale"] = {v.mesh_scale.x(), v.mesh_scale.y(), v.mesh_scale.z()};
  j["file"] = v.mesh_file;
  return j;
}

/// The page's JSON with every `<`, `>` and `&` written as a JSON escape (`\u003c`...): JSON has
/// them only inside strings, where the escape reads back the same; no `</script>`, `<!--` or
/// `<script>` in a name then ends or swallows the <script> that holds the data.
std::string scriptSafe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) {
    if (c == '<') out += "\\u003c";
    else if (c == '>') out += "\\u003e";
    else if (c == '&') out += "\\u0026";
    else out += c;
  }
  return out;
}

}  // namespace

CLI::Option* addMeshPathOption(CLI::App* cmd, std::vector<std::string>& dirs) {
  const CLI::Validator folder(
      [](std::string& dir) {
        std::error_code ec;
        return std::filesystem::is_directory(dir, ec) ? std::string() : dir + " is not a folder (give the folder that holds the package folders)";
      },
      "");
  return cmd->add_option("--mesh-path", dirs,
                         "A folder where the URDF's package://PACKAGE/... meshes are looked for (as DIR/PACKAGE/..., or "
                         "DIR/... when DIR is named PACKAGE); repeatable, searched in order before ROS_PACKAGE_PATH")
      ->type_name("DIR")->check(folder)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

std::vector<std::string> meshSearchPath(const std::vector<std::string>& mesh_path_options) {
  std::vector<std::string> dirs = mesh_path_options;
  if (const char* ros = std::getenv("ROS_PACKAGE_PATH")) {
    std::istringstream list(ros);
    for (std::string dir; std::getline(list, dir, ':');)
      if (!dir.empty()) dirs.push_back(dir);
  }
  return dirs;
}

int HtmlWriter::meshIndex(const std::string& path) const {
  for (std::size_t i = 0; i < meshes_.size(); ++i)
    if (meshes_[i].path == path) return static_cast<int>(i);
  return -1;
}

/// Each STL and COLLADA file read once; every other mesh is left to its box of inertia (its
/// mesh_path cleared) with a warning that says why and what to do.
void HtmlWriter::readMeshes() {
  for (auto& [link, list] : visuals_)
    for (LinkVisual& v : list) readMesh(link, v);
}

/// One mesh visual of `link` (a name for the warning): read into meshes_ once per file, or its
/// mesh_path cleared with a warning.
void HtmlWriter::readMesh(const std::string& link, LinkVisual& v) {
  if (v.shape != LinkVisual::Shape::Mesh) return;
  const std::string format = meshFormat(v.mesh_path.empty() ? v.mesh_file : v.mesh_path);
  std::string why;
  if (v.mesh_path.empty()) {
    why = "was not found (" + v.mesh_problem +
          "): give --mesh-path DIR (the folder holding the package's folder) or set ROS_PACKAGE_PATH";
  } else if (format.empty()) {
    why = "(" + v.mesh_path + ") is not drawn: only STL and COLLADA (.dae) meshes are read; convert it to one of them";
  } else if (std::ifstream(format == "stl" ? kStlLoaderJs : kColladaLoaderJs).fail()) {
    why = "is not drawn: three.js's loader is not installed (Debian package libjs-three; tools/deps.sh installs it)";
  } else if (meshIndex(v.mesh_path) < 0) {
    MeshBytes read = readMeshFile(v.mesh_path, format == "dae");
    if (!read.problem.empty()) why = "(" + v.mesh_path + ") " + read.problem + ": check the file";
    else meshes_.push_back({v.mesh_path, format, std::move(read.bytes)});
    if (!read.dropped.empty())
      warnings_.push_back({link, "--html: the mesh " + v.mesh_file + " is drawn without its " + read.dropped,
                           "mesh_reference_dropped", Severity::Warning});
  }
  if (why.empty()) return;
  warnings_.push_back({link, "--html: the mesh " + v.mesh_file + " " + why + "; the page draws the link's box of inertia",
                       "mesh_not_drawn", Severity::Warning});
  v.mesh_path.clear();
}

// --- The meshes a page reads, as inputs no output may replace (issue 25's rule) ----------------
PageVisuals readPageVisuals(const Scenario& sc, const std::vector<std::string>& mesh_search_path) {
  PageVisuals visuals;
  if (!sc.robot_urdf.empty()) visuals.robot = readUrdfVisuals(sc.robot_urdf, mesh_search_path);
  if (!sc.target_urdf.empty()) visuals.target = readUrdfVisuals(sc.target_urdf, mesh_search_path);
  return visuals;
}

std::vector<InputFile> meshInputs(const PageVisuals& visuals) {
  std::vector<InputFile> inputs;
  const std::pair<const std::map<std::string, std::vector<LinkVisual>>&, const char*> urdfs[] = {
      {visuals.robot, "link "}, {visuals.target, "the target's link "}};
  for (const auto& [read, whose] : urdfs)
    for (const auto& [link, list] : read)
      for (const LinkVisual& v : list)
        if (v.shape == LinkVisual::Shape::Mesh && !v.mesh_path.empty())
          inputs.push_back({"the mesh " + v.mesh_file + " of " + whose + link, v.mesh_path});
  return inputs;
}

std::vector<InputFile> meshInputs(const Scenario& sc, const std::vector<std::string>& mesh_search_path) {
  return meshInputs(readPageVisuals(sc, mesh_search_path));
}

void checkHtmlLibrary(const std::string& option, const std::string& path) {
  for (const char* file : {kThreeJs, kOrbitControlsJs})
    if (std::ifstream(file).fail())
      throw InputError(option + " " + path + ": three.js is not installed (" + file +
                       "; Debian package libjs-three; tools/deps.sh installs it)");
}

namespace {
/// The visuals a page of `sc` draws, for a run that has not read them: the target's only when the
/// page draws them (HtmlWriter::drawsTargetVisuals).
PageVisuals visualsToDraw(const Scenario& sc, const std::vector<std::string>& mesh_search_path, bool target) {
  PageVisuals visuals;
  if (!sc.robot_urdf.empty()) visuals.robot = readUrdfVisuals(sc.robot_urdf, mesh_search_path);
  if (target) visuals.target = readUrdfVisuals(sc.target_urdf, mesh_search_path);
  return visuals;
}
}  // namespace

HtmlWriter::HtmlWriter(const Scenario& sc, const std::vector<std::string>& mesh_search_path, double frames_per_second,
                       std::size_t max_frames)
    : HtmlWriter(sc, visualsToDraw(sc, mesh_search_path, drawsTargetVisuals(sc)), frames_per_second, max_frames) {}

HtmlWriter::HtmlWriter(const Scenario& sc, PageVisuals visuals, double frames_per_second, std::size_t max_frames)
    : sc_(sc), step_(1.0 / frames_per_second), max_frames_(std::max<std::size_t>(2, max_frames)) {
  const FloatingModel& robot = *sc.capture.robot.model;
  for (const Body& b : robot.bodies()) links_.push_back(b.name);
  visuals_ = std::move(visuals.robot);
  readMeshes();
  useTargetVisuals(std::move(visuals.target));
  warnOnStderr(warnings_);
  if (sc.impact)
    if (const auto* rigid = std::get_if<RigidTarget>(&sc.capture.target)) {
      target_ = *rigid;
      tumble_.emplace(*rigid);
    }
  // A free-floating target: its links, drawn from its URDF's visuals (or their boxes of inertia).
  if (sc.impact)
    if (const auto* other = std::get_if<FloatingSystem>(&sc.capture.target)) {
      target_model_ = other->model;  // its visuals: useTargetVisuals
    }
}

std::vector<float> HtmlWriter::frameOf(const OperationResult& so_far, const MotionSample& x) {
  const FloatingModel& model = *so_far.model;
  if (model_ != &model) {  // a new system (the capture): its bodies by the robot's link names
    model_ = &model;
    index_.assign(links_.size(), -1);
    target_body_ = -1;
    for (std::size_t i = 0; i < model.bodies().size(); ++i) {
      bool robot = false;
      for (std::size_t k = 0; k < links_.size(); ++k)
        if (model.bodies()[i].name == links_[k]) index_[k] = static_cast<int>(i), robot = true;
      if (!robot && model.bodies()[i].mass > 0.0) target_body_ = static_cast<int>(i);  // the last: a joined target
    }
  }
  State state(model);
  state.world_T_base = KDL::Frame(KDL::Rotation::Quaternion(x.quat(0), x.quat(1), x.quat(2), x.quat(3)), toKDL(x.p));
  for (Eigen::Index j = 0; j < x.q.size() && j < static_cast<Eigen::Index>(model.nj()); ++j) state.q(j) = x.q(j);
  Kinematics kin(model);
  std::vector<float> f;
  if (forwardKinematics(model, state, kin) != E_NOERROR) return f;  // not drawn
  const Contact& h = sc_.capture.robot.contact;
  const int hand = h.body >= 0 ? index_[h.body] : -1;
  const Vector3d c = hand >= 0 ? kin.point(Contact{hand, h.offset}) : Vector3d::Constant(std::nan(""));
  for (int k = 0; k < 3; ++k) f.push_back(static_cast<float>(c(k)));
  for (int i : index_)
    if (i >= 0) pushPose(f, kin.pose(i)); else pushHidden(f);
  if (target_model_) {
    pushFloatingTarget(f, so_far, x, kin);
    return f;
  }
  if (!target_) return f;
  // The target's frame: tumbling before the capture; then held by the hand, joined (its body's
  // inertia box; a compliant contact's rows too when caught: its system holds the body), or
  // tumbling on from the capture (from a compliant contact's end, when it opened).
  const bool after = so_far.capture && (x.phase == Phase::Post || (x.phase == Phase::Contact && so_far.joined));
  RigidTarget now = *target_;
  if (!after) {
    if (tumble_->at(x.t, now) != E_NOERROR) { pushHidden(f); return f; }
    pushPose(f, now.pose);
    return f;
  }
  if (so_far.joined && target_body_ >= 0) {
    const SceneBox box = equivalentBox(model.bodies()[target_body_].mass, kin.I_com[target_body_], kin.com[target_body_]);
    const SceneBox local = equivalentBox(target_->mass, target_->inertia, target_->com);
    pushPose(f, box.pose * local.pose.Inverse());  // the frame whose box is where the body's is
    return f;
  }
  const auto* at_contact = std::get_if<RigidTarget>(&so_far.at_contact.target);
  if (!at_contact) { pushHidden(f); return f; }
  if (so_far.payload_attached && hand >= 0) {
    if (!hand_T_target_) hand_T_target_ = kin.pose(hand).Inverse() * at_contact->pose;  // the first sample after
    pushPose(f, kin.pose(hand) * *hand_T_target_);
    return f;
  }
  const bool bounced = so_far.compliant.has_value();  // not joined: the contact opened
  if (!after_) {
    RigidTarget separated = *at_contact;
    separated.twist = so_far.capture->target_twist_after;
    if (bounced) {  // its one-body system: the base frame at the CoM, the target frame's axes
      const FloatingSystem& end = so_far.compliant->target_end;
      separated.pose = end.state.world_T_base * KDL::Frame(toKDL(Vector3d(-at_contact->com)));
      separated.twist = toEigen(end.velocity.base_twist);
    }
    after_.emplace(separated);
  }
  const double t0 = so_far.t_capture + (bounced ? so_far.compliant->duration : 0.0);
  if (after_->at(x.t - t0, now) != E_NOERROR) pushHidden(f); else pushPose(f, now.pose);
  return f;
}

void HtmlWriter::add(const OperationResult& so_far, const MotionSample& x) {
  std::vector<float> f = frameOf(so_far, x);
  if (f.empty()) return;
  appendSeries(f, so_far, x);
  if (x.t >= next_t_ || x.phase == Phase::Capture) {
    keep(std::move(f), x);
    last_.clear();
  } else {
    last_ = std::move(f);
    last_t_ = x.t;
    last_phase_ = static_cast<int>(x.phase);
  }
}

void HtmlWriter::keep(std::vector<float> frame, const MotionSample& x) {
  if (!times_.empty() && x.t < times_.back()) return;
  data_.insert(data_.end(), frame.begin(), frame.end());
  times_.push_back(x.t);
  phases_.push_back(static_cast<int>(x.phase));
  next_t_ = x.t + step_;
  if (times_.size() < max_frames_) return;
  // Full: every other frame goes (the capture's stays), at half the rate from now on.
  const std::size_t stride = frame.size();
  std::size_t kept = 0;
  for (std::size_t k = 0; k < times_.size(); ++k) {
    if (k % 2 && phases_[k] != static_cast<int>(Phase::Capture) && k + 1 != times_.size()) continue;
    std::memmove(&data_[kept * stride], &data_[k * stride], stride * sizeof(float));
    times_[kept] = times_[k];
    phases_[kept] = phases_[k];
    ++kept;
  }
  data_.resize(kept * stride);
  times_.resize(kept);
  phases_.resize(kept);
  step_ *= 2.0;
  next_t_ = times_.back() + step_;
}

void HtmlWriter::write(const AtomicFile& file, const OperationResult& r, const std::string& title, const std::string& note) {
  const std::string where = "--html " + file.path() + ": ";
  if (!last_.empty() && (times_.empty() || last_t_ > times_.back())) {
    data_.insert(data_.end(), last_.begin(), last_.end());
    times_.push_back(last_t_);
    phases_.push_back(last_phase_);
    last_.clear();
  }
  if (times_.empty()) throw InputError(where + "the run gave no sample to draw");
  Json plots_data;
  plotsJson(plots_data, r);  // splits the series off data_
  const FloatingModel& robot = *sc_.capture.robot.model;
  Json links = Json::array();
  for (const Body& b : robot.bodies()) {
    Json visuals = Json::array();
    if (const auto it = visuals_.find(b.name); it != visuals_.end())
      for (const LinkVisual& v : it->second) {
        if (v.shape != LinkVisual::Shape::Mesh) visuals.push_back(visualJson(v));
        else if (v.mesh_path.empty()) visuals.push_back(inertiaBoxJson(b));  // warned about
        else visuals.push_back(meshVisualJson(v, meshIndex(v.mesh_path)));
      }
    if (visuals.empty()) visuals.push_back(inertiaBoxJson(b));
    links.push_back({{"name", b.name}, {"visuals", visuals}});
  }
  Json data = {{"title", title}, {"note", note}, {"links", links}, {"frameCount", times_.size()},
               {"stride", data_.size() / times_.size()}, {"frames", base64(data_.data(), data_.size() * sizeof(float))},
               {"times", base64(times_.data(), times_.size() * sizeof(double))}, {"phases", phases_},
               {"phaseNames", {"approach", "contact", "after", "motion", "compliant contact"}}};
  // Each mesh file once (a mesh several links use is stored once), base64.
  data["meshes"] = Json::array();
  bool stl = false, dae = false;
  for (const MeshData& m : meshes_) {
    data["meshes"].push_back({{"file", m.path}, {"format", m.format}, {"data", base64(m.bytes.data(), m.bytes.size())}});
    (m.format == "stl" ? stl : dae) = true;
  }
  for (auto& [key, value] : plots_data.items()) data[key] = value;
  data["target"] = nullptr;
  if (target_) {
    const Vector3d size = equivalentBox(target_->mass, target_->inertia, target_->com).size.cwiseMax(1e-3);  // in its frame
    const SceneBox local = equivalentBox(target_->mass, target_->inertia, target_->com);
    data["target"] = {{"size", {size.x(), size.y(), size.z()}}, {"origin", poseJson(local.pose)}};
  }
  data["tCapture"] = nullptr;
  data["impulse"] = nullptr;
  if (sc_.impact && (r.approach || r.capture)) data["tCapture"] = r.t_capture;
  if (r.capture) {
    const Vector6d& F = r.capture->impulse.F;
    data["impulse"] = {F(0), F(1), F(2)};
  }
  writeTargetAndGrasp(data, r);
  errno = 0;
  std::ofstream out(file.tmp(), std::ios::binary);
  if (!out) throw InputError(where + "cannot write in its folder: " + writeFailure());
  out << kHtmlHead << "<script>\n" << readText(kThreeJs, where) << "\n</script>\n<script>\n"
      << readText(kOrbitControlsJs, where) << "\n</script>\n";
  // The mesh loaders only in a page that has such a mesh (the page stays small without).
  if (stl) out << "<script>\n" << readText(kStlLoaderJs, where) << "\n</script>\n";
  if (dae) out << "<script>\n" << readText(kColladaLoaderJs, where) << "\n</script>\n";
  out << "<script>\nwindow.KDL_DATA = "
      << scriptSafe(jsonText(data, -1)) << ";\n</script>\n" << kHtmlBody;
  out.close();
  if (!out) throw InputError(where + "cannot write the page: " + writeFailure());
}

// --- the linked plots (issue 27, item 3) ---------------------------------------------------------

/// The plots' values of a sample, in float32 (2^-24 relative), appended to its frame: the base's
/// attitude (roll, pitch, yaw, fixed X-Y-Z as KDL's GetRPY) [deg] and angular rate (world axes)
/// [deg/s], the robot's joint rates and torques (NaN for a joint the sample's system lacks), |P|,
/// |L| (about the world origin), the kinetic energy T and its balance T - T_0 - work (T_0 at the
/// phase's first sample: the balance restarts at the capture, as the --plot's), the base
/// control's torque (world axes).
void HtmlWriter::appendSeries(std::vector<float>& f, const OperationResult& so_far, const MotionSample& x) {
  const std::vector<std::string>& robot = sc_.capture.robot.model->jointNames();
  if (series_model_ != so_far.model.get()) {
    series_model_ = so_far.model.get();
    const std::vector<std::string>& names = series_model_->jointNames();
    series_joints_.assign(robot.size(), -1);
    for (std::size_t j = 0; j < robot.size(); ++j)
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == robot[j]) series_joints_[j] = static_cast<int>(i);
  }
  if (!series_phase0_ || ((x.phase == Phase::Post || x.phase == Phase::Contact) && series_phase_ != x.phase)) {
    series_phase0_ = true, series_phase_ = x.phase, series_T0_ = x.T;
  }
  series_at_ = f.size();
  double roll, pitch, yaw;
  KDL::Rotation::Quaternion(x.quat(0), x.quat(1), x.quat(2), x.quat(3)).GetRPY(roll, pitch, yaw);
  for (double v : {roll, pitch, yaw, x.twist(3), x.twist(4), x.twist(5)}) f.push_back(static_cast<float>(v * 180 / M_PI));
  const auto joint = [&](const Eigen::VectorXd& v, std::size_t j) {
    const int i = series_joints_[j];
    return i >= 0 && i < v.size() ? static_cast<float>(v(i)) : std::nanf("");
  };
  for (std::size_t j = 0; j < robot.size(); ++j) f.push_back(joint(x.qd, j));
  for (std::size_t j = 0; j < robot.size(); ++j) f.push_back(joint(x.tau, j));
  for (double v : {x.h.head<3>().norm(), x.h.tail<3>().norm(), x.T, x.T - series_T0_ - x.work.sum()})
    f.push_back(static_cast<float>(v));
  for (int i = 3; i < 6; ++i) f.push_back(static_cast<float>(x.base_wrench(i)));
  series_size_ = f.size() - series_at_;
}

/// The plots' JSON (`plots`: name, label, series names, first column; `series`: base64 float32,
/// `seriesStride` per frame) and data_ cut back to the frames' poses. No torque plot when no
/// joint torque acted (the run's record says so), no base control plot without its attitude
/// control.
void HtmlWriter::plotsJson(Json& data, const OperationResult& r) {
  if (!series_size_) {  // no sample's series (a capture's instant: before and after at one t): no plots
    data["plots"] = Json::array();
    data["seriesStride"] = 0;
    data["series"] = "";
    return;
  }
  const std::size_t n = times_.size(), stride = data_.size() / n, pose = stride - series_size_;
  const std::vector<std::string>& robot = sc_.capture.robot.model->jointNames();
  const std::size_t nj = robot.size();
  const bool torques = r.record.torques || r.approach;
  std::vector<std::size_t> columns;  // of a frame's series, kept
  Json plots = Json::array();
  const auto plot = [&](const char* name, const char* label, const std::vector<std::string>& series, std::size_t first) {
    plots.push_back({{"name", name}, {"label", label}, {"series", series}, {"column", columns.size()}});
    for (std::size_t k = 0; k < series.size(); ++k) columns.push_back(first + k);
  };
  plot("attitude", "base attitude: roll, pitch, yaw (fixed X-Y-Z) [deg]", {"roll", "pitch", "yaw"}, 0);
  plot("angular rate", "base angular rate (world axes) [deg/s]", {"w_x", "w_y", "w_z"}, 3);
  plot("joint rates", "joint rates [rad/s or m/s]", robot, 6);
  if (torques) plot("joint torques", "joint torques applied (control + friction) [N m or N]", robot, 6 + nj);
  plot("momentum", "momentum: |P| [N s], |L| about the world origin [N m s]", {"|P|", "|L|"}, 6 + 2 * nj);
  plot("energy", "kinetic energy T [J]", {"T"}, 8 + 2 * nj);
  // On its own axes: a balance error is some 1e-12 of T.
  plot("energy balance", "energy balance T - T0 - work [J] (from each phase's start)", {"T - T0 - work"}, 9 + 2 * nj);
  if (sc_.simulation.base_control.attitude.on)
    plot("base control", "base control torque (world axes) [N m]", {"n_x", "n_y", "n_z"}, 10 + 2 * nj);
  std::vector<float> series;
  series.reserve(n * columns.size());
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t c : columns) series.push_back(series_size_ ? data_[k * stride + pose + c] : std::nanf(""));
  for (std::size_t k = 0; k < n; ++k)  // the poses, in place
    std::memmove(&data_[k * pose], &data_[k * stride], pose * sizeof(float));
  data_.resize(n * pose);
  data["plots"] = plots;
  data["seriesStride"] = columns.size();
  data["series"] = base64(series.data(), series.size() * sizeof(float));
}

// --- A free-floating target, the grasp frame, a failed approach's closest distance -------------

void HtmlWriter::pushFloatingTarget(std::vector<float>& f, const OperationResult& so_far, const MotionSample& x,
                                    const Kinematics& kin) {
  const FloatingModel& model = *so_far.model;
  const std::vector<Body>& links = target_model_->bodies();
  if (target_index_for_ != &model) {  // joined to the robot: its links by their (prefixed) names
    target_index_for_ = &model;
    target_index_.assign(links.size(), -1);
    if (so_far.joined)
      for (std::size_t k = 0; k < links.size(); ++k)
        for (std::size_t i = 0; i < model.bodies().size(); ++i)
          if (model.bodies()[i].name == so_far.joined->target_prefix + links[k].name) target_index_[k] = static_cast<int>(i);
  }
  if (so_far.joined) {  // the joined tree keeps each link's frame (joinAtGrasp re-roots, it does not move them)
    for (int i : target_index_)
      if (i >= 0) pushPose(f, kin.pose(i)); else pushHidden(f);
    return;
  }
  // Not part of the system that moves: at the contact instant where the capture problem has it;
  // after a point impact it drifts on by itself (driftingTargetBase).
  // A compliant contact that opened: held where the touch found it during the contact (a few
  // milliseconds), then drifting from where the contact's end left it.
  const auto* other = std::get_if<FloatingSystem>(&so_far.at_contact.target);
  const bool bounced = so_far.compliant && !so_far.joined;
  const auto linkPoses = [&](const FloatingSystem& s, std::vector<KDL::Frame>& poses) {
    Kinematics target_kin(*s.model);
    if (forwardKinematics(*s.model, s.state, target_kin) == E_NOERROR)
      for (std::size_t i = 0; i < links.size(); ++i) poses.push_back(target_kin.pose(static_cast<int>(i)));
  };
  if (target_at_contact_.empty() && other) linkPoses(*other, target_at_contact_);
  if (target_after_contact_.empty() && bounced) linkPoses(so_far.compliant->target_end, target_after_contact_);
  const std::vector<KDL::Frame>& from = bounced ? target_after_contact_ : target_at_contact_;
  const double t_apart = so_far.t_capture + (bounced ? so_far.compliant->duration : 0.0);
  const bool at_contact = x.t <= t_apart && target_at_contact_.size() == links.size();
  const std::optional<KDL::Frame> moved = at_contact ? std::nullopt : driftingTargetBase(so_far, x.t);
  for (std::size_t i = 0; i < links.size(); ++i)
    if (at_contact) pushPose(f, target_at_contact_[i]);
    else if (moved && from.size() == links.size()) pushPose(f, *moved * from[i]);
    else pushHidden(f);
}

/// The operation's result does not carry a separated free-floating target's own motion after a
/// point impact: the page draws it as one rigid body (its joints frozen where the impact found
/// them, rigidSubtree) moving torque-free from its base twist after the impact (FreeRigidMotion:
/// its momentum kept). Returns world_new_T_world_at_contact at time t, or none (not drawn).
std::optional<KDL::Frame> HtmlWriter::driftingTargetBase(const OperationResult& so_far, double t) {
  const auto* other = std::get_if<FloatingSystem>(&so_far.at_contact.target);
  const bool bounced = so_far.compliant && !so_far.joined;  // a compliant contact that opened
  const double t0 = so_far.t_capture + (bounced ? so_far.compliant->duration : 0.0);
  if (!other || so_far.joined || t < t0) return std::nullopt;
  if (!bounced && (!so_far.capture || !so_far.capture->floating_target)) return std::nullopt;
  if (!drift_) {
    try {
      FloatingSystem from = bounced ? so_far.compliant->target_end : *other;
      if (!bounced) from.velocity = so_far.capture->floating_target->after;
      RigidTarget whole = rigidSubtree(*from.model, from.state, 0, from.velocity.base_twist);
      // The frozen body keeps the target's momentum (P; L): its CoM at P / m, turning at
      // I^-1 (L - c x P) (the base's own twist would ignore what the joint rates carry).
      Kinematics kin(*from.model);
      MomentumSolver momentum(from.model);
      if (forwardKinematics(*from.model, from.state, kin) || momentum.compute(kin, from.velocity)) return std::nullopt;
      const Vector6d h = momentum.momentum();
      const RigidBody body = whole.toWorld();
      whole.twist << h.head<3>() / body.mass, body.I_com.ldlt().solve(h.tail<3>() - body.com.cross(h.head<3>()));
      drift_.emplace(whole);
      drift_start_ = whole.pose;
    } catch (const Error&) {
      return std::nullopt;  // no mass to move: not drawn
    }
  }
  RigidTarget now;
  if (drift_->at(t - t0, now) != E_NOERROR) return std::nullopt;
  return now.pose * drift_start_.Inverse();
}

void HtmlWriter::addKept(const OperationResult& so_far, const MotionSample& x) {
  std::vector<float> f = frameOf(so_far, x);
  if (!f.empty()) keep(std::move(f), x);
}

void HtmlWriter::writeTargetAndGrasp(Json& data, const OperationResult& r) const {
  data["targetLinks"] = nullptr;
  if (target_model_) {
    Json links = Json::array();
    for (const Body& b : target_model_->bodies()) {
      Json visuals = Json::array();
      if (const auto it = target_visuals_.find(b.name); it != target_visuals_.end())
        for (const LinkVisual& v : it->second)
          visuals.push_back(v.shape != LinkVisual::Shape::Mesh ? visualJson(v)
                            : v.mesh_path.empty() ? inertiaBoxJson(b)  // warned about
                                                  : meshVisualJson(v, meshIndex(v.mesh_path)));
      if (visuals.empty()) visuals.push_back(inertiaBoxJson(b));
      for (Json& v : visuals)
        if (!v.contains("rgba") || v.value("inertia_box", false)) v["rgba"] = {1.0, 0.5, 0.05, 0.55};  // the target's orange
      links.push_back({{"name", b.name}, {"visuals", visuals}});
    }
    data["targetLinks"] = links;
  }
  if (target_ && data["target"].is_object()) data["target"]["visuals"] = rigidTargetVisualsJson();
  data["targetDrift"] = drift_.has_value();  // drawn after a point impact as a rigid body (driftingTargetBase)
  // The grasp frame rides on the target's frame (a rigid target's, a free-floating one's base).
  data["grasp"] = nullptr;
  if (sc_.grasp_frame && (target_ || target_model_)) data["grasp"] = {{"pose", poseJson(*sc_.grasp_frame)}};
  // A failed approach: how close the hand came to the grasp point, and when.
  data["closest"] = nullptr;
  if (r.approach && !r.approach->record.reached && std::isfinite(r.approach->record.closest_distance))
    data["closest"] = {{"distance", r.approach->record.closest_distance}, {"time", r.approach->record.closest_time}};
  if (r.approach && !r.approach->record.reached) data["tCapture"] = nullptr;  // no contact: no impact to step to
}

// --- The target's URDF visuals (issue 27, item 2) ------------------------------------------------

bool HtmlWriter::drawsTargetVisuals(const Scenario& sc) {
  if (!sc.impact || sc.target_urdf.empty()) return false;
  return sc.rigid_target_system || std::holds_alternative<FloatingSystem>(sc.capture.target);
}

void HtmlWriter::useTargetVisuals(std::map<std::string, std::vector<LinkVisual>> visuals) {
  if (!drawsTargetVisuals(sc_)) return;
  target_visuals_ = std::move(visuals);
  for (auto& [link, list] : target_visuals_)
    for (LinkVisual& v : list) readMesh("target " + link, v);
}

Json HtmlWriter::rigidTargetVisualsJson() const {
  Json out = Json::array();
  if (!sc_.rigid_target_system || target_visuals_.empty()) return out;
  const FloatingSystem& t = *sc_.rigid_target_system;
  const std::vector<Body>& bodies = t.model->bodies();
  Kinematics kin(*t.model);
  if (forwardKinematics(*t.model, t.state, kin) != E_NOERROR) return out;  // the scenario computed it: not here
  // The subtree from the target's body (bodies come parents first), each link in the target's
  // frame at the scenario's state: the visuals then ride on the target's pose per frame.
  const int root = sc_.rigid_target_body;
  std::vector<char> in(bodies.size(), 0);
  in[root] = 1;
  for (std::size_t j = root + 1; j < bodies.size(); ++j) in[j] = bodies[j].parent >= 0 && in[bodies[j].parent];
  bool any = false;
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    if (!in[j]) continue;
    const KDL::Frame target_T_link = kin.pose(root).Inverse() * kin.pose(static_cast<int>(j));
    const auto it = target_visuals_.find(bodies[j].name);
    const std::vector<LinkVisual> none;
    const std::vector<LinkVisual>& list = it != target_visuals_.end() ? it->second : none;
    any = any || !list.empty();
    std::vector<Json> visuals;
    for (const LinkVisual& v : list) {
      Json vj = v.shape != LinkVisual::Shape::Mesh ? visualJson(v)
               : v.mesh_path.empty()               ? inertiaBoxJson(bodies[j])  // warned about
                                                   : meshVisualJson(v, meshIndex(v.mesh_path));
      const bool box = vj.value("inertia_box", false);
      vj["origin"] = poseJson(target_T_link * (box ? equivalentBox(bodies[j].mass, bodies[j].I_com, bodies[j].com).pose : v.origin));
      visuals.push_back(vj);
    }
    if (list.empty() && bodies[j].mass > 0.0) {  // a link with mass but no visual: its box of inertia
      Json vj = inertiaBoxJson(bodies[j]);
      vj["origin"] = poseJson(target_T_link * equivalentBox(bodies[j].mass, bodies[j].I_com, bodies[j].com).pose);
      visuals.push_back(vj);
    }
    for (Json& v : visuals) {
      if (!v.contains("rgba") || v.value("inertia_box", false)) v["rgba"] = {1.0, 0.5, 0.05, 0.55};  // the target's orange
      v["link"] = bodies[j].name;
      out.push_back(v);
    }
  }
  return any ? out : Json::array();
}

std::vector<Diagnostic> writeCaptureHtml(const AtomicFile& file, const Scenario& sc, const CaptureResult& result,
                                         const std::string& title, const std::vector<std::string>& mesh_search_path) {
  OperationResult instant;  // the capture at the scenario's states, as the operation would have it at t = 0
  instant.at_contact = sc.capture;
  instant.capture = result;
  instant.model = sc.capture.robot.model;
  MotionSample x;
  const State& s = sc.capture.robot.state;
  x.p = toEigen(s.world_T_base.p);
  s.world_T_base.M.GetQuaternion(x.quat(0), x.quat(1), x.quat(2), x.quat(3));
  x.q = s.q.data;
  HtmlWriter writer(sc, mesh_search_path);
  OperationResult before = instant;  // the first frame: before the impact
  before.capture.reset();
  x.phase = Phase::Capture;
  writer.addKept(before, x);
  x.phase = Phase::Post;
  writer.addKept(instant, x);
  writer.write(file, instant, title);
  return writer.warnings();
}

}  // namespace kdl_space::cli
