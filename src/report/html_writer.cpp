#include "kdl_space/report/html_writer.hpp"

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

#include "kdl_space/report/capture_report.hpp"
#include "kdl_space/report/inspection_json.hpp"
#include "report/viewer_page.hpp"  // generated from src/report/viewer/ (cmake/embed_viewer.cmake)
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/report/scene_writer.hpp"
#include "report/page_parts.hpp"

namespace kdl_space::report {

using namespace page;

namespace {

std::string readText(const std::string& path, const std::string& where) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().empty())
    throw InputError(where + "cannot read " + path + " (Debian package libjs-three; tools/deps.sh installs it)");
  return text.str();
}

// --- meshes (STL, COLLADA) --------------------------------------------------------------------

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

namespace {
/// The visuals a page of `sc` draws, for a run that has not read them: the target's only when the
/// page draws them (HtmlWriter::drawsTargetVisuals).
PageVisuals visualsToDraw(const Scenario& sc, const std::vector<std::string>& mesh_search_path, bool target) {
  PageVisuals visuals;
  visuals.robot = robotVisuals(sc, mesh_search_path);
  if (target) visuals.target = targetVisuals(sc, mesh_search_path);
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

void HtmlWriter::addKept(const OperationResult& so_far, const MotionSample& x) {
  std::vector<float> f = frameOf(so_far, x);
  if (!f.empty()) keep(std::move(f), x);
}

// --- The target's URDF visuals (issue 27, item 2) ------------------------------------------------

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

}  // namespace kdl_space::report
