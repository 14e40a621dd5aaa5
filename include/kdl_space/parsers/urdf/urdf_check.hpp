// Checking a URDF file for use as a free-floating model: every problem, not only the first.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"

namespace kdl_space {

/// \brief Figures of the model, as far as the file could be read.
struct ModelSummary {
  std::string robot;   ///< the <robot> name ("" if unknown)
  std::string base;    ///< the free-floating base link ("" if it could not be decided)
  int links = 0;       ///< <link> elements in the file, less a dropped massless root
  int joints = 0;      ///< <joint> elements in the file, less the dropped floating joint
  /// True when the loader built the model (no errors); the fields below are set only then.
  bool loaded = false;
  std::vector<std::string> joint_names;  ///< movable joints, model order
  std::vector<JointProperties> joint_properties;  ///< their limits, damping, friction (model order)
  std::vector<FixedJoint> joints_treated_as_fixed;  ///< movable joints of the file that are not coordinates
  double total_mass = 0.0;               ///< [kg]
  /// Condition number (largest / smallest eigenvalue) of H* at q = 0, base at the origin;
  /// NaN without movable joints, or above 400 of them (not computed: an O(n^3) eigen-decomposition;
  /// the note `large_model` says so), +inf when singular.
  double condition_H_star = 0.0;
  /// Condition number of G* at each contact link (the requested tips, else every link that
  /// carries no other link), at q = 0.
  std::vector<std::pair<std::string, double>> condition_G_star;
};

/// \brief Everything `checkUrdfFile` found.
struct UrdfReport {
  std::string source;             ///< file name (or the name given to checkUrdfString)
  std::vector<Finding> errors;    ///< the model cannot be used until these are fixed
  std::vector<Finding> warnings;  ///< the model loads; these deserve a look
  std::vector<Finding> notes;     ///< what was read and how (not problems: --strict passes them)
  ModelSummary model;
};

/// \brief Reads a URDF file and reports every problem that keeps it from being used as a
/// free-floating model (errors) or that deserves attention (warnings).
///
/// Errors: not readable, not XML, not URDF; no root, several roots, a loop; a joint naming a
/// link that does not exist; a floating or planar joint below the root; a negative mass, a rigid
/// body (links joined by fixed joints) whose inertia is not positive definite; NaN, infinite or
/// malformed numbers (every number attribute is checked); a zero-length axis; a tip that is not a
/// link; a base without mass that the links do not supply (a singular mass matrix). Warnings: zero
/// mass with a rotational inertia, a link's inertia that fails while its rigid body passes, the
/// triangle inequality broken; the root link's
/// inertia that kdl_parser would drop (kdl_space keeps it), massless links, an axis that is
/// not unit length, limits that exclude 0, a base more than 1e6 times heavier than the lightest
/// moving link (with the condition numbers of H* and G* at q = 0).
///
/// The rules are the ones loadUrdfFile applies (one implementation): a file without errors
/// loads. Never throws (beyond std::bad_alloc) and never prints.
/// \param tips contact links to check and to compute G* at.
KDL_SPACE_EXPORT UrdfReport checkUrdfFile(const std::string& path, const std::vector<std::string>& tips = {});

/// Same as checkUrdfFile for a URDF document in memory; `source` names it in the report.
KDL_SPACE_EXPORT UrdfReport checkUrdfString(const std::string& xml, const std::string& source = "<urdf string>",
                           const std::vector<std::string>& tips = {});

}  // namespace kdl_space
