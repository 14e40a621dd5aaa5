// Generated test robots: an N-link revolute chain on a 500 kg base, every inertia a full tensor,
// written as URDF so that every library under comparison reads the same file.
#pragma once

#include <algorithm>
#include <cmath>
#include <ostream>
#include <sstream>
#include <string>

namespace kdl_space::bench {

/// Inertia block of a box-like body of mass m and size (a, b, c), rotated by small angles so that
/// the tensor is full (off-diagonal terms non-zero). Physically valid (positive definite,
/// triangle inequality) by construction.
inline std::string inertial(double m, double a, double b, double c, double tilt, const std::string& com) {
  const double I1 = m * (b * b + c * c) / 12, I2 = m * (a * a + c * c) / 12, I3 = m * (a * a + b * b) / 12;
  // R = Rz(tilt) Rx(tilt / 2); I = R diag(I1, I2, I3) R^T.
  const double cz = std::cos(tilt), sz = std::sin(tilt), cx = std::cos(tilt / 2), sx = std::sin(tilt / 2);
  const double R[3][3] = {{cz, -sz * cx, sz * sx}, {sz, cz * cx, -cz * sx}, {0, sx, cx}};
  const double d[3] = {I1, I2, I3};
  double I[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      I[i][j] = 0;
      for (int k = 0; k < 3; ++k) I[i][j] += R[i][k] * d[k] * R[j][k];
    }
  std::ostringstream s;
  s.precision(17);
  s << "<inertial><origin xyz=\"" << com << "\" rpy=\"0 0 0\"/><mass value=\"" << m << "\"/><inertia ixx=\""
    << I[0][0] << "\" ixy=\"" << I[0][1] << "\" ixz=\"" << I[0][2] << "\" iyy=\"" << I[1][1] << "\" iyz=\""
    << I[1][2] << "\" izz=\"" << I[2][2] << "\"/></inertial>";
  return s.str();
}

/// N revolute links (axes cycling z, y, x), 0.3 m apart, 4-8 kg each, on a 500 kg base, and a
/// massless `tip` link 0.1 m beyond the last one.
inline std::string generatedChainUrdf(int N) {
  std::ostringstream u;
  u << "<?xml version=\"1.0\"?>\n<robot name=\"chain" << N << "\">\n";
  u << "<link name=\"base\">" << inertial(500.0, 1.6, 1.4, 1.2, 0.2, "0.02 -0.01 0.03") << "</link>\n";
  const char* axes[3] = {"0 0 1", "0 1 0", "1 0 0"};
  for (int i = 1; i <= N; ++i) {
    const std::string parent = i == 1 ? "base" : "link" + std::to_string(i - 1);
    const double m = 4.0 + 4.0 * (N - i) / std::max(1, N - 1);
    u << "<joint name=\"joint" << i << "\" type=\"revolute\"><parent link=\"" << parent << "\"/><child link=\"link"
      << i << "\"/><origin xyz=\"" << (i == 1 ? "0.9 0 0" : "0.3 0 0") << "\" rpy=\"0 0 " << 0.1 * (i % 3)
      << "\"/><axis xyz=\"" << axes[i % 3] << "\"/><limit lower=\"-3\" upper=\"3\" effort=\"100\" velocity=\"1\"/></joint>\n";
    u << "<link name=\"link" << i << "\">" << inertial(m, 0.3, 0.08, 0.08, 0.1 + 0.01 * i, "0.15 0.01 0") << "</link>\n";
  }
  u << "<joint name=\"tip_joint\" type=\"fixed\"><parent link=\"link" << N
    << "\"/><child link=\"tip\"/><origin xyz=\"0.1 0 0\" rpy=\"0 0 0\"/></joint>\n<link name=\"tip\"/>\n</robot>\n";
  return u.str();
}

/// A revolute joint of the generated humanoids (limits +-3 rad, 100 N m, 1 rad/s), yawed at its
/// origin, with `mimic` (a <mimic> element, or "") inside.
inline void revoluteJoint(std::ostream& u, const std::string& name, const std::string& parent, const std::string& child,
                          const std::string& xyz, double yaw, const char* axis, const std::string& mimic) {
  u << "<joint name=\"" << name << "\" type=\"revolute\"><parent link=\"" << parent << "\"/><child link=\"" << child
    << "\"/><origin xyz=\"" << xyz << "\" rpy=\"0 0 " << yaw << "\"/><axis xyz=\"" << axis
    << "\"/><limit lower=\"-3\" upper=\"3\" effort=\"100\" velocity=\"1\"/>" << mimic << "</joint>\n";
}

/// The generated humanoids' upper body: a 500 kg torso, two arms of `arm_joints[0]` (right, side
/// "r") and `arm_joints[1]` (left, "l") revolute joints (as the chain's links), each arm ending in
/// what `hand(u, side, wrist)` writes (wrist: the arm's last link, or "base" for an arm of no
/// joint), and a massless `tip` link at `tip_xyz` from link `tip_parent`. The finger layout is
/// `hand`'s: generatedHandsUrdf and generatedGrippersUrdf differ only there and in the arm lengths.
template <class Hand>
std::string humanoidUrdf(const std::string& robot, const int (&arm_joints)[2], const Hand& hand,
                         const std::string& tip_parent, const std::string& tip_xyz) {
  std::ostringstream u;
  u << "<?xml version=\"1.0\"?>\n<robot name=\"" << robot << "\">\n";
  u << "<link name=\"base\">" << inertial(500.0, 1.6, 1.4, 1.2, 0.2, "0.02 -0.01 0.03") << "</link>\n";
  const char* axes[3] = {"0 0 1", "0 1 0", "1 0 0"};
  for (int side = 0; side < 2; ++side) {
    const std::string s = side == 0 ? "r" : "l";
    const int arm = arm_joints[side];
    std::string parent = "base";
    for (int i = 1; i <= arm; ++i) {
      const std::string child = s + "_link" + std::to_string(i);
      revoluteJoint(u, s + "_joint" + std::to_string(i), parent, child,
                    i == 1 ? (side == 0 ? "0 -0.8 0.5" : "0 0.8 0.5") : "0.3 0 0", 0.1 * (i % 3), axes[i % 3], "");
      u << "<link name=\"" << child << "\">" << inertial(4.0 + 2.0 * (arm - i) / std::max(1, arm - 1), 0.3, 0.08, 0.08,
                                                        0.1 + 0.01 * i, "0.15 0.01 0")
        << "</link>\n";
      parent = child;
    }
    hand(u, s, parent);
  }
  u << "<joint name=\"tip_joint\" type=\"fixed\"><parent link=\"" << tip_parent << "\"/><child link=\"tip\"/><origin xyz=\""
    << tip_xyz << "\" rpy=\"0 0 0\"/></joint>\n<link name=\"tip\"/>\n</robot>\n";
  return u.str();
}

/// A humanoid's upper body with coupled fingers, N movable joints in all: a 500 kg torso, two arms
/// of (N - 6F) / 2 revolute joints each (as the chain's links), each arm ending in a hand of
/// F = max(1, round(N / 12)) three-joint fingers whose middle and distal joints follow the proximal
/// one (URDF <mimic>, multipliers 0.9 and 0.7): a third of the joints are mimic joints at every N.
/// The contact link `tip` is beyond the first finger's distal phalanx of the first hand.
inline std::string generatedHandsUrdf(int N) {
  const int F = std::max(1, static_cast<int>(std::lround(N / 12.0)));
  const int arm = std::max(1, (N - 6 * F) / 2);
  const auto hand = [F](std::ostream& u, const std::string& s, const std::string& wrist) {
    for (int f = 0; f < F; ++f) {
      const std::string p = s + "_f" + std::to_string(f), y = std::to_string(0.02 * f - 0.01 * F);
      std::string previous = wrist;
      const char* names[3] = {"_proximal", "_middle", "_distal"};
      for (int k = 0; k < 3; ++k) {
        const std::string child = p + "_" + std::to_string(k + 1);
        const std::string mimic = k == 0 ? "" : "<mimic joint=\"" + p + names[0] + "\" multiplier=\"" +
                                                    (k == 1 ? "0.9" : "0.7") + "\" offset=\"0.01\"/>";
        revoluteJoint(u, p + names[k], previous, child, k == 0 ? "0.32 " + y + " 0" : "0.04 0 0", 0.0, "0 1 0", mimic);
        u << "<link name=\"" << child << "\">" << inertial(0.05 - 0.01 * k, 0.04, 0.015, 0.015, 0.2, "0.02 0 0")
          << "</link>\n";
        previous = child;
      }
    }
  };
  return humanoidUrdf("hands" + std::to_string(N), {arm, arm}, hand, "r_f0_3", "0.03 0 0");
}

/// A humanoid's upper body with few coupled fingers, N movable joints in all: a 500 kg torso, two
/// arms of (N - 8) / 2 revolute joints each (N - 8 odd: the right arm one more), each arm ending in
/// a two-finger gripper whose fingers have a proximal joint and a distal one that follows it (URDF
/// <mimic>, multiplier 0.6): k = 4 mimic joints at every N (the issue's "large humanoid with coupled
/// fingers"; generatedHandsUrdf is the hand-dominated case, k = N / 3). The contact link `tip` is
/// beyond the right gripper's first distal phalanx.
inline std::string generatedGrippersUrdf(int N) {
  const int arms = std::max(2, N - 8);
  const auto gripper = [](std::ostream& u, const std::string& s, const std::string& wrist) {
    for (int f = 0; f < 2; ++f) {
      const std::string p = s + "_finger" + std::to_string(f);
      revoluteJoint(u, p + "_proximal", wrist, p + "_1", f == 0 ? "0.32 0.03 0" : "0.32 -0.03 0", 0.0,
                    f == 0 ? "0 0 1" : "0 0 -1", "");
      u << "<link name=\"" << p << "_1\">" << inertial(0.08, 0.05, 0.02, 0.02, 0.2, "0.025 0 0") << "</link>\n";
      revoluteJoint(u, p + "_distal", p + "_1", p + "_2", "0.05 0 0", 0.0, "0 0 1",
                    "<mimic joint=\"" + p + "_proximal\" multiplier=\"0.6\" offset=\"0.01\"/>");
      u << "<link name=\"" << p << "_2\">" << inertial(0.05, 0.04, 0.015, 0.015, 0.2, "0.02 0 0") << "</link>\n";
    }
  };
  return humanoidUrdf("grippers" + std::to_string(N), {arms - arms / 2, arms / 2}, gripper, "r_finger0_2", "0.04 0 0");
}

}  // namespace kdl_space::bench
