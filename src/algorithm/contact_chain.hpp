// The kinematic chain from a free-floating model's base to a contact frame, and the coordinates
// that move it (private to the inverse kinematics): KDL's chain for its solvers, and the coupling
// of its joints to the model's coordinates (mimic joints follow their leaders).
#pragma once

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/jntarray.hpp>
#include <vector>

#include "kdl_space/multibody/model.hpp"

namespace kdl_space {

/// The chain from the base to the contact link, its tip moved to the contact offset, and the
/// coordinates that move it. A mimic joint on the chain follows its leader (chain angle
/// multiplier * x(leader) + offset), so the search runs in the coordinates, as the dynamics do
/// (J T); a joint the model holds fixed (it moves no mass) stays at 0.
struct ContactChain {
  KDL::Chain chain;
  std::vector<int> joints;  // the coordinates (model indices), in the order they first appear
  KDL::JntArray lower, upper;  // per coordinate
  /// Chain angles = T x + o (T: chain joints x coordinates).
  Eigen::MatrixXd T;
  Eigen::VectorXd o;
  bool coupled = false;  // T is not the identity (a mimic or a held joint on the chain)

  KDL::JntArray chainAngles(const KDL::JntArray& x) const;
};

/// The chain of `contact` in `model`. \throws ModelError when the link has no chain from the base.
ContactChain contactChain(const FloatingModel& model, const Contact& contact);

}  // namespace kdl_space
