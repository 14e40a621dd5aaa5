#include "kdl_space/multibody/diagnostics.hpp"

#include "spatial/message_text.hpp"

namespace kdl_space {

std::string describe(const Finding& f) {
  switch (f.element_type) {
    case ElementType::File: return f.message;
    case ElementType::Robot:
      return (f.element.empty() ? "robot" : "robot " + detail::quoted(f.element)) + ": " + f.message;
    case ElementType::Link: return "link " + detail::quoted(f.element) + ": " + f.message;
    case ElementType::Joint: return "joint " + detail::quoted(f.element) + ": " + f.message;
    case ElementType::Tip: return "tip " + detail::quoted(f.element) + ": " + f.message;
  }
  return f.message;
}

}  // namespace kdl_space
