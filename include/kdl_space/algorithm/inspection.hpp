// Everything `inspect` reports about a robot at one state and its contact points, by the dense
// FreeFloatingSolver up to kDenseJoints joints and by the O(n) routes above.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/multibody/state.hpp"
#include "kdl_space/spatial/spatial.hpp"

namespace kdl_space {

/// The quantities at one contact point h (world frame; twists (v; w)).
struct ContactInspection {
  Vector3d point = Vector3d::Zero();  ///< p_h
  KDL::Frame frame;                   ///< the contact frame (origin at p_h, the link's axes)
  Matrix6Xd J_star, J;                ///< generalized (eq. 4) and fixed-base Jacobians, 6 x n
  Matrix6d G_star = Matrix6d::Zero();     ///< Ex-IIT, eq. 11
  Matrix6d G_locked = Matrix6d::Zero();   ///< R_h M_a^-1 R_h^T, eq. 20
  std::optional<Matrix6d> G_grounded;     ///< J H^-1 J^T (eq. 22); none when H is not positive definite
  Conditioning conditioning;              ///< of J* and J
};

/// The system's quantities at one state and its contact points.
struct Inspection {
  double mass = 0.0;                  ///< w
  Vector3d r_g = Vector3d::Zero();    ///< system CoM
  Matrix3d I_g = Matrix3d::Zero();    ///< eq. 3
  /// Whether H* was formed (nj() <= dense_joints of inspect()): above, the O(n) routes give G* and the
  /// grounded G (RecursiveExIITSolver) and J* (FreeFloatingSolver::Extent::Jacobians), and no
  /// n x n matrix is formed.
  bool dense = true;
  Eigen::MatrixXd H_star;             ///< eq. 7, n x n; 0 x 0 when !dense
  std::vector<ContactInspection> contacts;
  /// G* over all contact points, 6k x 6k with the cross-coupling blocks
  /// G*_ij = J*_i H*^-1 J*_j^T + R_i M_a^-1 R_j^T (eq. 11); above kDenseJoints column by column from
  /// the velocity jumps of unit impulses (eq. 18), O(k^2 n).
  Eigen::MatrixXd G_star_all;

  /// What failed when inspect() returns an error code: -1 the state, a contact's index, or
  /// contacts.size() for G* over all of them; and the quantity ("free-floating quantities",
  /// "contact quantities", "grounded G", "fixed-base J", "G* over all contact points").
  int failed_at = -1;
  std::string failed;
};

/// \brief Computes `out` for `model` at `state` and the contact points `contacts`: by the dense
/// route up to `dense_joints` joints, by the O(n) routes above (the default kDenseJoints; the
/// tests pass 0 to run the O(n) routes on every model). Polls `cancelled` (if set) before each
/// contact and throws Cancelled when it says so.
/// \return 0, or a solver's code (errors.hpp) with out.failed_at and out.failed naming what.
KDL_SPACE_EXPORT int inspect(const std::shared_ptr<const FloatingModel>& model, const State& state,
                             const std::vector<Contact>& contacts, Inspection& out,
                             const std::function<bool()>& cancelled = {}, unsigned int dense_joints = kDenseJoints);

}  // namespace kdl_space
