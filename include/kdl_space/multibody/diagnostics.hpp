// What the library finds wrong with a description, as data (the library never prints): the
// findings of the URDF checker and the rules, and the diagnostics a model keeps. The bottom
// layer beside spatial.hpp: it includes nothing of ours.
#pragma once

#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "kdl_space/export.hpp"

namespace kdl_space {

/// Whether a finding stops the model from being used (error), deserves attention (warning), or
/// only says what was read and how (note: `check --strict` passes over notes).
enum class Severity { Error, Warning, Note };

/// What `Finding::element` names.
enum class ElementType {
  File,   ///< the file as a whole (`element` is empty)
  Robot,  ///< the <robot> element (`element` is the robot's name)
  Link,
  Joint,
  Tip,    ///< a contact link asked for by the caller
};

/// \brief One problem found in a URDF description (or a model).
struct Finding {
  Severity severity = Severity::Error;
  /// A short, stable, machine-readable identifier: `not_xml`, `not_urdf`, `malformed`,
  /// `duplicate_name`, `unknown_joint_type`, `no_root`, `several_roots`, `loop`,
  /// `missing_link`, `free_joint_inside`, `non_positive_mass`, `inertia_not_positive_definite`,
  /// `not_finite`, `bad_number`, `zero_axis`, `unknown_tip`, `base_without_mass`, `too_deep`,
  /// `singular_inertia`, `unreadable`, `refused_by_loader`, `xacro`, `encoding` (errors);
  /// `inertia_without_mass`, `link_inertia_not_positive_definite`,
  /// `point_mass`, `inertia_round_off`, `triangle_inequality`, `joint_moves_no_mass`,
  /// `revolute_without_limit`, `singular_composite`, `mimic_ignored`, `axis_not_unit`,
  /// `limits_exclude_zero`, `mass_ratio` (warnings); `root_inertia_dropped_by_kdl_parser`,
  /// `massless_link`, `massless_base`, `encoding` (an ISO-8859-1 file read), `large_model` (notes).
  std::string kind;
  ElementType element_type = ElementType::File;
  std::string element;  ///< link, joint or tip name; the robot's name; "" for the file
  std::string message;  ///< what is wrong and, where it helps, what to do; without the element
};

/// The element and the message in one line: "link 'forearm': inertia is not positive definite
/// (...)"; only the message for a finding about the file as a whole.
KDL_SPACE_EXPORT std::string describe(const Finding& finding);

/// A problem that does not stop the computation, or what was assumed to read a description (a
/// point mass, a joint treated as fixed, a dropped floating joint). The library never prints:
/// callers read these.
struct Diagnostic {
  std::string element;  ///< the link or joint concerned ("" for the model as a whole)
  std::string message;  ///< what was found and what the model does about it
  std::string kind;     ///< the Finding kind when it comes from a rule ("" otherwise)
  Severity severity = Severity::Warning;  ///< Warning or Note
  /// What the message states, as data for a program (the tool's JSON and Python add each as a key
  /// of the warning beside kind, element and message): an overlap's "depth" [m], "moment", ...
  /// Empty for most.
  std::vector<std::pair<std::string, std::variant<double, std::string>>> details = {};
};

}  // namespace kdl_space
