#include "kdl_space/multibody/poses.hpp"

#include <string>

#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {

PoseFigures poseFigures(const KDL::Frame& world_T_frame) {
  PoseFigures f;
  f.position = toEigen(world_T_frame.p);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) f.rotation(r, c) = world_T_frame.M(r, c);
  double x, y, z, w;
  world_T_frame.M.GetQuaternion(x, y, z, w);
  // q and -q are one rotation: w >= 0 makes the printed quaternion unique (but at w = 0).
  const double s = w < 0 ? -1.0 : 1.0;
  f.quaternion = Eigen::Vector4d(s * x, s * y, s * z, s * w);
  world_T_frame.M.GetRPY(f.rpy(0), f.rpy(1), f.rpy(2));
  return f;
}

KDL::Frame contactFrame(const FloatingModel& model, const State& state, const Contact& contact) {
  if (contact.body < 0 || static_cast<std::size_t>(contact.body) >= model.bodies().size())
    throw ModelError("contact frame: body index " + std::to_string(contact.body) + " is outside the model's " +
                     std::to_string(model.bodies().size()) + " bodies");
  Kinematics kin(model);
  if (const int code = forwardKinematics(model, state, kin))
    throw ModelError(std::string("contact frame: forward kinematics failed: ") + strError(code));
  return contactFrame(kin, contact);
}

int linkPose(const FloatingModel& model, const State& state, int body, KDL::Frame& world_T_link) {
  if (body < 0 || static_cast<std::size_t>(body) >= model.bodies().size()) return E_BAD_CONTACT;
  Kinematics kin(model);
  if (const int rc = forwardKinematics(model, state, kin)) return rc;
  world_T_link = kin.pose(body);
  return E_NOERROR;
}

}  // namespace kdl_space
