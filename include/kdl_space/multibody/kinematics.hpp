// The per-state kinematics of a free-floating model, computed once per state by one function
// (forwardKinematics) and read by every solver: the world pose of every body, every joint's unit
// twist, every body's mass properties in world terms, the system's centre of mass.
#pragma once

#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space {

/// \brief Kinematics of one state of a FloatingModel (plain data, world frame; per body in
/// model().bodies() order). Sized for its model by the constructor; filled by forwardKinematics,
/// which allocates nothing. Solvers read it `const` and keep no reference to it.
struct KDL_SPACE_EXPORT Kinematics {
  const FloatingModel* model = nullptr;  ///< the model it was sized for (identity only)
  bool valid = false;                    ///< set by a successful forwardKinematics
  State state;                           ///< the state it holds
  std::vector<Matrix3d> R;    ///< per body: world rotation (world_R_body)
  std::vector<Vector3d> p;    ///< per body: world position of its frame's origin [m]
  /// Per body: the unit twist (v; w) of its joint, world axes, v at the base origin p_b; zero for
  /// the base and for bodies on fixed joints. (A joint's twist at a point x: v + w x (x - p_b).)
  std::vector<Vector6d> S;
  std::vector<Vector3d> com;  ///< per body: world position of its CoM [m]
  std::vector<Matrix3d> I_com;  ///< per body: inertia about its CoM, world axes [kg m^2]
  Vector3d p_b = Vector3d::Zero();  ///< base frame origin (= p[0]) [m]
  Vector3d r_g = Vector3d::Zero();  ///< system CoM [m]
  /// Workspace of forwardKinematics: per body its joint angle (zero for a body without a
  /// revolute joint), and the angle's sine and cosine; padded to a multiple of four angles.
  std::vector<double> angle_, sin_, cos_;

  Kinematics() = default;
  explicit Kinematics(const FloatingModel& model);
  /// World pose of body i (KDL form).
  KDL::Frame pose(int i) const;
  /// World position of a contact point.
  Vector3d point(const Contact& h) const { return R[h.body] * toEigen(h.offset) + p[h.body]; }
};

/// \brief The code of a contact query that cannot be answered: E_NOT_COMPUTED (nothing
/// computed), E_BAD_CONTACT (h.body outside [0, bodies)), E_NOT_FINITE (a non-finite offset); 0
/// when it can. Every solver's contact queries start with it.
inline int contactCode(bool computed, const Contact& h, std::size_t bodies) {
  if (!computed) return E_NOT_COMPUTED;
  if (h.body < 0 || static_cast<std::size_t>(h.body) >= bodies) return E_BAD_CONTACT;
  if (!allFinite(h.offset)) return E_NOT_FINITE;
  return E_NOERROR;
}

/// \brief Forward kinematics of `model` at `state` into `kin` (sized for that model).
/// \return 0; E_SIZE_MISMATCH (state.q, or `kin` sized for another model); E_NOT_FINITE (the
/// state, or a result that overflows). On an error `kin.valid` is false.
KDL_SPACE_EXPORT int forwardKinematics(const FloatingModel& model, const State& state, Kinematics& kin);

}  // namespace kdl_space
