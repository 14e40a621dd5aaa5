// The target's shape and tumble inputs of a study (target_shape.hpp).
#include "study/target_shape.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "parsers/scenario/scenario_fields.hpp"
#include "spatial/message_text.hpp"
#include "study/study_sampling.hpp"

namespace kdl_space {

Vector3d coneAxis(const Vector3d& n, double theta, double phi) {
  Eigen::Index smallest = 0;
  n.cwiseAbs().minCoeff(&smallest);
  const Vector3d e1 = n.cross(Vector3d::Unit(smallest)).normalized();
  const Vector3d e2 = n.cross(e1);
  return std::cos(theta) * n + std::sin(theta) * (std::cos(phi) * e1 + std::sin(phi) * e2);
}

TargetShape::TargetShape(const RigidTarget& nominal) : mass(nominal.mass), w(nominal.twist.tail<3>()) {
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(0.5 * (nominal.inertia + nominal.inertia.transpose()));
  axes = eig.eigenvectors();  // ascending moments
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  moments = eig.eigenvalues();
}

Matrix3d TargetShape::inertia(const Vector3d& factor, double tilt, const Vector3d& tilt_axis, double mass_now) const {
  const Matrix3d A = Eigen::AngleAxisd(tilt, tilt_axis).toRotationMatrix() * axes;
  return (mass_now / mass) * (A * factor.cwiseProduct(moments).asDiagonal() * A.transpose());
}

void checkTargetShape(const fields::Field& inputs, const Study& study) {
  using F = StudyInput::Field;
  const auto* target = std::get_if<RigidTarget>(&study.scenario.capture.target);
  if (!target) return;  // the loader refuses every target input for a free-floating target
  const TargetShape shape(*target);
  Vector3d low = Vector3d::Ones(), high = Vector3d::Ones();
  const StudyInput* last_factor = nullptr;
  const StudyInput* cone = nullptr;
  const StudyInput* twist_w = nullptr;
  for (const StudyInput& in : study.inputs) {
    if (in.field == F::TargetPrincipalInertia) {
      std::tie(low(in.index), high(in.index)) = sampling::drawnRange(in.distribution);
      last_factor = &in;
    }
    if (in.field == F::TargetTumbleCone) cone = &in;
    if (in.field == F::TargetTwist && in.index >= 3) twist_w = &in;
  }
  if (last_factor)  // the triangle inequality is linear in the factors: its worst case is a corner of their box
    for (int corner = 0; corner < 8; ++corner) {
      Vector3d f, m;
      for (int k = 0; k < 3; ++k) f(k) = (corner >> k) & 1 ? high(k) : low(k);
      m = f.cwiseProduct(shape.moments);
      for (int k = 0; k < 3; ++k)
        if (m(k) > (m.sum() - m(k)) * (1.0 + 1e-12))
          inputs.at(last_factor->name)
              .fail("the principal moments " + detail::number(shape.moments(0)) + ", " + detail::number(shape.moments(1)) +
                    ", " + detail::number(shape.moments(2)) + " kg m^2 times the factors I1 x " + detail::number(f(0)) +
                    ", I2 x " + detail::number(f(1)) + ", I3 x " + detail::number(f(2)) + " (the ends of their draws) give " +
                    detail::number(m(0)) + ", " + detail::number(m(1)) + ", " + detail::number(m(2)) + " kg m^2: I" +
                    std::to_string(k + 1) + " exceeds the sum of the other two, which no rigid body has; narrow the "
                    "ranges (a normal: bound it with min and max)");
    }
  if (cone && !(shape.w.norm() > 0.0))
    inputs.at(cone->name).fail("is a cone about the target's tumble axis, and the scenario's target does not turn "
                               "(its twist's w is 0): give the target an angular velocity");
  if (cone && twist_w)
    inputs.at(twist_w->name).fail("sets the target's angular velocity, which " + cone->name +
                                  " turns within its cone: give one of them");
}

}  // namespace kdl_space
