// Error codes of the compute calls (KDL::SolverI style; our own codes are <= -101) and the
// exceptions thrown by constructors, loaders and set-up calls.
//
// The rule, for every class and free function of the library:
//  - Compute calls (everything called per state, per contact, per impulse or per step:
//    FreeFloatingSolver's queries, RecursiveExIITSolver, ForwardDynamicsSolver::CartToJnt,
//    Simulator::run / engageBrakes / energyAndMomentum, solveImpact, ImpactSide::applyImpulse,
//    FloatingSide::reset, collide) never throw. They check the sizes of their inputs and outputs,
//    the finiteness of their inputs and the range of their parameters, and return 0 (E_NOERROR) or
//    one of the codes below. On an error their outputs are left untouched (Simulator::run
//    documents its state argument). A result that overflows (finite inputs of absurd magnitude) is
//    reported as E_NOT_FINITE, never returned.
//  - Set-up calls throw and return nothing to check: constructors, loaders and the calls that
//    configure an object before its compute calls (FloatingModel, loadUrdfFile/String,
//    jointsByName, the solvers' setLocked and setGravity, FloatingSide, RigidBodySide, Simulator
//    and its setJointControl / setLimitMode / setBaseControl / addWrench, loadScenario,
//    solveCapture, loadStudy). They throw ModelError for a model or an object that cannot be
//    built as asked (a URDF, a joint, a size, a value), and InputError for an input file or a
//    field of a problem (a scenario's line and field, a capture problem's part); the message
//    names the file, field, link or joint, and what is wrong. They run once, before any loop,
//    and an object they cannot build must not exist.
//  - Both derive from Error. An error keeps its kind on the way up: a caller that knows more (the
//    scenario's file and field) puts it in front of the message with rethrowWithContext, which
//    throws the same type again; nothing converts a ModelError into an InputError or back. A
//    caller that reports both alike catches Error.
// Callbacks that the caller hands to a compute call (Simulator's torque callback and observer)
// are the caller's code: an exception they throw propagates unchanged.
#pragma once

#include <exception>
#include <kdl/solveri.hpp>
#include <stdexcept>
#include <string>

#include "kdl_space/export.hpp"

namespace kdl_space {

/// Return codes of compute calls. 0 and KDL's codes (e.g. KDL::SolverI::E_SIZE_MISMATCH = -4)
/// keep their KDL meaning; ours start at -101.
enum ErrorCode : int {
  E_NOERROR = KDL::SolverI::E_NOERROR,
  E_SIZE_MISMATCH = KDL::SolverI::E_SIZE_MISMATCH,
  E_NOT_COMPUTED = -101,          ///< compute(state) has not succeeded yet
  E_NOT_FINITE = -102,            ///< an input holds NaN or an infinity, or a result overflowed
  E_NOT_POSITIVE_DEFINITE = -103, ///< H* (or, for the grounded G, H; G_A + G_B for an impact) failed its factorisation
  E_BAD_CONTACT = -104,           ///< a contact refers to no body of this model
  E_MAX_STEPS = -105,             ///< a simulation spent its step budget (SimulationOptions::max_steps)
  E_BAD_ARGUMENT = -106,          ///< a parameter is out of its range (impact law, time span, enum value)
  E_STEP_UNDERFLOW = -107,        ///< the adaptive step size fell to round-off of the time
  E_CANCELLED = -108,             ///< the caller's cancel poll asked a run to stop (Simulator::setCancelPoll)
};

/// Human-readable text of a return code.
KDL_SPACE_EXPORT const char* strError(int code);

/// \brief The base of the library's exceptions (ModelError, InputError): what a set-up call
/// throws. Catch it to report both kinds alike; Python's kdl_space.Error is its binding.
class KDL_SPACE_EXPORT Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  ~Error() override;
  /// \brief Throws an error of this one's own type (ModelError stays ModelError) whose message is
  /// `context` + what(): how a caller adds the file or field it knows, e.g.
  /// `catch (const Error& e) { e.rethrowWithContext(path + ": "); }`.
  [[noreturn]] void rethrowWithContext(const std::string& context) const;

 protected:
  /// An error of this one's own type with message `what` (each subclass says its type).
  virtual std::exception_ptr renamed(const std::string& what) const;
};

/// Thrown by constructors, loaders and set-up calls when a model or an object cannot be built as
/// asked (a URDF, a joint, a size, a value). The message names the file, the link or joint, and
/// what is wrong.
class KDL_SPACE_EXPORT ModelError : public Error {
 public:
  using Error::Error;
  ~ModelError() override;

 protected:
  std::exception_ptr renamed(const std::string& what) const override;
};

/// Thrown by the scenario and study loaders and the capture set-up when an input (a file, a
/// field, a value) cannot be used: the message names the file, the field (e.g. "target.mass")
/// and what is wrong.
class KDL_SPACE_EXPORT InputError : public Error {
 public:
  using Error::Error;
  ~InputError() override;

 protected:
  std::exception_ptr renamed(const std::string& what) const override;
};

/// Thrown by a set-up call whose caller's cancel poll asked it to stop (IkOptions::cancelled: a
/// Ctrl-C): nothing it would have returned was computed. The message says where it stopped.
class KDL_SPACE_EXPORT Cancelled : public Error {
 public:
  using Error::Error;
  ~Cancelled() override;

 protected:
  std::exception_ptr renamed(const std::string& what) const override;
};

}  // namespace kdl_space
