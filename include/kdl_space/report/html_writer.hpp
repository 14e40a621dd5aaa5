// The capture as an interactive 3-D animation (`kdl_space simulate --html FILE`): one
// self-contained HTML page (three.js inlined from Debian's libjs-three; no server, no network)
// with the robot's URDF visuals posed per frame, the target, the base frame, the contact point,
// the hand's path, the impulse as an arrow, and a time line with the phases. The run's samples
// are decimated to a display rate as they come: the memory held is the frames kept (at most
// max_frames), not the run.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/report/json.hpp"
#include "kdl_space/parsers/output_file.hpp"
#include "kdl_space/operation/capture_operation.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/parsers/urdf/urdf_visuals.hpp"
#include "kdl_space/simulation/rigid_motion.hpp"

namespace kdl_space::report {

/// Where the page's 3-D library comes from (Debian's libjs-three).
inline const char* const kThreeJs = "/usr/share/javascript/three/three.min.js";
inline const char* const kOrbitControlsJs = "/usr/share/javascript/three/examples/js/controls/OrbitControls.js";
/// three.js's own mesh loaders (r111, non-module: they define THREE.STLLoader and
/// THREE.ColladaLoader), inlined only into a page that has such a mesh.
inline const char* const kStlLoaderJs = "/usr/share/javascript/three/examples/js/loaders/STLLoader.js";
inline const char* const kColladaLoaderJs = "/usr/share/javascript/three/examples/js/loaders/ColladaLoader.js";

/// \brief The folders package:// meshes are searched in, in order: `mesh_path_options` (the
/// --mesh-path folders), then the ROS_PACKAGE_PATH environment variable's (colon-separated). The
/// tool reads the environment; the library is given the list (resolveMeshFile).
std::vector<std::string> meshSearchPath(const std::vector<std::string>& mesh_path_options);

/// \brief The URDF visuals a page of a scenario draws, read once per run (readUrdfVisuals) and
/// handed to meshInputs and HtmlWriter: the robot's, and the target's when the scenario names
/// its URDF (the page draws them for a rigid target read from a URDF or a free-floating one).
struct PageVisuals {
  std::map<std::string, std::vector<LinkVisual>> robot, target;
};
/// Reads `sc`'s URDFs' visuals, their meshes resolved through `mesh_search_path` (meshSearchPath).
PageVisuals readPageVisuals(const Scenario& sc, const std::vector<std::string>& mesh_search_path);
/// The mesh files of `visuals` (read by readPageVisuals): as meshInputs below, without reading again.
std::vector<InputFile> meshInputs(const PageVisuals& visuals);

/// \brief The mesh files a page of `sc` embeds (issue 25's rule: no output replaces what the run
/// reads): every mesh visual of the robot's URDF and, when the scenario names one, the target's,
/// resolved through `mesh_search_path` as HtmlWriter resolves them (a mesh not found is not read,
/// so not listed; one of a format the page does not draw is listed all the same: the URDF names
/// it as the link's shape). Each is named "the mesh FILE of link L" ("of the target's link L"), FILE as
/// the URDF writes it. Given to refuseOverwritingInputs with every output of a run that has --html.
std::vector<InputFile> meshInputs(const Scenario& sc, const std::vector<std::string>& mesh_search_path);

/// Throws InputError naming `option` and `path` when three.js is not installed.
void checkHtmlLibrary(const std::string& option, const std::string& path);

class HtmlWriter {
 public:
  /// Reads the robot's visuals and their STL and COLLADA meshes, found through
  /// `mesh_search_path` (meshSearchPath); a mesh that cannot be drawn (not found, unreadable,
  /// another format) is its link's box of inertia, with a warning on stderr naming the link, the
  /// file and what to do (warnings() keeps them for the JSON). `frames_per_second`: the display rate.
  explicit HtmlWriter(const Scenario& sc, const std::vector<std::string>& mesh_search_path = {},
                      double frames_per_second = 30.0, std::size_t max_frames = 3000);
  /// The same from the visuals read already for the run (readPageVisuals): no URDF read again.
  HtmlWriter(const Scenario& sc, PageVisuals visuals, double frames_per_second = 30.0, std::size_t max_frames = 3000);
  /// One sample of the run; `so_far.model` is the system it belongs to.
  void add(const OperationResult& so_far, const MotionSample& x);
  /// One sample kept whatever the display rate (a capture's instant: before and after at one time).
  void addKept(const OperationResult& so_far, const MotionSample& x);
  /// Writes the page into file.tmp() (the caller commits it). `note`: shown over the view (e.g.
  /// "the approach did not reach its grasp").
  void write(const AtomicFile& file, const OperationResult& r, const std::string& title, const std::string& note = "");
  std::size_t frames() const { return times_.size(); }
  /// The meshes drawn as boxes of inertia (printed on stderr already; for the run's JSON).
  const std::vector<Diagnostic>& warnings() const { return warnings_; }

 private:
  struct Frame;
  std::vector<float> frameOf(const OperationResult& so_far, const MotionSample& x);
  void keep(std::vector<float> frame, const MotionSample& x);
  // --- the linked plots (issue 27, item 3): their values ride at the end of each frame (kept
  // and decimated with it) and are split off into `series` when the page is written.
  void appendSeries(std::vector<float>& f, const OperationResult& so_far, const MotionSample& x);
  void plotsJson(Json& data, const OperationResult& r);

  const Scenario& sc_;
  double step_;          ///< the display interval [s], doubled when max_frames is passed
  std::size_t max_frames_;
  std::vector<std::string> links_;  ///< the robot's bodies, by name
  std::map<std::string, std::vector<LinkVisual>> visuals_;
  /// The meshes the page embeds, each file once ({file, format, data}); a mesh visual's
  /// LinkVisual::mesh_path is cleared when it is not drawn.
  struct MeshData {
    std::string path, format, bytes;
  };
  std::vector<MeshData> meshes_;
  std::vector<Diagnostic> warnings_;
  void readMeshes();
  void readMesh(const std::string& link, LinkVisual& v);
  int meshIndex(const std::string& path) const;
  std::optional<RigidTarget> target_;     ///< a rigid target at t = 0
  std::optional<FreeRigidMotion> tumble_;  ///< its motion before the capture
  std::optional<FreeRigidMotion> after_;   ///< a separated target's motion after it
  std::optional<KDL::Frame> hand_T_target_;  ///< a target held by the hand
  const FloatingModel* model_ = nullptr;  ///< the system the index below is for
  std::vector<int> index_;                ///< robot link -> body in model_ (-1: none)
  int target_body_ = -1;                  ///< a joined target's body in model_
  std::vector<float> data_;     ///< the frames kept, one after the other
  std::vector<double> times_;
  std::vector<int> phases_;
  double next_t_ = -1e300;
  std::vector<float> last_;     ///< the latest sample's frame (the run's end), if not kept
  double last_t_ = 0.0;
  int last_phase_ = 0;
  // The plots' series (appendSeries): where they begin in a frame, the joints' columns in the
  // samples' model (by the robot's joint names), the energy balance's start.
  std::size_t series_at_ = 0, series_size_ = 0;
  const FloatingModel* series_model_ = nullptr;
  std::vector<int> series_joints_;
  bool series_phase0_ = false;
  Phase series_phase_ = Phase::Post;
  double series_T0_ = 0.0;

  // --- A free-floating target (its links posed per frame) and the grasp frame ----------------
  /// Appends a free-floating target's link poses to frame `f` (7 floats a link; NaN: not drawn).
  void pushFloatingTarget(std::vector<float>& f, const OperationResult& so_far, const MotionSample& x,
                          const Kinematics& kin);
  /// The target's links and the grasp frame (`data`'s "targetLinks", "grasp", "closest").
  void writeTargetAndGrasp(Json& data, const OperationResult& r) const;
  std::shared_ptr<const FloatingModel> target_model_;  ///< a free-floating target's model, or none
  std::map<std::string, std::vector<LinkVisual>> target_visuals_;  ///< of its URDF (target.urdf)
  std::vector<KDL::Frame> target_at_contact_;  ///< its links (world) at the contact instant
  /// A compliant contact that opened: its links (world) at the contact's end, where it drifts from.
  std::vector<KDL::Frame> target_after_contact_;
  std::vector<int> target_index_;              ///< its link -> body in model_ when joined (-1: none)
  const FloatingModel* target_index_for_ = nullptr;  ///< the system target_index_ is for

  // --- The target's URDF visuals (a rigid target read from a URDF, a free-floating target) -----
  /// Whether the page draws the target's URDF visuals: a rigid target read from a URDF, or a
  /// free-floating target, captured.
  static bool drawsTargetVisuals(const Scenario& sc);
  /// Keeps target_urdf's visuals (read by readPageVisuals) when the page draws them, and reads
  /// their meshes into meshes_ as the robot's (warnings name the link as "target LINK").
  void useTargetVisuals(std::map<std::string, std::vector<LinkVisual>> visuals);
  /// A rigid target read from a URDF: its subtree's links' visuals in the target's frame (a link
  /// without one: its box of inertia); empty when no link of it has a visual (the page then draws
  /// the target's box of inertia).
  Json rigidTargetVisualsJson() const;
  /// A free-floating target separated by a point impact (or a compliant contact that opened: from
  /// the contact's end), drifting as one rigid body with its momentum (c).
  std::optional<KDL::Frame> driftingTargetBase(const OperationResult& so_far, double t);
  std::optional<FreeRigidMotion> drift_;
  KDL::Frame drift_start_;
};

/// \brief The page of a capture at the scenario's states (`kdl_space capture --html`, Python's
/// CaptureResult.to_html): the instant as two frames at t = 0, before and after the impact (the
/// configuration does not change at an impact; the impulse's arrow shows from the first).
/// Writes into file.tmp() (the caller commits it).
/// `mesh_search_path`: where package:// meshes are found (meshSearchPath), as for HtmlWriter;
/// returns its warnings (the meshes drawn as boxes, on stderr already) for a run's JSON.
std::vector<Diagnostic> writeCaptureHtml(const AtomicFile& file, const Scenario& scenario, const CaptureResult& result,
                      const std::string& title, const std::vector<std::string>& mesh_search_path = {});

}  // namespace kdl_space::report
