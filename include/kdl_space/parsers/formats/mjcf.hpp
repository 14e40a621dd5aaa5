// MuJoCo's model format (MJCF): a scenario's robot, its state and its target written as one MJCF
// file that MuJoCo loads as the same free-floating dynamics, and the subset that file uses read
// back as a URDF document (which the URDF loader turns into a FloatingModel). The library does not
// link MuJoCo: the text is plain XML (TinyXML); the tests load it into MuJoCo to check it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/impact/collision.hpp"
#include "kdl_space/multibody/diagnostics.hpp"

namespace kdl_space {

/// What an MJCF file holds besides the robot: the scene of a scenario.
struct MjcfScene {
  /// The robot: its model, state (base pose, q), velocity (base twist of the base origin, qdot;
  /// an empty qdot reads as zero rates) and contact point (written as the site "contact"; none for a
  /// contact body of -1, a system without one).
  FloatingSystem robot;
  /// What it meets (if anything): a rigid body, or another free-floating system (its bodies and
  /// joints named "target/" + their names, its contact the site "target_contact").
  std::optional<CaptureTarget> target;
  std::string name = "kdl_space";  ///< the <mujoco model=...> name
};

/// \brief The scene as an MJCF document that MuJoCo (2.2 and later) loads as the same dynamics.
///
/// `<compiler angle="radian" inertiafromgeom="false"/>`, `<option gravity="0 0 0">` with contacts
/// off (`<flag contact="disable"/>`). The robot's base is a body with a `<freejoint/>` at the
/// base pose; each link a body nested in its parent's at its pose for q = 0 (a link on a fixed
/// joint, or on a movable joint the model treats as fixed, is a body without a joint); a revolute
/// or continuous joint a `hinge`, a prismatic one a `slide`, with `pos` and `axis` in the child
/// body's frame, `range` (with `limited="true"`) where both limits are finite, `damping`,
/// `frictionloss` (the URDF's Coulomb friction) and `armature` where they are not 0 (effort and
/// velocity limits belong to actuators in MJCF: not written). A body's `<inertial pos quat mass
/// diaginertia>` is its CoM and its inertia diagonalised in double precision here (not
/// `fullinertia`, which MuJoCo's compiler diagonalises to ~1e-6 only); a body without mass nor
/// inertia has no `<inertial>`. The target is a free body of its own (a rigid target, named
/// "target") or a free tree (a free-floating one). `<keyframe><key name="scenario" qpos qvel/>`
/// holds the state: per free joint its origin and its quaternion (w first), then the joints in
/// the document's order; qvel per free joint the origin's linear velocity in world axes and the
/// angular velocity in body axes, then the joint rates. Numbers have 17 significant digits.
/// Names are the model's; a name MuJoCo would see twice (a joint and the free joint, bodies of
/// the robot and of the target) is made unique with a suffix "_2", "_3", ...
/// MuJoCo's XML reader refuses more than 100 nested elements: a chain deeper than ~95 links is
/// written but MuJoCo will not load it.
/// \throws ModelError for a null model, a state, velocity or contact that is not the model's
/// (sizes, body index), a non-finite number, or a model with mimic joints (naming them: MuJoCo's
/// equality constraints are soft, the file would not be the same dynamics).
KDL_SPACE_EXPORT std::string writeMjcf(const MjcfScene& scene);

/// \brief The subset of MJCF that writeMjcf writes, read back as ONE URDF document.
///
/// Read: `<compiler angle eulerseq>` (angles in degrees unless `angle="radian"`), `<body name pos>`
/// with its orientation as `quat`, `axisangle`, `euler`, `xyaxes` or `zaxis`, `<freejoint/>` (or
/// `<joint type="free"/>`) on the robot's base, `<joint type="hinge|slide" pos axis range limited
/// damping frictionloss armature>` (at most one per body), `<inertial pos orientation mass
/// diaginertia|fullinertia>`. The robot is the first top-level body of `<worldbody>` with a free
/// joint, else the first top-level body; every other top-level body is a note (not read). Each
/// body is a link of the same name (an unnamed one "body_LINE"); a URDF link frame is the MJCF
/// body frame moved to its joint's `pos` (the URDF joint frame is the child's link frame), its
/// inertial re-expressed there; a body without a joint hangs on a fixed joint "NAME_fixed". A hinge
/// with a range is `revolute`, without one `continuous`; a slide `prismatic` (without a range: with
/// the limits of a double, and a note). A `range` counts where `limited="true"`, or where
/// `limited` is not written (MuJoCo's `autolimits`). Notes (Severity::Note) say what was not read:
/// geoms, sites, other top-level bodies, and each joint's `armature` (URDF has none: kind
/// "armature", element the joint, details {"armature", value}: FloatingModel::withArmature).
/// \param source names the text in messages (a file name).
/// \throws InputError "SOURCE:LINE: <element attribute=...>: what" for anything it cannot read:
/// not XML, no `<mujoco>` or `<worldbody>` or body, an unknown joint type, a ball joint, a free
/// joint below the base, two joints in one body, a joint `ref` other than 0, a global
/// `<compiler coordinate>`, `<include>` or default classes, an inertial without `mass` or without
/// its inertia, a number that is not a finite number or a wrong count of numbers.
KDL_SPACE_EXPORT std::string mjcfToUrdf(const std::string& xml, const std::string& source,
                                        std::vector<Diagnostic>& notes);

}  // namespace kdl_space
