// Real robots load as their authors wrote them (issue 12): a corpus of URDF files written the way
// public robot descriptions are (tests/data/real_patterns/, one pattern per file, each file's
// header says which), loaded or refused as documented:
//  - each file loads, or is refused with the expected error kind and words, by the loader and
//    the checker alike;
//  - the warnings are the expected kinds, the same from the loader (model.diagnostics()) and the
//    checker (checkUrdfFile(...).warnings): one set of rules; notes are not warnings;
//  - G* at contact links, from RecursiveExIITSolver and FreeFloatingSolver, equals the independent
//    KDL six-virtual-joint route (virtual_joint_route.hpp) and the twin file's (the same robot
//    written the unremarkable way) at random configurations;
//  - over every file that loads and over random trees with massless roots and point masses, the
//    compute calls return 0 and their results are finite;
//  - files as written (issue 28): zero mass with a rotational inertia (on the base, on fixed
//    frames, on fingers), tiny fixed links whose inertias fail alone while their rigid body
//    passes: they load with warnings, and their dynamics (H*, G*, KDL's full mass matrix) equal
//    those of twins written by hand to 1e-12; a massless base loads when its links supply the mass
//    (KDL's mass matrix positive definite), and singular systems are refused by loader and checker
//    alike with the rule's kind.
//
// Tolerances: G* 1e-9 relative to its norm (the routes sum in different orders); the massless
// world root against its twin 1e-12 (the composite base is the same rigid body, only re-expressed).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "random_tree.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

constexpr double kRel = 1e-9;
constexpr int kStates = 3;           ///< random configurations per G* comparison
constexpr int kPropertyStates = 20;  ///< random configurations and velocities per property test

std::string corpus(const std::string& file) { return dataDir() + "/real_patterns/" + file; }

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// ||a - b|| <= rel ||b|| (Frobenius), with the worst element in the message.
::testing::AssertionResult closeInNorm(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double rel,
                                       const std::string& what) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return near(a, b, 0.0, 0.0, what);
  const double error = (a - b).norm(), bound = rel * b.norm();
  if (error <= bound) return ::testing::AssertionSuccess();
  Eigen::Index i = 0, j = 0;
  (a - b).cwiseAbs().maxCoeff(&i, &j);
  return ::testing::AssertionFailure() << what << ": ||a - b|| = " << error << " > " << bound << " (" << rel
                                       << " ||b||); worst element (" << i << "," << j << "): " << a(i, j)
                                       << " vs " << b(i, j);
}

// --- Findings ----------------------------------------------------------------------------------

std::set<std::string> kinds(const std::vector<Finding>& findings) {
  std::set<std::string> out;
  for (const Finding& f : findings) out.insert(f.kind);
  return out;
}

std::vector<Diagnostic> modelWarnings(const FloatingModel& model) {
  std::vector<Diagnostic> out;
  for (const Diagnostic& d : model.diagnostics())
    if (d.severity == Severity::Warning) out.push_back(d);
  return out;
}

std::set<std::string> kinds(const std::vector<Diagnostic>& diagnostics) {
  std::set<std::string> out;
  for (const Diagnostic& d : diagnostics) out.insert(d.kind);
  return out;
}

std::string listed(const std::vector<Finding>& findings) {
  std::string out;
  for (const Finding& f : findings) out += "\n  " + f.kind + " [" + f.element + "] " + f.message;
  return out;
}

std::string listed(const std::vector<Diagnostic>& diagnostics) {
  std::string out;
  for (const Diagnostic& d : diagnostics) out += "\n  " + d.kind + " [" + d.element + "] " + d.message;
  return out;
}

// --- The corpus --------------------------------------------------------------------------------

/// A corpus file that loads.
struct LoadCase {
  std::string file;
  /// Expected warning kinds, each with the links or joints it must name (as the finding's
  /// element or in its message).
  std::map<std::string, std::vector<std::string>> warnings;
  std::vector<std::string> tips;           ///< contact links for G*
  std::vector<std::string> fixed_joints;   ///< movable joints the model treats as fixed
  std::string twin;                        ///< twin file ("" none; "*" built by the test)
  double twin_rel = kRel;                  ///< G* against the twin, relative to its norm
};

std::ostream& operator<<(std::ostream& os, const LoadCase& c) { return os << c.file; }
inline void PrintTo(const LoadCase& c, std::ostream* os) { *os << c.file; }

std::vector<LoadCase> loadCases() {
  return {
      {"massless_world_root.urdf", {}, {"tool0", "ee_link", "forearm_link", "base_link", "world"}, {},
       "massless_world_root_twin.urdf", 1e-12},
      {"massless_world_root_twin.urdf", {}, {"tool0", "base"}, {}, ""},
      {"point_masses.urdf",
       {{"point_mass", {"solar_wing_left", "solar_wing_right", "ft_sensor_link", "wrist_camera_link"}}},
       {"tool_flange", "wrist_camera_optical_frame", "ft_sensor_link", "solar_wing_left"}, {}, ""},
      {"inertia_round_off.urdf", {{"inertia_round_off", {"antenna_whip", "latch_pin"}}},
       {"grasp_point", "latch_pin", "link_2", "antenna_whip"}, {}, "*"},
      {"triangle_violation.urdf", {{"triangle_inequality", {"Link2", "Link6"}}}, {"EndEffector", "Link3"}, {}, ""},
      // The right finger's <mimic> is no warning, here or in the twin: that joint is no coordinate
      // (treated as fixed here, written fixed in the twin), and `mimic_ignored` ("it is an
      // independent coordinate") would say the opposite of `joint_moves_no_mass`.
      {"massless_finger_joint.urdf",
       {{"joint_moves_no_mass", {"gripper_left_finger_joint", "gripper_right_finger_joint"}}},
       {"gripper_palm", "gripper_left_finger_tip", "arm_proximal_link"},
       {"gripper_left_finger_joint", "gripper_right_finger_joint"}, "massless_finger_joint_twin.urdf"},
      {"massless_finger_joint_twin.urdf", {}, {"gripper_palm"}, {}, ""},
      {"revolute_without_limit.urdf", {{"revolute_without_limit", {"Joint_1", "Joint_2", "Joint_3", "Joint_4"}}},
       {"End_Effector", "Link_2"}, {}, "revolute_without_limit_twin.urdf"},
      {"revolute_without_limit_twin.urdf", {}, {"End_Effector"}, {}, ""},
      {"xacro_output_with_comments.urdf", {}, {"tool", "shoulder_yaw"}, {}, ""},
      // Zero mass with a rotational inertia, read as written (issue 28): on the free-floating base
      // (the arm supplies the mass), on fixed sensor frames, on fingers with revolute joints (which
      // stay coordinates). Twins written by hand: G* equal to round-off.
      {"zero_mass_base_inertia.urdf", {{"inertia_without_mass", {"body"}}}, {"tool", "arm_upper", "body"}, {},
       "zero_mass_base_inertia_twin.urdf", 1e-12},
      {"zero_mass_base_inertia_twin.urdf", {{"inertia_without_mass", {"body"}}}, {"tool"}, {}, ""},
      {"zero_mass_inertia_frames.urdf", {{"inertia_without_mass", {"camera_link", "ft_sensor_link"}}},
       {"ft_sensor_link", "camera_link", "upper_arm", "bus"}, {}, "zero_mass_inertia_frames_twin.urdf", 1e-12},
      {"zero_mass_inertia_frames_twin.urdf", {}, {"ft_sensor_link"}, {}, ""},
      {"zero_mass_inertia_fingers.urdf", {{"inertia_without_mass", {"left_finger", "right_finger"}}},
       {"left_finger", "right_finger", "palm"}, {}, ""},
      // Tiny fixed links whose inertias fail alone; the hand's rigid body is positive definite.
      {"tiny_fixed_links_not_positive_definite.urdf",
       {{"link_inertia_not_positive_definite", {"imu_link", "tool_tip", "hand"}}},
       {"tool_tip", "imu_link", "hand", "arm"}, {}, "tiny_fixed_links_not_positive_definite_twin.urdf", 1e-12},
      {"tiny_fixed_links_not_positive_definite_twin.urdf", {}, {"tool_tip"}, {}, ""},
      {"humanoid44.urdf", {},
       {"left_hand_index_finger_tip", "right_hand_thumb_tip", "right_leg_sole", "head_left_camera_optical_frame",
        "left_arm_wrist_ft_sensor_frame", "pelvis"},
       {}, ""},
  };
}

/// A corpus file that is refused.
struct RefusedCase {
  std::string file;
  std::string kind;                  ///< the checker's error kind
  std::vector<std::string> words;    ///< parts of the message
};

std::ostream& operator<<(std::ostream& os, const RefusedCase& c) { return os << c.file; }
inline void PrintTo(const RefusedCase& c, std::ostream* os) { *os << c.file; }

std::vector<RefusedCase> refusedCases() {
  return {
      {"unexpanded.urdf.xacro", "xacro", {"xacro", ".urdf"}},
      // A massless base whose one joint can turn it without moving any mass: singular.
      {"massless_base_composite.urdf", "base_without_mass",
       {"world", "mount", "flange", "singular", "base_yaw", "<inertial>"}},
  };
}

/// The inertia_round_off.urdf twin: every <inertia> replaced by its positive-semidefinite
/// projection (negative principal moments set to 0), written with 17 significant digits.
std::string positiveSemidefiniteTwin(const std::string& xml) {
  const std::regex inertia(R"re(<inertia\s+ixx="([^"]*)"\s+ixy="([^"]*)"\s+ixz="([^"]*)"\s+)re"
                           R"re(iyy="([^"]*)"\s+iyz="([^"]*)"\s+izz="([^"]*)"\s*/>)re");
  std::string out;
  std::size_t last = 0;
  int projected = 0;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), inertia); it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    const double ixx = std::stod(m[1]), ixy = std::stod(m[2]), ixz = std::stod(m[3]), iyy = std::stod(m[4]),
                 iyz = std::stod(m[5]), izz = std::stod(m[6]);
    Eigen::Matrix3d I;
    I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
    out += xml.substr(last, m.position(0) - last);
    last = m.position(0) + m.length(0);
    if (eig.eigenvalues().minCoeff() >= 0.0) {
      out += m.str(0);
      continue;
    }
    ++projected;
    const Eigen::Matrix3d P =
        eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
    char buffer[400];
    std::snprintf(buffer, sizeof buffer,
                  R"(<inertia ixx="%.17g" ixy="%.17g" ixz="%.17g" iyy="%.17g" iyz="%.17g" izz="%.17g"/>)",
                  P(0, 0), 0.5 * (P(0, 1) + P(1, 0)), 0.5 * (P(0, 2) + P(2, 0)), P(1, 1), 0.5 * (P(1, 2) + P(2, 1)),
                  P(2, 2));
    out += buffer;
  }
  EXPECT_EQ(projected, 2) << "inertia_round_off.urdf: two inertias with a negative principal moment";
  return out + xml.substr(last);
}

/// The twin of a case as a model, and the name it goes by.
std::shared_ptr<const FloatingModel> loadTwin(const LoadCase& c) {
  if (c.twin == "*") {
    const std::string xml = positiveSemidefiniteTwin(readFile(corpus(c.file)));
    return std::make_shared<const FloatingModel>(loadUrdfString(xml, c.file + " (positive-semidefinite twin)"));
  }
  return std::make_shared<const FloatingModel>(loadUrdfFile(corpus(c.twin)));
}

// --- The independent route ---------------------------------------------------------------------

/// \brief The independent route (virtual_joint_route.hpp) for one model, at one state at a time,
/// by link name. The route reads the model's KDL tree; what it cannot take as it is is handed to
/// it rewritten as the same robot: joints the model does not move but its tree still does (fixed
/// at 0). (A base link named "world" needs nothing: the route's root has a name of its own.)
class Route {
 public:
  explicit Route(const std::shared_ptr<const FloatingModel>& model) : model_(model), route_model_(model) {
    KDL::Tree tree = model->tree();
    bool rewritten = false;
    if (tree.getNrOfJoints() != model->nj()) {
      std::map<std::string, double> at_zero;
      for (const FixedJoint& f : model->fixedJoints()) at_zero[f.joint] = 0.0;
      tree = lockJoints(tree, at_zero);
      rewritten = true;
    }
    if (rewritten) route_model_ = std::make_shared<const FloatingModel>(tree, baseInertia(*model));
    std::vector<std::string> a = route_model_->jointNames(), b = model->jointNames();
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b) << "the route's model moves other joints";
  }

  /// The state of the model (its joint order) the route is evaluated at.
  void at(const State& state) {
    State s(*route_model_);
    s.world_T_base = state.world_T_base;
    for (unsigned int j = 0; j < route_model_->nj(); ++j)
      s.q(j) = state.q(model_->jointIndex(route_model_->jointNames()[j]));
    tree_ = std::make_unique<VirtualJointTree>(*route_model_, s);
  }
  Eigen::MatrixXd G(const LinkPoint& p) const { return tree_->G(p); }
  KDL::Frame pose(const std::string& name) const { return tree_->pose(name); }

 private:

  std::shared_ptr<const FloatingModel> model_, route_model_;
  std::unique_ptr<VirtualJointTree> tree_;
};

/// G* of the model at `point` from both library solvers (checked against each other).
Eigen::MatrixXd libraryGStar(RecursiveExIITSolver& recursive, FreeFloatingSolver& dense, const FloatingModel& model,
                             const LinkPoint& point) {
  const Contact h = model.contact(point.link, point.offset);
  Matrix6d G_rec, G_dense;
  EXPECT_EQ(recursive.G_star(h, G_rec), E_NOERROR) << point.link;
  EXPECT_EQ(dense.G_star(h, G_dense), E_NOERROR) << point.link;
  EXPECT_TRUE(closeInNorm(G_dense, G_rec, kRel, "dense G* vs recursive G* at " + point.link));
  return G_rec;
}

/// The twin's state for the same configuration: the same world pose of the twin's root link
/// (taken from the route's KDL forward kinematics) and the same joint positions by name.
State twinState(const FloatingModel& model, const State& state, const Route& route, const FloatingModel& twin) {
  State s(twin);
  s.world_T_base = route.pose(twin.bodies()[0].name);
  for (unsigned int j = 0; j < twin.nj(); ++j) {
    const int k = model.jointIndex(twin.jointNames()[j]);
    EXPECT_GE(k, 0) << "twin joint " << twin.jointNames()[j] << " is not a joint of the model";
    if (k >= 0) s.q(j) = state.q(k);
  }
  return s;
}

// --- Files that load ---------------------------------------------------------------------------

class RealPatternLoads : public ::testing::TestWithParam<LoadCase> {};

TEST_P(RealPatternLoads, WarningsAreTheExpectedOnesFromLoaderAndChecker) {
  const LoadCase& c = GetParam();
  const std::string path = corpus(c.file);
  std::unique_ptr<FloatingModel> model;
  try {
    model = std::make_unique<FloatingModel>(loadUrdfFile(path));
  } catch (const ModelError& e) {
    FAIL() << "refused: " << e.what();
  }
  const UrdfReport report = checkUrdfFile(path, c.tips);
  EXPECT_TRUE(report.errors.empty()) << listed(report.errors);
  EXPECT_TRUE(report.model.loaded);

  std::set<std::string> expected;
  for (const auto& [kind, names] : c.warnings) expected.insert(kind);
  const std::vector<Diagnostic> loader = modelWarnings(*model);
  EXPECT_EQ(kinds(loader), expected) << "loader:" << listed(loader);
  EXPECT_EQ(kinds(report.warnings), expected) << "checker:" << listed(report.warnings);

  // One set of rules: every warning of the checker is one of the loader's, in the same words.
  for (const Finding& f : report.warnings) {
    EXPECT_EQ(f.severity, Severity::Warning) << f.kind;
    const bool found = std::any_of(loader.begin(), loader.end(), [&](const Diagnostic& d) {
      return d.kind == f.kind && d.element == f.element && d.message == f.message;
    });
    EXPECT_TRUE(found) << "checker warning not among the loader's: " << f.kind << " [" << f.element << "] "
                       << f.message << "\nloader:" << listed(loader);
  }
  EXPECT_EQ(loader.size(), report.warnings.size())
      << "loader:" << listed(loader) << "\nchecker:" << listed(report.warnings);
  for (const Finding& f : report.notes) EXPECT_EQ(f.severity, Severity::Note) << f.kind << " " << f.element;
  for (const Diagnostic& d : model->diagnostics())
    EXPECT_TRUE(d.severity == Severity::Warning || d.severity == Severity::Note) << d.kind;

  // Each expected warning names its links or joints.
  for (const auto& [expected_kind, names] : c.warnings)
    for (const std::string& name : names) {
      const std::string& kind = expected_kind;  // a lambda captures no structured binding before C++20 (clang)
      const bool named = std::any_of(report.warnings.begin(), report.warnings.end(), [&](const Finding& f) {
        return f.kind == kind && (f.element == name || f.message.find(name) != std::string::npos);
      });
      EXPECT_TRUE(named) << kind << " does not name " << name << ":" << listed(report.warnings);
    }

  // Movable joints treated as fixed: exactly the expected ones, each with its reason.
  std::vector<std::string> fixed;
  for (const FixedJoint& f : model->fixedJoints()) {
    fixed.push_back(f.joint);
    EXPECT_FALSE(f.reason.empty()) << f.joint;
    EXPECT_LT(model->jointIndex(f.joint), 0) << f.joint << " is treated as fixed and still a coordinate";
  }
  std::vector<std::string> expected_fixed = c.fixed_joints;
  std::sort(fixed.begin(), fixed.end());
  std::sort(expected_fixed.begin(), expected_fixed.end());
  EXPECT_EQ(fixed, expected_fixed);

  // Every link is a body, a contact link (links on fixed joints stay bodies).
  EXPECT_EQ(static_cast<int>(model->bodies().size()), report.model.links);
  for (const std::string& tip : c.tips) EXPECT_GE(model->bodyIndex(tip), 0) << tip;
}

TEST_P(RealPatternLoads, GStarAgreesWithTheVirtualJointRouteAndTheTwin) {
  const LoadCase& c = GetParam();
  std::shared_ptr<const FloatingModel> model, twin;
  try {
    model = std::make_shared<const FloatingModel>(loadUrdfFile(corpus(c.file)));
    if (!c.twin.empty()) twin = loadTwin(c);
  } catch (const ModelError& e) {
    FAIL() << "refused: " << e.what();
  }
  Route route(model);
  if (twin) EXPECT_EQ(model->jointNames(), twin->jointNames());

  RecursiveExIITSolver recursive(model);
  FreeFloatingSolver dense(model);
  std::unique_ptr<RecursiveExIITSolver> twin_recursive;
  std::unique_ptr<FreeFloatingSolver> twin_dense;
  if (twin) {
    twin_recursive = std::make_unique<RecursiveExIITSolver>(twin);
    twin_dense = std::make_unique<FreeFloatingSolver>(twin);
  }
  std::mt19937 rng(1200 + static_cast<unsigned>(c.file.size()));
  std::uniform_real_distribution<double> off(-0.1, 0.1);
  for (int s = 0; s < kStates; ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    const State state = randomState(*model, rng);
    ASSERT_EQ(recursive.compute(state), E_NOERROR);
    ASSERT_EQ(dense.compute(state), E_NOERROR);
    route.at(state);
    State twin_state;
    if (twin) {
      twin_state = twinState(*model, state, route, *twin);
      ASSERT_EQ(twin_recursive->compute(twin_state), E_NOERROR);
      ASSERT_EQ(twin_dense->compute(twin_state), E_NOERROR);
    }
    for (const std::string& tip : c.tips)
      for (const KDL::Vector& offset : {KDL::Vector::Zero(), KDL::Vector(off(rng), off(rng), off(rng))}) {
        const LinkPoint point{tip, offset};
        SCOPED_TRACE("contact " + tip);
        const Eigen::MatrixXd G = libraryGStar(recursive, dense, *model, point);
        EXPECT_TRUE(closeInNorm(G, route.G(point), kRel, "G* vs the virtual-joint route"));
        if (twin && twin->bodyIndex(tip) >= 0)
          EXPECT_TRUE(closeInNorm(G, libraryGStar(*twin_recursive, *twin_dense, *twin, point), c.twin_rel,
                                  "G* vs the twin's"));
      }
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, RealPatternLoads, ::testing::ValuesIn(loadCases()),
                         [](const ::testing::TestParamInfo<LoadCase>& info) {
                           std::string name = info.param.file.substr(0, info.param.file.find('.'));
                           return name;
                         });

TEST(RealPatterns, CleanModelsHaveNoWarnings) {
  for (const std::string file : {"massless_world_root.urdf", "massless_world_root_twin.urdf", "humanoid44.urdf",
                                 "xacro_output_with_comments.urdf"}) {
    try {
      const FloatingModel model = loadUrdfFile(corpus(file));
      EXPECT_TRUE(modelWarnings(model).empty()) << file << ":" << listed(modelWarnings(model));
    } catch (const ModelError& e) {
      ADD_FAILURE() << "refused: " << e.what();
    }
    EXPECT_TRUE(checkUrdfFile(corpus(file)).warnings.empty()) << file;
  }
}

TEST(RealPatterns, MasslessWorldRootIsTheBaseAndItsCompositeCarriesTheMass) {
  const FloatingModel model = loadUrdfFile(corpus("massless_world_root.urdf"));
  const FloatingModel twin = loadUrdfFile(corpus("massless_world_root_twin.urdf"));
  EXPECT_EQ(model.bodies()[0].name, "world");
  EXPECT_EQ(twin.bodies()[0].name, "base_link");
  EXPECT_EQ(model.nj(), 6u);
  EXPECT_EQ(model.jointNames(), twin.jointNames());
  EXPECT_NEAR(model.totalMass(), twin.totalMass(), 1e-12 * twin.totalMass());
  EXPECT_NEAR(model.totalMass(), 4.0 + 3.7 + 8.393 + 2.275 + 1.219 + 1.219 + 0.1879, 1e-12);
  const UrdfReport report = checkUrdfFile(corpus("massless_world_root.urdf"));
  EXPECT_EQ(report.model.base, "world");
  EXPECT_EQ(report.model.joint_names, model.jointNames());
}

TEST(RealPatterns, HumanoidIsALargeTree) {
  const FloatingModel model = loadUrdfFile(corpus("humanoid44.urdf"));
  EXPECT_GE(model.nj(), 44u);
  EXPECT_EQ(model.bodies()[0].name, "torso");
  EXPECT_DOUBLE_EQ(model.bodies()[0].mass, 30.0);
  EXPECT_GE(model.bodyIndex("left_hand_little_finger_tip"), 0);
}

// --- Files that are refused --------------------------------------------------------------------

class RealPatternRefused : public ::testing::TestWithParam<RefusedCase> {};

TEST_P(RealPatternRefused, LoaderAndCheckerRefuseWithTheExpectedWords) {
  const RefusedCase& c = GetParam();
  const std::string path = corpus(c.file);
  const UrdfReport report = checkUrdfFile(path);
  EXPECT_FALSE(report.model.loaded);
  ASSERT_FALSE(report.errors.empty());
  EXPECT_EQ(report.errors[0].kind, c.kind) << listed(report.errors);
  for (const std::string& word : c.words)
    EXPECT_NE(report.errors[0].message.find(word), std::string::npos)
        << "'" << word << "' not in: " << report.errors[0].message;
  try {
    loadUrdfFile(path);
    ADD_FAILURE() << path << " was loaded";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_EQ(what, path + ": " + describe(report.errors[0]));
    for (const std::string& word : c.words)
      EXPECT_NE(what.find(word), std::string::npos) << "'" << word << "' not in: " << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, RealPatternRefused, ::testing::ValuesIn(refusedCases()),
                         [](const ::testing::TestParamInfo<RefusedCase>& info) {
                           return info.param.file.substr(0, info.param.file.find('.'));
                         });

TEST(RealPatterns, XacroMessageSaysToRunXacro) {
  const std::string path = corpus("unexpanded.urdf.xacro");
  const UrdfReport report = checkUrdfFile(path);
  ASSERT_FALSE(report.errors.empty());
  EXPECT_NE(report.errors[0].message.find("xacro "), std::string::npos) << report.errors[0].message;
  EXPECT_NE(report.errors[0].message.find(" > "), std::string::npos) << report.errors[0].message;
}

// --- Zero mass, massless bases, rigid bodies (issue 28) -------------------------------------------

/// `xml` with `from` replaced by `to` (once; the test fails when `from` is not there).
std::string edited(std::string xml, const std::string& from, const std::string& to) {
  const std::size_t at = xml.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? xml : xml.replace(at, from.size(), to);
}

/// ||a - b|| <= rel ||b|| for H* and M (the full mass matrix), both routes' by KDL.
TEST(RealPatterns, TwinsWrittenByHandHaveTheSameDynamics) {
  // The files' twins are the same robots written otherwise by hand (inertias moved and rotated,
  // rigid bodies merged outside kdl_space): the full mass matrix from KDL's own dynamics (the
  // virtual-joint route) and H* from the library equal the twin's to round-off.
  for (const std::string file : {"zero_mass_base_inertia.urdf", "zero_mass_inertia_frames.urdf",
                                 "tiny_fixed_links_not_positive_definite.urdf"}) {
    SCOPED_TRACE(file);
    const std::string twin_file = file.substr(0, file.size() - 5) + "_twin.urdf";
    const auto model = std::make_shared<const FloatingModel>(loadUrdfFile(corpus(file)));
    const auto twin = std::make_shared<const FloatingModel>(loadUrdfFile(corpus(twin_file)));
    ASSERT_EQ(model->jointNames(), twin->jointNames());
    FreeFloatingSolver solver(model), twin_solver(twin);
    Route route(model), twin_route(twin);
    std::mt19937 rng(2800 + static_cast<unsigned>(file.size()));
    for (int s = 0; s < kStates; ++s) {
      SCOPED_TRACE("state " + std::to_string(s));
      const State state = randomState(*model, rng);
      route.at(state);
      const State twin_state = twinState(*model, state, route, *twin);
      twin_route.at(twin_state);
      ASSERT_EQ(solver.compute(state), E_NOERROR);
      ASSERT_EQ(twin_solver.compute(twin_state), E_NOERROR);
      EXPECT_TRUE(closeInNorm(solver.H_star().data, twin_solver.H_star().data, 1e-12, "H* vs the twin's"));
      const VirtualJointTree a(*model, state), b(*twin, twin_state);
      EXPECT_TRUE(closeInNorm(a.M_full(), b.M_full(), 1e-12, "KDL's full mass matrix vs the twin's"));
    }
  }
}

TEST(RealPatterns, MasslessBaseIsAllowedWhenTheLinksSupplyTheMass) {
  // massless_base_composite.urdf is refused: its one joint turns the massless base without moving
  // any mass. A second arm on the mount, on another axis, leaves no such motion: the mass matrix
  // is positive definite, and the file loads with a note.
  const std::string second_arm = R"(
  <joint name="side_yaw" type="revolute">
    <parent link="mount"/>
    <child link="side_arm"/>
    <origin xyz="0.1 0.1 0.02" rpy="1.2 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-2.9" upper="2.9" effort="40" velocity="1.2"/>
  </joint>
  <link name="side_arm">
    <inertial>
      <origin xyz="0 0 0.1" rpy="0 0 0"/>
      <mass value="1.1"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"/>
    </inertial>
  </link>
</robot>)";
  const std::string xml = edited(readFile(corpus("massless_base_composite.urdf")), "</robot>", second_arm);
  std::shared_ptr<const FloatingModel> model;
  try {
    model = std::make_shared<const FloatingModel>(loadUrdfString(xml, "two_arms.urdf"));
  } catch (const ModelError& e) {
    FAIL() << e.what();
  }
  const auto note = std::find_if(model->diagnostics().begin(), model->diagnostics().end(),
                                 [](const Diagnostic& d) { return d.kind == "massless_base"; });
  ASSERT_NE(note, model->diagnostics().end()) << listed(model->diagnostics());
  EXPECT_EQ(note->severity, Severity::Note);
  EXPECT_EQ(note->element, "world");
  EXPECT_NE(note->message.find("'world', 'mount', 'flange'"), std::string::npos) << note->message;
  EXPECT_TRUE(modelWarnings(*model).empty()) << listed(modelWarnings(*model));
  const UrdfReport report = checkUrdfString(xml, "two_arms.urdf");
  EXPECT_TRUE(report.errors.empty()) << listed(report.errors);
  EXPECT_EQ(kinds(report.notes).count("massless_base"), 1u) << listed(report.notes);

  // KDL's full mass matrix (the virtual-joint route) is positive definite, and G* the route's.
  RecursiveExIITSolver recursive(model);
  FreeFloatingSolver dense(model);
  Route route(model);
  std::mt19937 rng(2801);
  for (int s = 0; s < kStates; ++s) {
    const State state = randomState(*model, rng);
    route.at(state);
    const VirtualJointTree tree(*model, state);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(tree.M_full(), Eigen::EigenvaluesOnly);
    EXPECT_GT(eig.eigenvalues()(0), 1e-9 * eig.eigenvalues().maxCoeff());
    ASSERT_EQ(recursive.compute(state), E_NOERROR);
    ASSERT_EQ(dense.compute(state), E_NOERROR);
    for (const std::string tip : {"tool", "side_arm", "flange"}) {
      const LinkPoint point{tip, KDL::Vector(0.02, -0.01, 0.03)};
      EXPECT_TRUE(closeInNorm(libraryGStar(recursive, dense, *model, point), route.G(point), kRel, "G* at " + tip));
    }
  }
}

/// The loader and the checker refuse `xml` alike: the checker's first error of `kind` on
/// `element`, with `words`; the loader's message that error's.
void expectRefusedAlike(const std::string& xml, const std::string& source, const std::string& kind,
                        const std::string& element, const std::vector<std::string>& words) {
  const UrdfReport report = checkUrdfString(xml, source);
  ASSERT_FALSE(report.errors.empty()) << listed(report.warnings);
  EXPECT_EQ(report.errors[0].kind, kind) << listed(report.errors);
  EXPECT_EQ(report.errors[0].element, element) << listed(report.errors);
  for (const std::string& word : words)
    EXPECT_NE(report.errors[0].message.find(word), std::string::npos) << "'" << word << "' not in: " << report.errors[0].message;
  try {
    loadUrdfString(xml, source);
    ADD_FAILURE() << source << " was loaded";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), source + ": " + describe(report.errors[0]));
  }
}

TEST(RealPatterns, SingularSystemsAreRefusedClearly) {
  // A massless base (a rotational inertia only) with no massive link: nothing supplies the mass
  // (its joints move no mass and are fixed; the base translates without inertia).
  std::string xml = readFile(corpus("zero_mass_base_inertia.urdf"));
  for (const std::string mass : {"0.9", "1.2", "0.7"}) xml = edited(xml, "<mass value=\"" + mass + "\"/>", "<mass value=\"0\"/>");
  for (const std::string inertia : {R"(ixx="0.0011" ixy="0" ixz="0.0001" iyy="0.0012" iyz="0" izz="0.0008")",
                                    R"(ixx="0.0009" ixy="0" ixz="0" iyy="0.0071" iyz="0" izz="0.0070")",
                                    R"(ixx="0.0004" ixy="0" ixz="0" iyy="0.0031" iyz="0" izz="0.0030")"})
    xml = edited(xml, inertia, R"(ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0")");
  expectRefusedAlike(xml, "no_massive_link.urdf", "base_without_mass", "body",
                     {"no mass", "singular", "without moving any mass", "<inertial>"});

  // A finger with a rotational inertia but no mass on a prismatic joint: the joint moves no
  // inertia (a zero-mass body translating), the mass matrix is singular.
  std::string prismatic = readFile(corpus("zero_mass_inertia_fingers.urdf"));
  prismatic = edited(prismatic, R"(<joint name="left_finger_joint" type="revolute">)",
                     R"(<joint name="left_finger_joint" type="prismatic">)");
  expectRefusedAlike(prismatic, "prismatic_finger.urdf", "singular_inertia", "left_finger_joint",
                     {"singular", "'left_finger'", "rotational inertia but no mass", "armature"});
}

TEST(RealPatterns, ARigidBodyThatFailsIsStillRefused) {
  // The hand's own inertia made indefinite: the rigid body hand + imu_link + tool_tip then fails
  // too, and the file is refused, naming the rigid body's links.
  const std::string xml = edited(readFile(corpus("tiny_fixed_links_not_positive_definite.urdf")),
                                 R"(<inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/>)",
                                 R"(<inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="-0.001"/>)");
  expectRefusedAlike(xml, "indefinite_hand.urdf", "inertia_not_positive_definite", "hand",
                     {"not positive definite", "nor is the rigid body it forms by fixed joints with 'imu_link', 'tool_tip'",
                      "check the signs"});
}

// --- Properties ----------------------------------------------------------------------------------

/// Every compute call of the three solvers at random states and velocities: 0 and finite, at a
/// random offset on every link.
void expectFiniteEverywhere(const std::shared_ptr<const FloatingModel>& model, std::mt19937& rng, int states,
                            const std::string& what) {
  RecursiveExIITSolver recursive(model);
  FreeFloatingSolver dense(model);
  ForwardDynamicsSolver dynamics(model);
  const unsigned int n = model->nj();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int s = 0; s < states; ++s) {
    SCOPED_TRACE(what + ", state " + std::to_string(s));
    const State state = randomState(*model, rng);
    FloatingVelocity velocity(*model);
    velocity.base_twist = KDL::Twist(KDL::Vector(u(rng), u(rng), u(rng)), KDL::Vector(u(rng), u(rng), u(rng)));
    KDL::JntArray tau(n);
    for (unsigned int j = 0; j < n; ++j) {
      velocity.qdot(j) = u(rng);
      tau(j) = 5.0 * u(rng);
    }
    ASSERT_EQ(recursive.compute(state), E_NOERROR);
    ASSERT_EQ(dense.compute(state), E_NOERROR);
    FloatingAcceleration acceleration;
    acceleration.qddot = KDL::JntArray(n);
    ASSERT_EQ(dynamics.CartToJnt(state, velocity, tau, {}, acceleration), E_NOERROR);
    EXPECT_TRUE(acceleration.base.allFinite());
    EXPECT_TRUE(acceleration.qddot.data.allFinite());
    for (int b = 0; b < static_cast<int>(model->bodies().size()); ++b) {
      const Contact h{b, KDL::Vector(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng))};
      const std::string& link = model->bodies()[b].name;
      Matrix6d G_rec, G_dense;
      ASSERT_EQ(recursive.G_star(h, G_rec), E_NOERROR) << link;
      ASSERT_EQ(dense.G_star(h, G_dense), E_NOERROR) << link;
      EXPECT_TRUE(G_rec.allFinite() && G_dense.allFinite()) << link;
      EXPECT_TRUE(closeInNorm(G_rec, G_rec.transpose(), kRel, "G* symmetric at " + link));
      Vector6d F;
      for (int k = 0; k < 6; ++k) F(k) = u(rng);
      Vector6d d_base, dPL;
      KDL::JntArray dq_rec(n), dq_dense(n);
      ASSERT_EQ(recursive.velocityJump(h, F, d_base, dq_rec), E_NOERROR) << link;
      ASSERT_EQ(dense.velocityJump(h, Response::FreeFloating, F, dPL, dq_dense), E_NOERROR) << link;
      EXPECT_TRUE(d_base.allFinite() && dq_rec.data.allFinite() && dPL.allFinite() && dq_dense.data.allFinite())
          << link;
      EXPECT_TRUE(closeInNorm(dq_rec.data, dq_dense.data, 1e-8, "joint-rate jump at " + link));
    }
  }
}

std::vector<std::string> corpusFiles() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dataDir() + "/real_patterns"))
    if (entry.is_regular_file()) files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(RealPatterns, EveryFileLoadsOrIsRefusedAsListed) {
  std::set<std::string> listed_files;
  for (const LoadCase& c : loadCases()) listed_files.insert(c.file);
  for (const RefusedCase& c : refusedCases()) listed_files.insert(c.file);
  const std::vector<std::string> files = corpusFiles();
  EXPECT_EQ(std::set<std::string>(files.begin(), files.end()), listed_files);
}

TEST(RealPatterns, ComputeCallsAreFiniteOnEveryFileThatLoads) {
  std::mt19937 rng(12);
  int loaded = 0;
  for (const std::string& file : corpusFiles()) {
    std::shared_ptr<const FloatingModel> model;
    try {
      model = std::make_shared<const FloatingModel>(loadUrdfFile(corpus(file)));
    } catch (const ModelError&) {
      continue;
    }
    ++loaded;
    expectFiniteEverywhere(model, rng, kPropertyStates, file);
  }
  EXPECT_EQ(loaded, static_cast<int>(loadCases().size()));
}

// --- Random trees with a massless root and point masses -------------------------------------------

/// Copies the children of `from` below `hook` in `target`; segments whose name ends in "_frame"
/// and that have no mass get a point mass when `point_masses` (mass > 0, zero rotational inertia).
void copyBelow(KDL::SegmentMap::const_iterator from, const std::string& hook, KDL::Tree& target, bool point_masses,
               std::mt19937& rng) {
  std::uniform_real_distribution<double> mass(0.05, 2.0);
  for (const auto& child : GetTreeElementChildren(from->second)) {
    const KDL::Segment& seg = GetTreeElementSegment(child->second);
    KDL::RigidBodyInertia inertia = seg.getInertia();
    const std::string& name = seg.getName();
    if (point_masses && inertia.getMass() == 0.0 && name.size() > 6 && name.substr(name.size() - 6) == "_frame")
      inertia = KDL::RigidBodyInertia(mass(rng), randomVector(rng, 0.2), KDL::RotationalInertia::Zero());
    ASSERT_TRUE(target.addSegment(KDL::Segment(name, seg.getJoint(), seg.pose(0.0), inertia), hook)) << name;
    copyBelow(child, name, target, point_masses, rng);
  }
}

/// The random tree below a massless root "world": its base (with the base inertia) on a fixed
/// joint at a random pose, and (if asked) point masses in place of the massless frame leaves.
KDL::Tree belowMasslessWorld(const RandomTree& r, const KDL::Frame& world_T_base, bool point_masses,
                             std::mt19937& rng) {
  KDL::Tree tree("world");
  EXPECT_TRUE(tree.addSegment(KDL::Segment("base", KDL::Joint("world_joint", KDL::Joint::None), world_T_base,
                                           r.base_inertia),
                              "world"));
  copyBelow(r.tree.getRootSegment(), "base", tree, point_masses, rng);
  return tree;
}

TEST(RealPatterns, RandomTreesOnAMasslessWorldRoot) {
  std::mt19937 rng(kTreeSeed + 12);
  std::uniform_real_distribution<double> off(-0.2, 0.2);
  int point_mass_trees = 0, singular_composites = 0;
  for (int t = 0; t < kRandomTrees; ++t) {
    SCOPED_TRACE("tree " + std::to_string(t));
    const RandomTree r = randomTree(rng);
    const KDL::Frame world_T_base(randomRotation(rng), randomVector(rng, 0.5));
    const auto plain = std::make_shared<const FloatingModel>(r.tree, r.base_inertia);
    std::shared_ptr<const FloatingModel> on_world, with_points;
    try {
      on_world = std::make_shared<const FloatingModel>(belowMasslessWorld(r, world_T_base, false, rng),
                                                       KDL::RigidBodyInertia::Zero());
      with_points = std::make_shared<const FloatingModel>(belowMasslessWorld(r, world_T_base, true, rng),
                                                          KDL::RigidBodyInertia::Zero());
    } catch (const ModelError& e) {
      FAIL() << e.what();
    }
    if (r.coverage.frame_leaves > 0) {
      ++point_mass_trees;
      // The model's own rules (no loader) say what they read: a point mass per frame leaf.
      int point_masses = 0;
      for (const Diagnostic& d : with_points->diagnostics()) {
        point_masses += d.kind == "point_mass";
        if (d.kind == "singular_composite") ++singular_composites;
      }
      EXPECT_EQ(point_masses, r.coverage.frame_leaves) << listed(with_points->diagnostics());
    }
    EXPECT_TRUE(modelWarnings(*on_world).empty()) << listed(modelWarnings(*on_world));
    EXPECT_EQ(on_world->bodies()[0].name, "world");
    EXPECT_NEAR(on_world->totalMass(), plain->totalMass(), 1e-12 * plain->totalMass());

    // The massless root changes nothing: G* equals the plain tree's and the route's.
    RecursiveExIITSolver plain_solver(plain), world_solver(on_world), points_solver(with_points);
    FreeFloatingSolver plain_dense(plain), world_dense(on_world), points_dense(with_points);
    Route world_route(on_world), points_route(with_points);
    for (int s = 0; s < 2; ++s) {
      const State state = randomState(*on_world, rng);
      world_route.at(state);
      points_route.at(state);
      const State plain_state = twinState(*on_world, state, world_route, *plain);
      ASSERT_EQ(world_solver.compute(state), E_NOERROR);
      ASSERT_EQ(world_dense.compute(state), E_NOERROR);
      ASSERT_EQ(points_solver.compute(state), E_NOERROR);
      ASSERT_EQ(points_dense.compute(state), E_NOERROR);
      ASSERT_EQ(plain_solver.compute(plain_state), E_NOERROR);
      ASSERT_EQ(plain_dense.compute(plain_state), E_NOERROR);
      for (const auto& [name, element] : r.tree.getSegments()) {
        const LinkPoint point{name, KDL::Vector(off(rng), off(rng), off(rng))};
        SCOPED_TRACE("contact " + name);
        const Eigen::MatrixXd G = libraryGStar(world_solver, world_dense, *on_world, point);
        EXPECT_TRUE(closeInNorm(G, world_route.G(point), kRel, "massless root: G* vs the route"));
        EXPECT_TRUE(closeInNorm(G, libraryGStar(plain_solver, plain_dense, *plain, point), kRel,
                                "massless root: G* vs the plain tree's"));
        EXPECT_TRUE(closeInNorm(libraryGStar(points_solver, points_dense, *with_points, point),
                                points_route.G(point), kRel, "point masses: G* vs the route"));
      }
    }
    expectFiniteEverywhere(with_points, rng, 3, "point masses, tree " + std::to_string(t));
  }
  EXPECT_GT(point_mass_trees, 5);
  std::cout << "[ info     ] " << point_mass_trees << " of " << kRandomTrees << " trees with point masses, "
            << singular_composites << " singular composites among them\n";
}

}  // namespace
}  // namespace kdl_space::test
