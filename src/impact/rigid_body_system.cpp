#include "kdl_space/impact/rigid_body_system.hpp"

#include <cmath>
#include <memory>

#include "kdl_space/spatial/errors.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {

FloatingSystem rigidBodySystem(const RigidTarget& t, const Vector3d& contact_point, const Vector6d& twist_at_com) {
  // A free body of no mass has no dynamics of its own (its twist after any impulse is undefined).
  if (!std::isfinite(t.mass) || t.mass <= 0.0)
    throw InputError("target.mass: a rigid target must have a finite mass > 0 [kg], got " + detail::number(t.mass) +
                     ": give its mass");
  if (!t.inertia.allFinite()) throw InputError("target.inertia: must be finite [kg m^2]");
  const Matrix3d& I = t.inertia;
  FloatingSystem s;
  s.model = std::make_shared<const FloatingModel>(
      KDL::Tree("target"), KDL::RigidBodyInertia(t.mass, KDL::Vector::Zero(),
                                                 KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2))));
  s.state = State(*s.model);
  s.state.world_T_base = KDL::Frame(t.pose.M, t.pose * toKDL(t.com));
  s.velocity = FloatingVelocity(*s.model);
  s.velocity.base_twist = toTwist(twist_at_com);
  s.contact = Contact{0, s.state.world_T_base.Inverse() * toKDL(contact_point)};
  return s;
}

}  // namespace kdl_space
