// The free-floating quantities of Yoshida et al. (MATH.md): centroid terms, J*, H*, G*.
#pragma once

#include <Eigen/Cholesky>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
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

/// \brief Up to this many joints the commands form the n x n matrices (H, H*, their
/// factorisations and eigenvalues: O(n^2) memory, O(n^3) time); above it they take the O(n)
/// routes (RecursiveExIITSolver, FreeFloatingSolver::Extent::Jacobians) and say so (note
/// `large_model`), so that a robot of thousands of links is checked in linear time.
constexpr unsigned int kDenseJoints = 400;

/// \brief Computes, for one state of a FloatingModel, the centroid terms (w, r_g, I_g, M_a,
/// A_m), the fixed-base H and the generalized inertia H* (eq. 7), and at any contact point the
/// fixed-base J, the generalized Jacobian J* (eq. 4), the Ex-IIT G* (eq. 11), the grounded
/// G = J H^-1 J^T (eq. 22) and the locked R_h M_a^-1 R_h^T (eq. 20).
///
/// Usage: `compute(kin)` once per state (a composite-rigid-body pass over the kinematics of
/// forwardKinematics, factorisation of H* and H; `compute(state)` runs forwardKinematics into the
/// solver's own Kinematics first), then any number of contact queries, which read the result of
/// the last successful `compute` (the solver keeps what they need: no reference to `kin`). Every vector and matrix is in the world
/// frame; twists are (v; w), wrenches (f; n). Compute calls never throw: they return 0 or an
/// Error code (errors.hpp) and leave their outputs untouched on an error. Every query returns
/// E_NOT_COMPUTED before a successful compute(); a contact query returns E_BAD_CONTACT for a
/// body index outside bodies() and E_NOT_FINITE for a non-finite offset; a joint-indexed input
/// or output of the wrong size gives E_SIZE_MISMATCH, a NaN or infinite input E_NOT_FINITE, and
/// so does a result that overflows. Workspaces are sized in the constructor; contact queries use
/// them, so one solver serves one thread (build one per thread: the model is shared).
///
/// The accessors that take an index (bodyPose, S, bodyInertia) are not checked: the index must
/// lie in [0, bodies().size()) or [0, nj()).
class KDL_SPACE_EXPORT FreeFloatingSolver {
 public:
  /// \brief What compute() forms.
  enum class Extent {
    /// Everything above (H, H*, both factorised).
    Full,
    /// The centroid terms and A_m only, in O(n * depth) time and O(n) memory (no n x n matrix is
    /// ever allocated): contactPoint, R_h, J, J*, G_locked, momentum, baseTwist and handTwist
    /// answer; H() and H_star() are empty (0 x 0); G_star, G_grounded, G (but JointsLocked),
    /// velocityJump (but JointsLocked) and kineticEnergy return E_NOT_COMPUTED; compute()
    /// returns E_NOT_POSITIVE_DEFINITE only for a singular I_g. For the callers that need J* alone
    /// (a configuration's conditioning, inverse kinematics, the approach's control law).
    Jacobians
  };
  explicit FreeFloatingSolver(std::shared_ptr<const FloatingModel> model, Extent extent = Extent::Full);
  Extent extent() const { return extent_; }

  const FloatingModel& model() const { return *model_; }
  const std::shared_ptr<const FloatingModel>& sharedModel() const { return model_; }

  /// \brief Joints braked at the impact (model order, size nj(); empty: none). G_star, G_grounded,
  /// G (FreeFloating, Grounded) and velocityJump then answer for the partly locked system: the
  /// braked coordinates removed, G* = J*_f H*_ff^-1 J*_f^T + R_h M_a^-1 R_h^T and
  /// G = J_f H_ff^-1 J_f^T with f the free joints; their rate jumps are exactly 0 (a mimic
  /// joint follows its leader's coordinate: braked with it). The accessors (H, H*, A_m, J, J*)
  /// and momentum, energy, handTwist stay those of the whole model. A set-up call (it may
  /// allocate); takes effect at the next compute(). \throws ModelError (naming the model's
  /// joints; the locks unchanged) for another size than nj() or 0.
  void setLocked(const std::vector<bool>& locked);
  /// The braked joints (model order, size nj(); all false unless setLocked says otherwise).
  const std::vector<bool>& locked() const { return locked_; }

  /// \brief Centroid terms, H, A_m, H* at the state of `kin`; factorises H* and H.
  /// \return E_NOERROR, E_SIZE_MISMATCH (kin of another model), E_NOT_COMPUTED (kin not valid),
  /// E_NOT_FINITE (a state so far away that the centroid terms overflow), or
  /// E_NOT_POSITIVE_DEFINITE if H* is not. On any error the previous result is discarded: every
  /// query returns E_NOT_COMPUTED until the next successful compute().
  int compute(const Kinematics& kin);
  /// The same from a state: forwardKinematics into the solver's own Kinematics, then compute.
  /// \return also E_SIZE_MISMATCH (q) and E_NOT_FINITE (q or the base pose).
  int compute(const State& state);

  // --- Results of the last compute() (world frame) ------------------------------------------
  /// Total mass w [kg].
  double w() const { return model_->totalMass(); }
  /// System CoM r_g [m].
  const Vector3d& r_g() const { return r_g_; }
  /// Locked inertia about the CoM, I_g (eq. 3) [kg m^2].
  const Matrix3d& I_g() const { return I_g_; }
  /// Centroid inertia M_a = diag(w E, I_g) (eq. 12).
  const Matrix6d& M_a() const { return M_a_; }
  /// Momentum about r_g produced by unit joint rates with the base still (6 x n).
  const Matrix6Xd& A_m() const { return A_m_; }
  /// Fixed-base joint-space inertia H (n x n), armature included.
  const KDL::JntSpaceInertiaMatrix& H() const { return H_; }
  /// Generalized inertia H* = H - A_m^T M_a^-1 A_m (eq. 7).
  const KDL::JntSpaceInertiaMatrix& H_star() const { return H_star_; }
  /// The state of the last successful compute().
  const State& state() const { return state_; }
  /// World pose of body i (model().bodies() order).
  const KDL::Frame& bodyPose(int i) const { return world_T_body_[i]; }
  /// Unit twist of joint j (model order), world frame, at the point r_g.
  const Vector6d& S(int j) const { return Sb_[model_->jointBody()[j]]; }
  /// The twist of body i's joint per unit rate of its coordinate (a mimic joint's multiplier
  /// included; zero for a fixed joint and the base), world frame, at r_g.
  const Vector6d& bodyJointTwist(int i) const { return Sb_[i]; }
  /// Spatial inertia of body i alone, world frame, about the point r_g.
  const Matrix6d& bodyInertia(int i) const { return I_body_[i]; }
  /// Whether H is positive definite (false: the grounded G is unavailable).
  bool groundedAvailable() const { return H_ok_; }

  // --- Momentum (eq. 2) ----------------------------------------------------------------------
  /// \brief Total momentum (P_g; L_g), angular part about r_g, from the base twist (linear
  /// velocity of the base frame's origin, angular velocity) and the joint rates.
  int momentum(const KDL::Twist& base_twist, const KDL::JntArray& qdot, Vector6d& PL_g) const;
  /// \brief Inverse of momentum(): the base twist that gives momentum (P_g; L_g) with rates qdot.
  int baseTwist(const Vector6d& PL_g, const KDL::JntArray& qdot, KDL::Twist& base_twist) const;
  /// \brief Kinetic energy of the whole system, 1/2 [y; qdot]^T [[M_a, A_m], [A_m^T, H]] [y; qdot].
  int kineticEnergy(const KDL::Twist& base_twist, const KDL::JntArray& qdot, double& T) const;

  // --- One contact point h ---------------------------------------------------------------------
  /// World position p_h of the contact point.
  int contactPoint(const Contact& h, Vector3d& p_h) const;
  /// R_h = [[E, -skew(r_gh)], [0, E]], r_gh = p_h - r_g (eq. 5).
  int R_h(const Contact& h, Matrix6d& R) const;
  /// Fixed-base Jacobian J of h (6 x n; base held still).
  int J(const Contact& h, KDL::Jacobian& J);
  /// Generalized Jacobian J* = J - R_h M_a^-1 A_m (eq. 4).
  int J_star(const Contact& h, KDL::Jacobian& J_star);
  /// Ex-IIT G* = J* H*^-1 J*^T + R_h M_a^-1 R_h^T (eq. 11).
  int G_star(const Contact& h, Matrix6d& G);
  /// Grounded G = J H^-1 J^T (eq. 22); singular where J is (see spectralFigures()).
  int G_grounded(const Contact& h, Matrix6d& G);
  /// Locked G = R_h M_a^-1 R_h^T (eq. 20): the whole system as one rigid body.
  int G_locked(const Contact& h, Matrix6d& G) const;
  /// Twist of h from joint rates and momentum: t_h = J* qdot + R_h M_a^-1 (P_g; L_g) (eq. 4).
  int handTwist(const Contact& h, const KDL::JntArray& qdot, const Vector6d& PL_g,
                KDL::Twist& t_h);

  // --- Impulses (section 4) -------------------------------------------------------------------
  /// \brief The inverse inertia seen at h for a response: G*, the grounded G or the locked G.
  /// \return as the three calls; E_BAD_ARGUMENT for a value of `response` that is no enumerator.
  int G(const Contact& h, Response response, Matrix6d& G);
  /// \brief Velocity jump from an impulse wrench F (on the robot, at h, world frame):
  /// FreeFloating: dqdot = H*^-1 J*^T F, d(P_g; L_g) = R_h^T F (eq. 8, 18);
  /// Grounded: dqdot = H^-1 J^T F, no momentum change of the base (the ground takes it);
  /// JointsLocked: dqdot = 0, d(P_g; L_g) = R_h^T F.
  /// \return 0, E_SIZE_MISMATCH (dqdot), E_NOT_FINITE (F), E_NOT_POSITIVE_DEFINITE (grounded with
  /// a singular H), E_BAD_ARGUMENT (`response` no enumerator), or a contact query's code.
  int velocityJump(const Contact& h, Response response, const Vector6d& F, Vector6d& dPL_g,
                   KDL::JntArray& dqdot);

  // --- Several contact points (dual-arm) -------------------------------------------------------
  /// \brief The 6k x 6k G* over contacts h_1..h_k: blocks
  /// G*_ij = J*_i H*^-1 J*_j^T + R_i M_a^-1 R_j^T (eq. 11), one factorisation of H* for all.
  /// G must be sized 6k x 6k by the caller (else E_SIZE_MISMATCH). Allocation-free for up to the
  /// reserved number of contacts (2 by default, see reserveContacts).
  int G_star(const std::vector<Contact>& contacts, Eigen::MatrixXd& G);
  /// Sizes the multi-contact workspace for k contacts (allocates; call before the loop).
  void reserveContacts(std::size_t k);

 private:
  int ready(const Contact& h) const;
  /// ready(h), and E_NOT_COMPUTED for a query that needs H or H* under Extent::Jacobians.
  int readyDense(const Contact& h) const;
  /// Keeps the state of a successful compute and marks the result ready.
  int finish(const State& state);
  /// Fixed-base Jacobian of h into J (6 x n, sized).
  void fixedBaseJacobian(const Contact& h, Eigen::Ref<Matrix6Xd> J) const;
  /// J* of h into J_star (6 x n, sized), eq. 4.
  void generalizedJacobian(const Contact& h, Eigen::Ref<Matrix6Xd> J_star) const;
  /// Zeroes the columns of the braked joints (J_f, J*_f with the locked columns 0).
  void dropLocked(Eigen::Ref<Matrix6Xd> J) const;
  /// x <- M_a^-1 x for a 6-row block (M_a is block diagonal: 1/w and a factorised I_g).
  void M_a_solveInPlace(Eigen::Ref<Matrix6Xd> x) const;

  std::shared_ptr<const FloatingModel> model_;
  Extent extent_ = Extent::Full;
  Kinematics own_;  ///< for compute(State) only
  bool computed_ = false;
  bool H_ok_ = false;
  std::vector<bool> locked_;     ///< per joint: braked (setLocked)
  bool any_locked_ = false;
  Eigen::MatrixXd H_locked_work_;  ///< H or H* with the braked rows and columns made those of the identity (n x n)
  KDL::Frame world_T_base_;
  State state_;                           ///< copy of the last computed state
  std::vector<KDL::Frame> world_T_body_;  ///< per body
  std::vector<Vector6d> Sb_;              ///< per body: its joint's twist per coordinate rate at r_g
  std::vector<Matrix6d> I_body_;          ///< per body: its spatial inertia about r_g
  std::vector<Matrix6d> I_c_;             ///< per body: composite spatial inertia about r_g
  Vector3d r_g_ = Vector3d::Zero();
  Matrix3d I_g_ = Matrix3d::Zero();
  Matrix6d M_a_ = Matrix6d::Zero();
  Eigen::LLT<Matrix3d> I_g_llt_;
  Matrix6Xd A_m_;
  Matrix6Xd Am_work_;           ///< M_a^-1 A_m (6 x n), kept from compute()
  KDL::JntSpaceInertiaMatrix H_, H_star_;
  Eigen::LLT<Eigen::MatrixXd> H_star_llt_, H_llt_;
  Matrix6Xd J_work_;            ///< contact-query workspace (6 x n)
  Eigen::MatrixXd X_work_;      ///< H^-1 J^T workspace (n x 6)
  Eigen::VectorXd dqdot_work_;  ///< velocityJump's joint-rate jump before it is returned (n)
  Eigen::MatrixXd J_all_work_, X_all_work_, G_all_work_;  ///< multi-contact workspaces (6k x n, n x 6k, 6k x 6k)
  std::vector<Matrix6d> R_all_work_;         ///< multi-contact R_h per contact
};

}  // namespace kdl_space
