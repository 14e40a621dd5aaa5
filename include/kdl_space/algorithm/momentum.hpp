// Momentum, kinetic energy and twists of a free-floating system from its kinematics and its
// velocity, in O(n) (no n x n matrix): what an impact side and the simulator need per state.
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/export.hpp"
#include "kdl_space/multibody/kinematics.hpp"

namespace kdl_space {

/// \brief Velocity-dependent whole-system quantities of a FloatingModel at one state, in O(n):
/// the twist of every body, the total momentum (eq. 2), the kinetic energy, the locked twist at
/// the CoM (v_g; w_g) = M_a^-1 (P_g; L_g), the twist of any contact point (eq. 4), and the
/// inverse map: the base twist that gives a momentum with given joint rates. The same numbers
/// as FreeFloatingSolver's dense momentum / kineticEnergy / handTwist / baseTwist (the tests'
/// second route). Workspaces are sized in the constructor; compute calls allocate nothing and
/// never throw. The solver keeps what its queries need (no reference to the Kinematics).
class KDL_SPACE_EXPORT MomentumSolver {
 public:
  explicit MomentumSolver(std::shared_ptr<const FloatingModel> model);
  const FloatingModel& model() const { return *model_; }

  /// \brief Body twists, momentum, energy, centroid terms at the state of `kin` with velocity v.
  /// \return 0, E_SIZE_MISMATCH (kin of another model, v.qdot), E_NOT_COMPUTED (kin not valid),
  /// E_NOT_FINITE (v, or a result that overflows), E_NOT_POSITIVE_DEFINITE (I_g).
  int compute(const Kinematics& kin, const FloatingVelocity& v);

  // --- Results of the last compute() (world frame) ------------------------------------------
  /// Total momentum (P; L about the world origin).
  const Vector6d& momentum() const { return h_O_; }
  /// Total momentum (P_g; L_g about the system CoM r_g), eq. 2.
  const Vector6d& momentumAtCoM() const { return PL_g_; }
  /// Kinetic energy [J].
  /// Kinetic energy [J], the rotors' (1/2 armature qdot^2) included, as in the dense H.
  double kineticEnergy() const { return T_; }
  /// Locked twist at the CoM: (v_g; w_g) = M_a^-1 (P_g; L_g) (eq. 12).
  const Vector6d& centroidTwist() const { return v_g_; }
  /// System CoM r_g and locked inertia about it I_g (eq. 3).
  const Vector3d& r_g() const { return r_g_; }
  const Matrix3d& I_g() const { return I_g_; }
  /// Twist of the material point of body h.body at h (v at the contact point; w), eq. 4.
  /// \return 0, E_NOT_COMPUTED, E_BAD_CONTACT, E_NOT_FINITE (offset).
  int contactTwist(const Contact& h, Vector6d& t_h) const;
  /// Locked G = R_h M_a^-1 R_h^T at h (eq. 20): the whole system as one rigid body.
  int G_locked(const Contact& h, Matrix6d& G) const;

  /// \brief The base twist (of the base origin) that gives total momentum h_O (P; L about the
  /// world origin) with joint rates qdot at the state of `kin`; needs no compute().
  /// \return 0, E_SIZE_MISMATCH, E_NOT_COMPUTED (kin), E_NOT_FINITE, E_NOT_POSITIVE_DEFINITE.
  int baseTwist(const Kinematics& kin, const Vector6d& h_O, const KDL::JntArray& qdot, KDL::Twist& base_twist);

 private:
  /// Twists at p_b of every body from a base twist at p_b and joint rates (V_), and
  /// sum_i I_i V_i (about p_b) and sum_i V_i^T I_i V_i; I_tot_ = sum_i I_i (about p_b).
  void sweep(const Kinematics& kin, const Vector6d& V_b, const Eigen::VectorXd& qdot, Vector6d& h_b, double& twoT);

  std::shared_ptr<const FloatingModel> model_;
  bool computed_ = false;
  std::vector<Vector6d> V_;        ///< per body: twist at p_b
  std::vector<Matrix3d> R_;        ///< per body: world rotation (for contact points)
  std::vector<Vector3d> p_;        ///< per body: world position
  Vector3d p_b_ = Vector3d::Zero();
  Matrix6d I_tot_ = Matrix6d::Zero();  ///< locked spatial inertia about p_b
  Vector6d h_O_ = Vector6d::Zero(), PL_g_ = Vector6d::Zero(), v_g_ = Vector6d::Zero();
  Vector3d r_g_ = Vector3d::Zero();
  Matrix3d I_g_ = Matrix3d::Zero();
  double T_ = 0.0;
};

}  // namespace kdl_space
