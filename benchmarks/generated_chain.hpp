// Generated test robots: an N-link revolute chain on a 500 kg base, every inertia a full tensor,
// written as URDF so that every library under comparison reads the same file.
#pragma once

#include <cmath>
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

}  // namespace kdl_space::bench
