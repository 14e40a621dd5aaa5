// The whole of both systems before and after an impact: the impulse from impact.hpp applied to
// a free-floating robot (FloatingSide) and to what it hits (a rigid body or another
// free-floating robot), with momentum and energy accounting.
#pragma once

#include <Eigen/Cholesky>
#include <memory>
#include <vector>

#include "kdl_space/export.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/impact/impact.hpp"
#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/algorithm/momentum.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/spatial/response.hpp"
#include "kdl_space/multibody/state.hpp"

namespace kdl_space {

/// A free rigid body (the target): everything in the world frame.
struct RigidBody {
  double mass = 0.0;                           ///< [kg]
  Matrix3d I_com = Matrix3d::Identity();       ///< inertia about the CoM, world axes [kg m^2]
  Vector3d com = Vector3d::Zero();             ///< CoM position [m]
  Vector6d twist = Vector6d::Zero();           ///< (v of the CoM; w)
};

/// One side of an impact: its inverse inertia and contact twist before, and its state after an
/// impulse. Implemented for a free-floating robot and for a rigid body.
class KDL_SPACE_EXPORT ImpactSide {
 public:
  virtual ~ImpactSide() = default;
  /// Inverse inertia at the contact point (G*, G, or G_B), twist per impulse.
  virtual const Matrix6d& G() const = 0;
  /// Twist of the side's material point at the contact point, before / after the impulse.
  virtual const Vector6d& contactTwistBefore() const = 0;
  virtual Vector6d contactTwistAfter() const = 0;
  /// Linear momentum and angular momentum about the world origin, before / after.
  virtual Vector6d momentumBefore() const = 0;
  virtual Vector6d momentumAfter() const = 0;
  /// Kinetic energy before / after [J].
  virtual double energyBefore() const = 0;
  virtual double energyAfter() const = 0;
  /// \brief Applies the impulse wrench F received by this side at the contact point: the state
  /// after becomes the state before plus the jump from F (a second call replaces the first).
  /// \return 0 or an Error code (E_NOT_FINITE for a non-finite F or a jump that overflows); on an
  /// error the state after is untouched. Never throws.
  virtual int applyImpulse(const Vector6d& F) = 0;
};

/// How a free-floating side computes G* and its velocity jump.
enum class ExIITMethod {
  Recursive,  ///< O(n) articulated-body recursion (RecursiveExIITSolver): the default, faster
  Dense,      ///< the paper's J* H*^-1 J*^T + R_h M_a^-1 R_h^T with a factorised H* (eq. 11)
};

/// A free-floating system at one instant, touching at one contact point: what a FloatingSide is
/// built from (and one side of a CaptureProblem).
struct FloatingSystem {
  std::shared_ptr<const FloatingModel> model;
  State state;                 ///< base pose and joint positions
  FloatingVelocity velocity;   ///< base twist (of the base origin) and joint rates
  Contact contact;             ///< where it touches
  Response response = Response::FreeFloating;  ///< free, grounded or joints locked
  /// Joints braked at the impact (model order, size model->nj(); empty: none): the system's G is
  /// that of the partly locked system and their rates stay 0 (they must be 0 before). With
  /// Response::JointsLocked every joint is braked anyway.
  std::vector<bool> locked;
};

/// \brief A free-floating robot (or grounded, or with locked joints) as an impact side.
///
/// The side owns what it answers from: the model (shared), its state and velocity, its
/// kinematics (computed in the constructor, or handed to it) and its own solvers, computed once
/// in the constructor; nothing a caller does later can make it stale. With ExIITMethod::Recursive (the default) every step is O(n): G* or the
/// grounded G and the velocity jump by the articulated-body recursion, the locked G, momentum,
/// energy and twists by MomentumSolver; no n x n matrix is built. A model with mimic joints
/// always takes the dense route (the recursion cannot couple joints). ExIITMethod::Dense uses the
/// paper's formulas (FreeFloatingSolver) for G and the velocity jump. Braked joints (`locked`)
/// are fixed joints to both routes (on the dense one a braked mimic leader brakes its followers).
class KDL_SPACE_EXPORT FloatingSide : public ImpactSide {
 public:
  /// \throws ModelError (a set-up call) if the model is null, the state or velocity has the
  /// wrong size or is not finite, the contact is no body of the model or its offset is not
  /// finite, `response` or `method` is no enumerator, the response is unavailable (grounded
  /// with a singular H), `locked` has another size than nj() (or 0), or a braked joint's rate
  /// before is not 0 (named). The message starts with "FloatingSide: ".
  /// \param locked joints braked at the impact (FloatingSystem::locked).
  FloatingSide(std::shared_ptr<const FloatingModel> model, const State& state, const Contact& h,
               const FloatingVelocity& before, Response response = Response::FreeFloating,
               ExIITMethod method = ExIITMethod::Recursive, std::vector<bool> locked = {});
  /// \brief The same from the kinematics of the side's state, already computed by
  /// forwardKinematics for `model` (the side keeps them: it owns its state). \throws ModelError
  /// as above, or if `kin` is not a successful forwardKinematics of `model`.
  FloatingSide(std::shared_ptr<const FloatingModel> model, Kinematics kin, const Contact& h,
               const FloatingVelocity& before, Response response = Response::FreeFloating,
               ExIITMethod method = ExIITMethod::Recursive, std::vector<bool> locked = {});
  explicit FloatingSide(const FloatingSystem& system, ExIITMethod method = ExIITMethod::Recursive);
  ~FloatingSide() override;

  /// \brief The same side at another state and velocity (same model, contact, response and
  /// method and braked joints), reusing its solvers and workspaces: a compute call,
  /// allocation-free, that never throws. \return 0, or the code of the part that refused
  /// (E_SIZE_MISMATCH, E_NOT_FINITE, E_NOT_POSITIVE_DEFINITE, E_BAD_ARGUMENT for a braked joint
  /// whose rate is not 0...); on an error the side answers nothing (applyImpulse returns
  /// E_NOT_COMPUTED) until a successful reset.
  int reset(const State& state, const FloatingVelocity& before);

  const Matrix6d& G() const override { return G_; }
  const Vector6d& contactTwistBefore() const override { return t_before_; }
  Vector6d contactTwistAfter() const override { return t_after_; }
  Vector6d momentumBefore() const override { return h_before_; }
  Vector6d momentumAfter() const override { return h_after_; }
  double energyBefore() const override { return T_before_; }
  double energyAfter() const override { return T_after_; }
  int applyImpulse(const Vector6d& F) override;

  const FloatingModel& model() const { return *model_; }
  const std::shared_ptr<const FloatingModel>& sharedModel() const { return model_; }
  const State& state() const { return kin_.state; }
  /// The side's kinematics (world poses of every body at its state).
  const Kinematics& kinematics() const { return kin_; }
  const Contact& contact() const { return h_; }
  Response response() const { return response_; }
  /// The joints braked at the impact (model order, size nj(); all false if none).
  const std::vector<bool>& locked() const { return locked_; }
  /// World position of the contact point.
  Vector3d contactPoint() const { return kin_.point(h_); }
  const FloatingVelocity& before() const { return before_; }
  /// The base twist and joint rates after the last applyImpulse (before it: equal to before()).
  const FloatingVelocity& after() const { return after_; }
  /// Locked twist at the system CoM before / after: (v_g; w_g) = M_a^-1 (P_g; L_g).
  const Vector6d& centroidTwistBefore() const { return v_g_before_; }
  const Vector6d& centroidTwistAfter() const { return v_g_after_; }

 private:
  std::shared_ptr<const FloatingModel> model_;
  Kinematics kin_;
  MomentumSolver momentum_;
  std::unique_ptr<RecursiveExIITSolver> recursive_;  ///< ExIITMethod::Recursive, free or grounded
  std::unique_ptr<FreeFloatingSolver> dense_;        ///< ExIITMethod::Dense, free or grounded
  Contact h_;
  Response response_;
  std::vector<bool> locked_;  ///< per joint: braked (size nj())
  Matrix6d G_;
  FloatingVelocity before_, after_;
  Vector6d h_before_, h_after_, t_before_, t_after_, v_g_before_, v_g_after_;
  double T_before_ = 0.0, T_after_ = 0.0;
  /// The state before: momentum, energy, G and twists of kin_ and before_ (the constructor's and
  /// reset's common part); `stage` names the part that refused.
  int prepare(const char*& stage);
  bool ready_ = false;
  Vector3d r_gh_ = Vector3d::Zero();         ///< contact point from the system CoM
  Eigen::LLT<Matrix3d> I_g_llt_;             ///< the locked inertia about the CoM, factorised
  Vector6d d_base_ = Vector6d::Zero();  ///< workspace
  KDL::JntArray dqdot_;      ///< workspace
  FloatingVelocity trial_;   ///< workspace: the state after, until it is known to be good
};

/// \brief A rigid body as an impact side, touched at a world point.
class KDL_SPACE_EXPORT RigidBodySide : public ImpactSide {
 public:
  /// \throws ModelError (a set-up call) if the mass is not a finite value > 0, the inertia is not
  /// symmetric positive definite, or an input is not finite. The message starts with "target: ".
  RigidBodySide(const RigidBody& body, const Vector3d& contact_point);

  const Matrix6d& G() const override { return G_; }
  const Vector6d& contactTwistBefore() const override { return t_before_; }
  Vector6d contactTwistAfter() const override;
  Vector6d momentumBefore() const override { return momentum(body_.twist); }
  Vector6d momentumAfter() const override { return momentum(twist_after_); }
  double energyBefore() const override { return energy(body_.twist); }
  double energyAfter() const override { return energy(twist_after_); }
  int applyImpulse(const Vector6d& F) override;

  /// Twist at the CoM before / after.
  const Vector6d& twistBefore() const { return body_.twist; }
  const Vector6d& twistAfter() const { return twist_after_; }

 private:
  Vector6d momentum(const Vector6d& twist) const;
  double energy(const Vector6d& twist) const;
  RigidBody body_;
  Vector3d r_bc_;
  Matrix6d G_;
  Vector6d t_before_, twist_after_;
};

/// Which part of collide() refused, for a message that names it.
enum class ImpactFault {
  None,   ///< no error
  Law,    ///< solveImpact: the law's parameters, or G_A + G_B (see solveImpact)
  SideA,  ///< A refused the impulse F (A.applyImpulse)
  SideB,  ///< B refused the impulse -F (B.applyImpulse)
};

/// \brief Solves the impact between A (the robot) and B (the target) with `law` (the checked
/// solveImpact), and applies the impulse: F to A, -F to B. Afterwards each side reports its state
/// after. Never throws.
/// \param impulse the impulse on A; untouched on an error
/// \param fault if not null, set to the part that refused (ImpactFault::None on success)
/// \return 0, or the code of the part that refused. On an error neither side keeps the impulse:
/// if B refuses it, A is reset to its state before (as by A.applyImpulse of a zero impulse).
KDL_SPACE_EXPORT int collide(ImpactSide& A, ImpactSide& B, const ImpactLaw& law, Impulse& impulse, ImpactFault* fault = nullptr);

}  // namespace kdl_space
