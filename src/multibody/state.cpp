#include "kdl_space/multibody/state.hpp"

#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

KDL::JntArray jointsByName(const FloatingModel& model, const std::map<std::string, double>& values) {
  KDL::JntArray q(model.nj());
  for (const auto& [name, value] : values) {
    const int j = model.jointIndex(name);
    if (j < 0) throw ModelError("joint '" + name + "': the model has no movable joint of that name");
    q(j) = value;
  }
  return q;
}

}  // namespace kdl_space
