// Whether a robot link sits inside its target at the start or at the capture: each link's
// geometry (its URDF visuals bounded by boxes, or its box of inertia) against the target's boxes
// of inertia, by the separating-axis test (multibody/overlap.hpp). What `simulate` and `capture`
// warn of (kind `overlap`): a target placed around the arm, or a grasp that buries the wrist.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/multibody/overlap.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"
#include "kdl_space/parsers/urdf/urdf_visuals.hpp"

namespace kdl_space {

/// The depth [m] a link may penetrate the target before it is warned of: 1 cm (a contact that
/// grazes is not an overlap; boxes bound the geometry, so a smaller depth says little).
inline constexpr double kOverlapAllowance = 0.01;

/// The robot's geometry for the check, in each body's frame (model order).
struct LinkGeometry {
  std::vector<std::vector<OrientedBox>> boxes;  ///< per body
  /// Per body: true where the boxes bound its visuals, false where they are its box of inertia.
  std::vector<bool> from_visuals;
};

/// \brief Each body's boxes: its visuals bounded by boxes (a box as it is; a cylinder of radius r
/// and length l: r x r x l's box 2r x 2r x l on its axes; a sphere: the cube of edge 2r), its box
/// of inertia for a body without a visual or with a mesh (not read here: its extent is unknown).
/// `visuals` by link name (readUrdfVisuals); empty: every body takes its box of inertia.
KDL_SPACE_EXPORT LinkGeometry linkGeometry(const FloatingModel& model,
                                           const std::map<std::string, std::vector<LinkVisual>>& visuals);

/// \brief The overlap warnings of `problem`'s robot at its state against its target (a rigid
/// target's box of inertia, or each body of a free-floating target's), kind `overlap`: one per
/// robot link that penetrates deeper than `allowance` [m] (penetrations; deepest first), element
/// the link, details {link, target, depth [m], moment, geometry: "visuals" or "inertia_box"}.
/// The bodies that carry the contact (contactBodies: the hand touches the target by design) are
/// not checked; the link that carries them (the wrist) may reach as deep as the grasp point lies
/// inside the target's boxes (a grasp inside a box says the target is smaller there), plus
/// `allowance`. `moment`: "start" or "capture" (the message begins "at the capture: " for the
/// latter; the start's is the caller's to say: approachStartWarnings). Pure; no warning where the
/// kinematics cannot be computed (the run fails there on its own).
KDL_SPACE_EXPORT std::vector<Diagnostic> overlapWarnings(const CaptureProblem& problem, const LinkGeometry& robot,
                                                         const std::string& moment,
                                                         double allowance = kOverlapAllowance);

/// \brief The same with the robot's visuals read from `robot_urdf` (readUrdfVisuals; "" for boxes
/// of inertia only). \throws ModelError naming the file when it cannot be read.
KDL_SPACE_EXPORT std::vector<Diagnostic> overlapWarnings(const CaptureProblem& problem, const std::string& robot_urdf,
                                                         const std::string& moment,
                                                         double allowance = kOverlapAllowance);

/// \brief The robot's links inside its own bus at `state`: each body more than two joints from the
/// base (the arm's first links sit on the bus by design) whose boxes (`robot`) penetrate the base
/// body's deeper than `allowance` [m], deepest first: kind `overlap`, element the link, details
/// {link, target: "bus", depth [m], moment}. None where the kinematics cannot be computed.
KDL_SPACE_EXPORT std::vector<Diagnostic> busOverlapWarnings(const FloatingModel& model, const State& state,
                                                            const LinkGeometry& robot, const std::string& moment,
                                                            double allowance = kOverlapAllowance);

/// \brief A scenario's overlap warnings at `at` (its own capture problem, or the one at the contact
/// instant of its approach), its robot's visuals from its URDF; none for a plain motion.
KDL_SPACE_EXPORT std::vector<Diagnostic> overlapWarnings(const Scenario& scenario, const CaptureProblem& at,
                                                         const std::string& moment);

}  // namespace kdl_space
