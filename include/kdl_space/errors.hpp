// Error codes of the compute calls (KDL::SolverI style; our own codes are <= -101) and the
// exception thrown by constructors and loaders.
#pragma once

#include <kdl/solveri.hpp>
#include <stdexcept>
#include <string>

namespace kdl_space {

/// Return codes of compute calls. 0 and KDL's codes (e.g. KDL::SolverI::E_SIZE_MISMATCH = -4)
/// keep their KDL meaning; ours start at -101.
enum Error : int {
  E_NOERROR = KDL::SolverI::E_NOERROR,
  E_SIZE_MISMATCH = KDL::SolverI::E_SIZE_MISMATCH,
  E_NOT_COMPUTED = -101,          ///< compute(state) has not succeeded yet
  E_NOT_FINITE = -102,            ///< an input holds NaN or an infinity
  E_NOT_POSITIVE_DEFINITE = -103, ///< H* (or, for the grounded G, H) failed its factorisation
  E_BAD_CONTACT = -104,           ///< a contact refers to no body of this model
  E_MAX_STEPS = -105,             ///< a simulation spent its step budget (SimulationOptions::max_steps)
};

/// Human-readable text of a return code.
const char* strError(int code);

/// Thrown by constructors and loaders when a model or an input cannot be used. The message
/// names the file, the link or joint, and what is wrong.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace kdl_space
