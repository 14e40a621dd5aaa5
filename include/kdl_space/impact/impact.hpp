// Impact laws between two bodies that touch at one point (section 4 of the paper, MATH.md).
// Pure functions of the two sides' inverse inertias at the contact point and their contact
// twists: stateless, allocation-free. Each has a checked form that returns 0 or an Error code
// (errors.hpp) and leaves its output untouched on an error, and a value form: the bare formula,
// for inputs the caller has already checked (its result is unspecified, NaN or infinite, for
// inputs the checked form refuses; it never throws).
//
// Sign convention: F is the impulse wrench on side A (the robot) at the contact point, world
// frame; side B (the target) receives -F. The unit normal n points from A's contact point toward
// B. A approaches B when u_n = n^T (v_A - v_B) > 0.
#pragma once

#include "kdl_space/export.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space {

/// The impact laws a user can choose.
enum class ImpactKind {
  Capture,               ///< rigid 6-D grasp: both contact twists equal afterwards (eq. 24-25)
  PointImpact,           ///< frictionless, Newton restitution e along n
  FrictionalImpact,      ///< Newton restitution e along n and Coulomb friction mu
  TranslationalCapture,  ///< linear velocities equal afterwards, rotation free (probe in a drogue)
};

/// An impact law and its parameters.
struct ImpactLaw {
  ImpactKind kind = ImpactKind::Capture;
  Vector3d normal = Vector3d::UnitX();  ///< unit, from A toward B (point impacts)
  double restitution = 0.0;             ///< e in [0, 1] (point impacts)
  double friction = 0.0;                ///< mu >= 0 (FrictionalImpact)
};

/// The impulse an impact law gives.
struct Impulse {
  Vector6d F = Vector6d::Zero();  ///< impulse wrench on A at the contact point (B gets -F)
  bool separating = false;        ///< point impacts: already separating along n, no impulse
  bool sticking = false;          ///< FrictionalImpact: no slip at the end of the impact
  /// FrictionalImpact: the slip process chattered past its step budget (extremely anisotropic
  /// G) and was completed by the maximum-dissipation impulse (docs/IMPACT.md).
  bool max_dissipation_completion = false;
};

/// \brief Solves an impact law.
/// \param G_A, G_B inverse inertias (Ex-IIT) of A and B at the contact point (twist per impulse)
/// \param t_A, t_B twists of A's and B's material points at the contact point before the impact
/// Uses (G_A + G_B), never G_A^-1, so a grounded A at a singular configuration is fine.
/// Frictional model (docs/IMPACT.md): Coulomb friction through the impact by Routh's method in
/// impulse space, sticking while the sticking impulse rate lies in the cone and sliding against
/// the slip otherwise, with Stronge's energetic restitution e (Stronge 2000, ch. 5). Never adds
/// energy, always in the cone; with mu = 0 it is PointImpact (Newton's and Stronge's e agree).
/// \return 0, or: E_NOT_FINITE if an input holds NaN or an infinity (law parameters included) or
/// the impulse overflows; E_BAD_ARGUMENT if `law.kind` is no enumerator, or for a point or
/// frictional impact the normal has zero length or the restitution lies outside [0, 1], or for a
/// frictional impact the friction is negative; E_NOT_POSITIVE_DEFINITE if the law's block of
/// G_A + G_B cannot be factorised (capture: the 6x6 sum; translational capture and friction: its
/// translational 3x3 block; point impact: n^T G_vv n <= 0). `impulse` is untouched on an error.
KDL_SPACE_EXPORT int solveImpact(const Matrix6d& G_A, const Matrix6d& G_B, const Vector6d& t_A, const Vector6d& t_B,
                const ImpactLaw& law, Impulse& impulse);
/// The same, unchecked (see the top of this header).
KDL_SPACE_EXPORT Impulse solveImpact(const Matrix6d& G_A, const Matrix6d& G_B, const Vector6d& t_A, const Vector6d& t_B,
                    const ImpactLaw& law);

/// \brief Virtual mass of a side along a direction n: 1 / (n^T G_vv n) with n made unit (the
/// seed's ref. 3). \return 0, E_NOT_FINITE (G or n), E_BAD_ARGUMENT (n of zero length), or
/// E_NOT_POSITIVE_DEFINITE when n^T G_vv n <= 0 (the side cannot be moved along n: a grounded arm
/// at a singular configuration has an infinite virtual mass there). `m` untouched on an error.
KDL_SPACE_EXPORT int virtualMass(const Matrix6d& G, const Vector3d& n, double& m);
/// The same for a unit n, unchecked: +inf where n^T G_vv n = 0.
KDL_SPACE_EXPORT double virtualMass(const Matrix6d& G, const Vector3d& n);


}  // namespace kdl_space
