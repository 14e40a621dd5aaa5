#include "kdl_space/algorithm/grasp_wrench.hpp"

namespace kdl_space {

int graspWrench(const FloatingModel& model, const HeldTarget& target, const Kinematics& kin, const FloatingVelocity& v,
                const FloatingAcceleration& a, const std::vector<KDL::Wrench>& f_ext, const Vector3d& gravity,
                Vector6d& on_robot) {
  const std::vector<Body>& bodies = model.bodies();
  const std::size_t nb = bodies.size();
  const unsigned int n = model.nj();
  if (kin.model != &model || target.bodies.size() != nb || v.qdot.rows() != n || a.qddot.rows() != n ||
      (!f_ext.empty() && f_ext.size() != nb) || target.payload_body >= static_cast<int>(nb))
    return E_SIZE_MISMATCH;
  if (const int rc = contactCode(kin.valid, target.contact, nb)) return rc;
  const Vector3d& P = kin.p_b;  // every spatial quantity about the base origin, a point fixed for the instant
  const Vector3d w = toEigen(v.base_twist.rot), v_b = toEigen(v.base_twist.vel);
  std::vector<Vector6d> V(nb), A(nb);
  V[0] << v_b, w;
  A[0] << a.base.head<3>() - w.cross(v_b), a.base.tail<3>();  // p_b'' = A_v + w x v_b
  A[0].head<3>() -= gravity;                                  // gravity as an acceleration -g of the frame
  Vector6d F = Vector6d::Zero();  // what the target's bodies need from the hand, about P
  const auto add = [&](int i, double m, const Vector3d& c, const Matrix3d& I_c) {
    const Matrix6d I = spatialInertia(m, c - P, I_c);
    F += I * A[i] + crossForce(V[i], I * V[i]);
  };
  for (std::size_t i = 0; i < nb; ++i) {
    const Body& b = bodies[i];
    if (b.parent >= 0) {
      V[i] = V[b.parent];
      A[i] = A[b.parent];
      if (b.joint >= 0) {
        const Vector6d Sqd = kin.S[i] * v.qdot(b.joint);
        V[i] += Sqd;
        A[i] += kin.S[i] * a.qddot(b.joint) + crossMotion(V[i], Sqd);
      }
    }
    if (target.bodies[i]) {
      add(static_cast<int>(i), b.mass, kin.com[i], kin.I_com[i]);
      if (!f_ext.empty()) {
        const Vector3d f = toEigen(f_ext[i].force);
        F.head<3>() -= f;
        F.tail<3>() -= toEigen(f_ext[i].torque) + (kin.p[i] - P).cross(f);
      }
    }
    if (static_cast<int>(i) == target.payload_body)
      add(static_cast<int>(i), target.payload_mass, kin.R[i] * target.payload_com + kin.p[i],
          kin.R[i] * target.payload_I_com * kin.R[i].transpose());
  }
  // On the robot: minus that, the moment moved from P to the contact point x (n_x = n_P + (P - x) x f).
  const Vector3d x = kin.point(target.contact);
  on_robot.head<3>() = -F.head<3>();
  on_robot.tail<3>() = -(F.tail<3>() + (P - x).cross(F.head<3>()));
  return on_robot.allFinite() ? E_NOERROR : E_NOT_FINITE;
}

}  // namespace kdl_space
