#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

const char* strError(int code) {
  switch (code) {
    case E_NOERROR: return "no error";
    case E_SIZE_MISMATCH: return "the size of an input or output does not match the model";
    case E_NOT_COMPUTED: return "compute(state) has not succeeded for this solver";
    case E_NOT_FINITE: return "an input holds NaN or infinite values, or a result overflowed";
    case E_NOT_POSITIVE_DEFINITE: return "an inertia matrix is not positive definite";
    case E_BAD_CONTACT: return "the contact refers to no body of this model";
    case E_MAX_STEPS: return "the simulation spent its step budget (is a controller unstable?)";
    case E_BAD_ARGUMENT: return "a parameter is out of its range";
    case E_STEP_UNDERFLOW: return "the adaptive step size fell to round-off (a stiff or singular motion)";
    case E_CANCELLED: return "cancelled by the caller";
    default: return "unknown error";
  }
}

// Out of line: one vtable and one type_info per exception, so that a catch in a program matches
// what the shared library throws.
Error::~Error() = default;
ModelError::~ModelError() = default;
InputError::~InputError() = default;
Cancelled::~Cancelled() = default;

void Error::rethrowWithContext(const std::string& context) const { std::rethrow_exception(renamed(context + what())); }

std::exception_ptr Error::renamed(const std::string& what) const { return std::make_exception_ptr(Error(what)); }
std::exception_ptr ModelError::renamed(const std::string& what) const { return std::make_exception_ptr(ModelError(what)); }
std::exception_ptr InputError::renamed(const std::string& what) const { return std::make_exception_ptr(InputError(what)); }
std::exception_ptr Cancelled::renamed(const std::string& what) const { return std::make_exception_ptr(Cancelled(what)); }

}  // namespace kdl_space
