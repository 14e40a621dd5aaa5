// O(n) recursive Ex-IIT and impulse response: articulated-body inertias over the KDL tree
// (Featherstone's articulated-body algorithm with a floating base) instead of forming and
// factorising H*. Same results as the paper's dense formula (FreeFloatingSolver), which stays
// the second route in the tests.
#pragma once

#include <memory>
#include <vector>

#include "kdl_space/errors.hpp"
#include "kdl_space/model.hpp"
#include "kdl_space/spatial.hpp"
#include "kdl_space/state.hpp"

namespace kdl_space {

/// \brief G* at one contact point and the velocity jump of the whole robot from an impulse there,
/// in O(n) per state (plus O(depth of the contact) per contact), allocation-free after
/// construction.
///
/// `compute(state)`: forward kinematics and one backward pass of articulated-body inertias
/// I^A_i = I_i + sum over children (I^A_c - U_c D_c^-1 U_c^T), U = I^A S, D = S^T U (+ armature),
/// all in world axes about the base frame's origin (packed symmetric, Symmetric6d), and
/// Omega_0 = (I^A_0)^-1 by a root-free Cholesky factorisation.
/// `G_star(h)`: the inverse inertia a wrench on body i meets, outward along the path from the
/// base to h's body: from Omega_0, Omega_i = T_i Omega_parent T_i^T + S_i D_i^-1 S_i^T,
/// T_i = 1 - S_i D_i^-1 U_i^T (sums of positive terms: no cancellation), then
/// G* = R_h Omega R_h^T (eq. 5, 11) = J_full M_full^-1 J_full^T without any n x n matrix.
/// `velocityJump`: the impulse's bias forces from h's body to the base, the base's jump
/// -(I^A_0)^-1 p^A_0, and the joints' jumps outward.
/// Compute calls return 0 or an Error code and never throw.
class RecursiveExIITSolver {
 public:
  explicit RecursiveExIITSolver(std::shared_ptr<const FloatingModel> model);
  const FloatingModel& model() const { return *model_; }

  /// Forward kinematics and articulated-body inertias. \return 0, E_SIZE_MISMATCH, E_NOT_FINITE
  /// or E_NOT_POSITIVE_DEFINITE.
  int compute(const State& state);
  /// Ex-IIT G* at h (world frame, twist per impulse), eq. 11.
  int G_star(const Contact& h, Matrix6d& G);
  /// \brief Velocity jump from an impulse wrench F on the robot at h (world frame): the change of
  /// the base twist (linear velocity of the base origin; angular velocity) and of the joint
  /// rates, M_full^-1 J_full^T F by one articulated-body pass.
  int velocityJump(const Contact& h, const Vector6d& F, Vector6d& d_base_twist, KDL::JntArray& dqdot);
  /// World pose of body i after compute().
  KDL::Frame bodyPose(int i) const;

 private:
  /// Marks the bodies from h.body to the base in path_ (root last); returns the count.
  int walkPath(const Contact& h);

  std::shared_ptr<const FloatingModel> model_;
  bool computed_ = false;
  Vector3d p_b_ = Vector3d::Zero();                ///< base origin: the common reference point
  /// What compute() reads of one body, copied from the model once and packed together.
  /// Its joint's motion, from KDL's segment: pose(q) = screw(q) * pose(0), the screw about the
  /// joint's axis (revolute: rotation by scale q about the line through `point`; prismatic:
  /// translation by scale q), so that compute() needs no KDL call per body.
  /// Revolute, by Rodrigues' formula Rot(a, t) = E + sin t a^ + (1 - cos t) a^ a^ folded into
  /// pose(0): pose(q) = (R0 + s K1 + (1 - c) K2, p0 + s k1 + (1 - c) k2), t = scale q.
  struct LocalBody {
    int parent = -1, joint = -1;  ///< as Body
    int kind = 0;  ///< 0 fixed, 1 revolute, 2 prismatic
    Vector3d axis = Vector3d::UnitZ();  ///< parent frame
    double scale = 1.0;
    Matrix3d R0 = Matrix3d::Identity(), K1 = Matrix3d::Zero(), K2 = Matrix3d::Zero();  ///< parent frame
    Vector3d p0 = Vector3d::Zero(), k1 = Vector3d::Zero(), k2 = Vector3d::Zero();
    Vector3d twist_v = Vector3d::Zero(), twist_w = Vector3d::Zero();  ///< Body::joint_twist
    double mass = 0.0, armature = 0.0;
    Vector3d com = Vector3d::Zero();
    Matrix3d I_com = Matrix3d::Zero();
  };
  std::vector<LocalBody> local_;        ///< per body
  std::vector<Matrix3d> R_;             ///< per body: world rotation
  std::vector<Vector3d> p_;             ///< per body: world position of the frame origin
  std::vector<Vector6d> S_;                        ///< per body: unit joint twist at p_b (0 if fixed)
  std::vector<Symmetric6d> IA_;                    ///< per body: articulated inertia at p_b
  std::vector<Vector6d> U_;                        ///< per body: I^A S
  std::vector<double> D_;                          ///< per body: S^T I^A S + armature
  Symmetric6d Omega0_;                             ///< (I^A_0)^-1
  std::vector<int> path_;                          ///< scratch: contact path
  std::vector<Vector6d> a_;                        ///< scratch: velocity jumps per body
  std::vector<Vector6d> pa_;                       ///< scratch: bias force per body (one impulse)
};

}  // namespace kdl_space
