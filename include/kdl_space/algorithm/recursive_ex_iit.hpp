// O(n) recursive Ex-IIT and impulse response: articulated-body inertias over the KDL tree
// (Featherstone's articulated-body algorithm with a floating base) instead of forming and
// factorising H*. Same results as the paper's dense formula (FreeFloatingSolver), which stays
// the second route in the tests.
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/multibody/model.hpp"
#include "kdl_space/spatial/response.hpp"
#include "kdl_space/spatial/spatial.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space {
namespace detail {
struct LaneSymmetric6d;  // src/detail/lane_symmetric6d.hpp: a symmetric 6x6 in four-lane blocks
class MimicCoupling;     // src/algorithm/mimic_coupling.hpp: mimic joints as constraints
}

/// \brief G* at one contact point and the velocity jump of the whole robot from an impulse there,
/// in O(n) per state (plus O(depth of the contact) per contact), allocation-free after
/// construction.
///
/// `compute(kin)`: one backward pass of articulated-body inertias
/// I^A_i = I_i + sum over children (I^A_c - U_c D_c^-1 U_c^T), U = I^A S, D = S^T U (+ armature),
/// all in world axes about the base frame's origin (four-lane 3x3 blocks), and
/// Omega_0 = (I^A_0)^-1 by a root-free Cholesky factorisation.
/// `G_star(h)`: the inverse inertia a wrench on body i meets, outward along the path from the
/// base to h's body: from Omega_0, Omega_i = T_i Omega_parent T_i^T + S_i D_i^-1 S_i^T,
/// T_i = 1 - S_i D_i^-1 U_i^T (sums of positive terms: no cancellation), then
/// G* = R_h Omega R_h^T (eq. 5, 11) = J_full M_full^-1 J_full^T without any n x n matrix.
/// `velocityJump`: the impulse's bias forces from h's body to the base, the base's jump
/// -(I^A_0)^-1 p^A_0, and the joints' jumps outward.
/// Joints braked at the impact (setLocked) are fixed joints to all three: their bodies' articulated
/// inertias pass to the parent whole, the path skips them, their rate jumps are exactly 0.
/// Mimic joints: the recursion runs every joint free and imposes the k couplings by their Lagrange
/// multipliers (src/algorithm/mimic_coupling.hpp): k more passes per compute (per base kind), then
/// G_c = G - (J Y) S^-1 (J Y)^T and the jumps less the couplings' share; O(n k + k^3).
/// Compute calls return 0 or an Error code and never throw.
class KDL_SPACE_EXPORT RecursiveExIITSolver {
 public:
  explicit RecursiveExIITSolver(std::shared_ptr<const FloatingModel> model);
  ~RecursiveExIITSolver();
  RecursiveExIITSolver(const RecursiveExIITSolver&);
  RecursiveExIITSolver& operator=(const RecursiveExIITSolver&);
  const FloatingModel& model() const { return *model_; }

  /// \brief Joints braked at the impact (model order, size nj(); empty: none): each is treated as
  /// a fixed joint at its current position by compute, G and velocityJump (for FreeFloating and
  /// Grounded), so G is that of the partly locked system and their rate jumps are exactly 0. A
  /// set-up call (it may allocate); takes effect at the next compute(). \throws ModelError
  /// (naming the model's joints; the locks unchanged) for another size than nj() or 0.
  void setLocked(const std::vector<bool>& locked);
  /// The braked joints (model order, size nj(); all false unless setLocked says otherwise).
  const std::vector<bool>& locked() const { return locked_; }

  /// \brief Articulated-body inertias at the state of `kin` (forwardKinematics of this model).
  /// Keeps what its queries need; no reference to `kin`.
  /// \return 0, E_SIZE_MISMATCH (kin of another model), E_NOT_COMPUTED (kin not valid) or
  /// E_NOT_POSITIVE_DEFINITE.
  int compute(const Kinematics& kin);
  /// The same from a state: forwardKinematics into the solver's own Kinematics, then compute.
  /// \return also E_NOT_FINITE for a non-finite state.
  int compute(const State& state);
  /// Ex-IIT G* at h (world frame, twist per impulse), eq. 11.
  /// \return 0, E_NOT_COMPUTED, E_BAD_CONTACT (no such body), E_NOT_FINITE (offset, result).
  int G_star(const Contact& h, Matrix6d& G);
  /// \brief G at h for a response: FreeFloating is G* (eq. 11); Grounded is G = J H^-1 J^T
  /// (eq. 22) by the same recursion from a base of infinite inertia (Omega_0 = 0; singular where J
  /// is). JointsLocked is not this solver's (it needs no recursion: see MomentumSolver).
  /// \return as G_star, and E_BAD_ARGUMENT for JointsLocked or a value that is no enumerator.
  int G(const Contact& h, Response response, Matrix6d& G);
  /// \brief Velocity jump from an impulse wrench F on the robot at h (world frame): the change of
  /// the base twist (linear velocity of the base origin; angular velocity) and of the joint
  /// rates, M_full^-1 J_full^T F by one articulated-body pass (eq. 18). Grounded: the base does
  /// not move (eq. 23). \return 0, E_NOT_COMPUTED, E_BAD_CONTACT, E_SIZE_MISMATCH (dqdot),
  /// E_NOT_FINITE (F, offset, result), E_BAD_ARGUMENT (JointsLocked, no enumerator).
  int velocityJump(const Contact& h, const Vector6d& F, Vector6d& d_base_twist, KDL::JntArray& dqdot);
  int velocityJump(const Contact& h, Response response, const Vector6d& F, Vector6d& d_base_twist,
                   KDL::JntArray& dqdot);
  /// World pose of body i at the state of the last compute().
  KDL::Frame bodyPose(int i) const;

 private:
  /// 0, or the code of a contact query that cannot be answered.
  int ready(const Contact& h) const;
  /// The bodies from h.body to the base in path_ (root last; kept for the next query at the same
  /// body); returns the count.
  int walkPath(const Contact& h);

  std::shared_ptr<const FloatingModel> model_;
  Kinematics own_;                                 ///< for compute(State) only
  bool computed_ = false;
  std::vector<bool> locked_;                       ///< per joint: braked (setLocked)
  std::vector<char> moves_;                        ///< per body: a joint that moves (not fixed, not locked)
  Vector3d p_b_ = Vector3d::Zero();                ///< base origin: the common reference point
  std::vector<Matrix3d> R_;                        ///< per body: world rotation (copied from kin)
  std::vector<Vector3d> p_;                        ///< per body: world position of the frame origin
  std::vector<Vector6d> S_;                        ///< per body: unit joint twist at p_b (0 if fixed)
  /// per body: the sum of the articulated inertias (at p_b) of its children other than the next body
  std::vector<detail::LaneSymmetric6d> IA_;
  std::vector<char> far_children_;                 ///< per body: children other than the next body (summed in IA_)
  std::vector<char> first_far_child_;              ///< per body: its parent's far child done first (sets the sum)
  std::vector<Vector6d> U_;                        ///< per body: I^A S
  std::vector<double> Dinv_;                       ///< per body: 1 / D, D = S^T I^A S + armature (no division in the queries)
  Matrix6d Omega0_ = Matrix6d::Zero();            ///< (I^A_0)^-1
  std::vector<int> path_;                          ///< the path of body path_body_ to the base (walkPath)
  int path_body_ = -1, path_count_ = 0;
  std::vector<Vector6d> a_;                        ///< scratch: velocity jumps per body
  Eigen::VectorXd dq_;                             ///< scratch: joint-rate jumps (n)
  std::vector<double> Sp_;                         ///< scratch: S^T p, the bias force along the joint (zero off the path)
  std::vector<double> qb_;                         ///< scratch: joint-rate jumps per body (a mimic body's own)
  /// Mimic joints (none: rows() == 0): the couplings' responses for a free-floating and a grounded
  /// base (the latter made at its first query after a compute). A copy is a deep copy.
  struct Couplings {
    Couplings();
    Couplings(const Couplings& other);
    Couplings& operator=(const Couplings& other);
    ~Couplings();
    std::unique_ptr<detail::MimicCoupling> free, grounded;
  };
  Couplings couplings_;
  bool grounded_ready_ = false;
  /// The couplings' responses for `response`'s base at the last compute's state (once per compute).
  int couple(Response response);
};

}  // namespace kdl_space
