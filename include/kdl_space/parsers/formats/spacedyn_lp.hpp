// SpaceDyn (the MATLAB toolbox of the formulation's authors): a robot written as its link
// parameters `LP` and an initial state `SV`, and an `LP` function file read back as a URDF document.
// SpaceDyn's definitions (calc_aa.m, calc_pos.m, rpy2dc.m, init_SV.m): link i hangs on link BB(i)
// by joint i, which turns about (slides along) the z axis of link i's frame; A_i = A_BB(i)
// Rx(Qi1) Ry(Qi2) Rz(Qi3 + q_i) (rpy2dc(Qi)' = Rx Ry Rz); c0, cc, ce are vectors from a link's
// centroid (to a joint, an end point) in that link's frame; the base's quantities at its centroid.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/impact/collision.hpp"
#include "kdl_space/multibody/diagnostics.hpp"

namespace kdl_space {

/// The two MATLAB function files of a robot and what the export assumed.
struct SpaceDynFiles {
  std::string name;   ///< the functions' stem: NAME_LP, NAME_SV (a MATLAB identifier)
  std::string lp;     ///< "function LP = NAME_LP()": num_q, BB, SS, S0, SE, J_type, c0, cc, ce, Qi, Qe, m0, m, mass, inertia0, inertia
  std::string sv;     ///< "function SV = NAME_SV()": R0, A0, Q0, v0, w0, q, qd (and the rest of init_SV.m's fields, zero)
  std::vector<Diagnostic> notes;  ///< links merged, frames re-oriented, what SpaceDyn cannot hold (limits, armature)
};

/// \brief `system`'s robot as SpaceDyn's LP and its state as SV. The links fixed to one another
/// merge into one SpaceDyn link (their composite mass and inertia); each moving joint's link frame
/// is re-oriented so that its z axis is the joint's axis (the least rotation from the link's own
/// z), its origin on the axis; links are numbered in the tree's order (a parent before its
/// children: BB(i) < i). End points (SE, ce, Qe): the system's contact point on its link, and each
/// leaf link's last fixed descendant (e.g. a tool frame). Extra fields name what SpaceDyn numbers:
/// LP.link_names (base first), LP.joint_names, LP.end_names (cell arrays; SpaceDyn ignores them).
/// The SV's q and qd are in SpaceDyn's joint order (LP.joint_names), v0 the base centroid's velocity.
/// \throws ModelError for mimic joints (SpaceDyn has no coupled joints), naming them.
KDL_SPACE_EXPORT SpaceDynFiles writeSpaceDyn(const FloatingSystem& system, const std::string& name);

/// \brief An LP function file (the numeric assignments to LP's fields that writeSpaceDyn writes and
/// SpaceDyn's examples use: matrices, `'` transposes, zeros(...), LP.cc(:,i,j) = ...) as one URDF
/// document: the base link at the base's centroid, each link at its joint with its frame as
/// SpaceDyn's, its end points as fixed massless links (LP.end_names, else "end<k>"); names from
/// LP.link_names / LP.joint_names when given, else "base", "link<i>", "joint<i>".
/// \param notes gets what was assumed (no limits in an LP: a prismatic joint gets +-1e9 m).
/// \throws InputError "FILE:LINE: LP.FIELD: what" for anything else (a statement it does not read,
/// a size that disagrees with num_q, BB(i) >= i, an unknown joint type, a mass < 0).
KDL_SPACE_EXPORT std::string spaceDynToUrdf(const std::string& lp_path, std::vector<Diagnostic>& notes);

}  // namespace kdl_space
