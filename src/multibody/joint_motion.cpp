#include "multibody/joint_motion.hpp"

namespace kdl_space::detail {

MotionTable::MotionTable(const std::vector<Body>& model_bodies) : bodies(model_bodies.size()) {
  for (std::size_t i = 0; i < model_bodies.size(); ++i) {
    const Body& b = model_bodies[i];
    JointMotion& j = bodies[i];
    j.parent = b.parent;
    j.joint = b.joint;
    j.twist_v = b.joint_twist.head<3>();
    j.twist_w = b.joint_twist.tail<3>();
    j.mass = b.mass;
    j.com = b.com;
    j.I_com = b.I_com;
    if (b.parent < 0) continue;
    const KDL::Frame pose0 = b.segment.pose(b.offset);  // at q = 0 of its coordinate (a mimic's offset)
    j.R0 = toEigen(pose0.M);
    j.p0 = toEigen(pose0.p);
    if (b.joint < 0) continue;
    const Vector3d v = j.twist_v, w = j.twist_w;  // at the parent's origin
    if (w.norm() > 0.0) {
      j.kind = JointMotion::Revolute;
      j.scale = w.norm();
      j.axis = w / j.scale;
      const Vector3d point = w.cross(v) / w.squaredNorm();  // the axis' point nearest the parent's origin
      const Matrix3d a = skew(j.axis), a2 = a * a;
      j.K1 = a * j.R0;
      j.K2 = a2 * j.R0;
      j.k1 = a * (j.p0 - point);
      j.k2 = a2 * (j.p0 - point);
    } else {
      j.kind = JointMotion::Prismatic;
      j.scale = v.norm();
      j.axis = v / j.scale;
    }
  }
}

}  // namespace kdl_space::detail
