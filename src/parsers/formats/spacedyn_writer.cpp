// writeSpaceDyn: the model at q = 0 (base at the origin) grouped into SpaceDyn's links, each
// group's mass properties and frame in world terms, then SpaceDyn's vectors in its link frames.
#include <Eigen/Geometry>
#include <cctype>
#include <cmath>
#include <sstream>

#include "kdl_space/multibody/kinematics.hpp"
#include "kdl_space/parsers/formats/spacedyn_lp.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/spacedyn_angles.hpp"
#include "parsers/formats/urdf_builder.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;

Vector3d vec(const KDL::Vector& v) { return {v.x(), v.y(), v.z()}; }
Matrix3d mat(const KDL::Rotation& R) {
  Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = R(r, c);
  return m;
}

/// One SpaceDyn link (or the base): the bodies fixed together, their composite at q = 0 in world
/// terms, and the link frame (origin on the joint's axis, z along it; the base's at its centroid).
struct Group {
  int body = 0;                 ///< the body whose joint moves the group (0: the base)
  int parent = 0;               ///< the parent group (SpaceDyn's BB)
  std::vector<int> members;     ///< bodies, in traversal order
  double mass = 0.0;
  Vector3d com = Vector3d::Zero();
  Matrix3d I = Matrix3d::Zero();  ///< about com, world axes
  Matrix3d R = Matrix3d::Identity();  ///< the link frame's axes
  Vector3d origin = Vector3d::Zero();
  bool prismatic = false;
  int end_body = -1;            ///< the end point's body (-1: none)
  KDL::Frame end_offset = KDL::Frame::Identity();  ///< the end point in end_body's frame
  std::string end_name;
};

/// The least rotation taking z onto the unit vector `a`.
Matrix3d zOnto(const Vector3d& a) {
  if (a.z() < -1.0 + 1e-15) return Eigen::AngleAxisd(M_PI, Vector3d::UnitX()).toRotationMatrix();
  return Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), a).toRotationMatrix();
}

struct Export {
  const FloatingSystem& system;
  const FloatingModel& model;
  Kinematics kin;
  std::vector<Group> groups;
  std::vector<int> group_of;     ///< per body
  std::vector<Diagnostic> notes;

  explicit Export(const FloatingSystem& s) : system(s), model(*s.model), kin(model) {
    State zero(model);
    forwardKinematics(model, zero, kin);
  }
  void group();
  void massProperties();
  void frames();
  void endPoints();
};

void Export::group() {
  const auto& bodies = model.bodies();
  group_of.assign(bodies.size(), 0);
  groups.push_back(Group{});
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (b > 0 && bodies[b].joint >= 0) {
      Group g;
      g.body = int(b);
      g.parent = group_of[bodies[b].parent];
      group_of[b] = int(groups.size());
      groups.push_back(g);
    } else if (b > 0) {
      group_of[b] = group_of[bodies[b].parent];
    }
    groups[group_of[b]].members.push_back(int(b));
  }
  for (const Group& g : groups)
    if (g.members.size() > 1)
      notes.push_back({bodies[g.body].name, "links fixed together merged into one SpaceDyn link: " +
                                                 [&] { std::string s; for (int m : g.members) s += (s.empty() ? "" : ", ") + detail::quoted(bodies[m].name); return s; }(),
                       "", Severity::Note});
}

void Export::massProperties() {
  for (Group& g : groups) {
    Vector3d first = Vector3d::Zero();
    for (int b : g.members) {
      const Body& body = model.bodies()[b];
      const KDL::Frame T = kin.pose(b);
      g.mass += body.mass;
      first += body.mass * vec(T * KDL::Vector(body.com.x(), body.com.y(), body.com.z()));
    }
    g.com = g.mass > 0.0 ? Vector3d(first / g.mass) : vec(kin.pose(g.body).p);  // massless: the frame's origin
    for (int b : g.members) {
      const Body& body = model.bodies()[b];
      const KDL::Frame T = kin.pose(b);
      const Matrix3d R = mat(T.M);
      const Vector3d d = vec(T * KDL::Vector(body.com.x(), body.com.y(), body.com.z())) - g.com;
      g.I += R * body.I_com * R.transpose() + body.mass * (d.squaredNorm() * Matrix3d::Identity() - d * d.transpose());
    }
  }
}

void Export::frames() {
  std::vector<std::string> turned;  // joints whose SpaceDyn link frame is not the link's own
  groups[0].R = mat(kin.pose(0).M);
  groups[0].origin = groups[0].com;
  for (std::size_t k = 1; k < groups.size(); ++k) {
    Group& g = groups[k];
    const Body& body = model.bodies()[g.body];
    const KDL::Frame parent_T_child = body.segment.pose(0.0);
    const Vector3d w = body.joint_twist.tail<3>(), v = body.joint_twist.head<3>();  // parent axes, parent origin
    g.prismatic = w.norm() == 0.0;
    const double rate = g.prismatic ? v.norm() : w.norm();
    if (std::abs(rate - 1.0) > 1e-12)
      throw ModelError("SpaceDyn's LP: joint " + detail::quoted(model.jointNames()[body.joint]) +
                       " moves by " + detail::number(rate) + " per unit of its coordinate: SpaceDyn's joints move by one");
    const Vector3d axis_parent = g.prismatic ? v : w;
    const Vector3d on_axis_parent = g.prismatic ? vec(parent_T_child.p) : Vector3d(w.cross(v) / w.squaredNorm());
    const KDL::Frame child_T_parent = parent_T_child.Inverse();
    const Vector3d a = mat(child_T_parent.M) * axis_parent;
    const Vector3d on_axis = vec(child_T_parent * KDL::Vector(on_axis_parent.x(), on_axis_parent.y(), on_axis_parent.z()));
    const Vector3d p = g.prismatic ? Vector3d::Zero() : Vector3d(on_axis - a.normalized() * a.normalized().dot(on_axis));  // nearest the link's origin
    const KDL::Frame T = kin.pose(g.body);
    const Matrix3d child_R_link = zOnto(a.normalized());
    g.R = mat(T.M) * child_R_link;
    g.origin = vec(T * KDL::Vector(p.x(), p.y(), p.z()));
    if (!child_R_link.isIdentity(1e-12) || p.norm() > 1e-12) turned.push_back(model.jointNames()[body.joint]);
  }
  if (!turned.empty()) {
    std::string list;
    for (const std::string& j : turned) list += (list.empty() ? "" : ", ") + detail::quoted(j);
    notes.push_back({"", "the SpaceDyn link frames of joints " + list + " are their links' frames turned so that z is the joint's "
                         "axis (and moved onto it): SpaceDyn's joints turn about z", "", Severity::Note});
  }
}

void Export::endPoints() {
  const auto& bodies = model.bodies();
  std::vector<bool> has_child(groups.size(), false);
  for (std::size_t k = 1; k < groups.size(); ++k) has_child[groups[k].parent] = true;
  const int contact_group = system.contact.body >= 0 ? group_of[system.contact.body] : 0;
  for (std::size_t k = 1; k < groups.size(); ++k) {
    Group& g = groups[k];
    if (int(k) == contact_group) {
      g.end_body = system.contact.body;
      g.end_offset = KDL::Frame(system.contact.offset);
      g.end_name = "contact";
    } else if (!has_child[k]) {
      g.end_body = g.members.back();
      g.end_name = g.end_body == g.body ? bodies[g.body].name + "_end" : bodies[g.end_body].name;
    }
  }
  if (system.contact.body >= 0 && contact_group == 0 && groups.size() > 1)
    notes.push_back({bodies[system.contact.body].name, "the contact is on the base: SpaceDyn's end points are on links, so it is not one", "", Severity::Note});
}

std::string identifier(const std::string& name) {
  std::string s;
  for (char c : name) s += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0]))) s = "robot_" + s;
  return s.substr(0, 50);  // MATLAB: at most 63 characters, with "_LP"
}

/// A MATLAB matrix literal, rows ended by ';' (zeros(r,c) when empty).
std::string matrix(const MatrixXd& m) {
  if (m.size() == 0) return "zeros(" + std::to_string(m.rows()) + "," + std::to_string(m.cols()) + ")";
  std::string s = "[";
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) s += (c ? " " : "") + formats::exactNumber(m(r, c));
    s += r + 1 < m.rows() ? (m.cols() > 1 ? ";\n    " : "; ") : "]";
  }
  return s;
}

std::string cells(const std::vector<std::string>& names) {
  std::string s = "{";
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string n;
    for (char c : names[i]) n += c == '\'' ? std::string("''") : std::string(1, c);
    s += (i ? ", '" : "'") + n + "'";
  }
  return s + "}";
}

void writeLp(const Export& e, std::ostringstream& o) {
  const auto& g = e.groups;
  const int n = int(g.size()) - 1;
  MatrixXd BB(1, n), SS = MatrixXd::Zero(n, n), S0 = MatrixXd::Zero(1, n), SE = MatrixXd::Zero(1, n), m(1, n);
  MatrixXd c0 = MatrixXd::Zero(3, n), ce = MatrixXd::Zero(3, n), Qi(3, n), Qe = MatrixXd::Zero(3, n), inertia(3, 3 * n);
  std::string J_type;
  std::vector<std::string> links{e.model.bodies()[0].name}, joints, ends;
  for (int k = 1; k <= n; ++k) {
    const Group& l = g[k];
    const Group& p = g[l.parent];
    BB(0, k - 1) = l.parent;
    SS(k - 1, k - 1) = -1;
    if (l.parent > 0) SS(l.parent - 1, k - 1) = 1;
    if (l.parent == 0) S0(0, k - 1) = 1, c0.col(k - 1) = p.R.transpose() * (l.origin - p.com);
    J_type += l.prismatic ? 'P' : 'R';
    m(0, k - 1) = l.mass;
    inertia.block<3, 3>(0, 3 * (k - 1)) = l.R.transpose() * l.I * l.R;
    Qi.col(k - 1) = formats::spaceDynAngles(p.R.transpose() * l.R);  // eq: A_i = A_BB Rx Ry Rz(Qi3 + q)
    links.push_back(e.model.bodies()[l.body].name);
    joints.push_back(e.model.jointNames()[e.model.bodies()[l.body].joint]);
    if (l.end_body >= 0) {
      const KDL::Frame end = e.kin.pose(l.end_body) * l.end_offset;
      SE(0, k - 1) = 1;
      ce.col(k - 1) = l.R.transpose() * (vec(end.p) - l.com);
      Qe.col(k - 1) = formats::spaceDynAngles(l.R.transpose() * mat(end.M));
      ends.push_back(l.end_name);
    }
  }
  o << "LP.num_q = " << n << ";\n";
  o << "LP.BB = " << matrix(BB) << ";\nLP.SS = " << matrix(SS) << ";\nLP.S0 = " << matrix(S0) << ";\nLP.SE = " << matrix(SE) << ";\n";
  o << "LP.J_type = '" << J_type << "';\n";
  o << "LP.c0 = " << matrix(c0) << ";\n";
  o << "LP.cc = zeros(3," << n << "," << n << ");\n";
  for (int k = 1; k <= n; ++k) {  // cc(:,i,i): centroid to own joint; cc(:,BB,i): the parent's centroid to joint i
    const Group& l = g[k];
    o << "LP.cc(:," << k << "," << k << ") = " << matrix(l.R.transpose() * (l.origin - l.com)) << ";\n";
    if (l.parent > 0)
      o << "LP.cc(:," << l.parent << "," << k << ") = " << matrix(g[l.parent].R.transpose() * (l.origin - g[l.parent].com)) << ";\n";
  }
  o << "LP.ce = " << matrix(ce) << ";\nLP.Qi = " << matrix(Qi) << ";\nLP.Qe = " << matrix(Qe) << ";\n";
  o << "LP.m0 = " << formats::exactNumber(g[0].mass) << ";\nLP.m = " << matrix(m) << ";\nLP.mass = LP.m0 + sum(LP.m);\n";
  o << "LP.inertia0 = " << matrix(g[0].R.transpose() * g[0].I * g[0].R) << ";\nLP.inertia = " << matrix(inertia) << ";\n";
  o << "LP.link_names = " << cells(links) << ";\nLP.joint_names = " << cells(joints) << ";\nLP.end_names = " << cells(ends) << ";\n";
}

void writeSv(const Export& e, std::ostringstream& o) {
  const FloatingSystem& s = e.system;
  const Group& base = e.groups[0];
  const KDL::Frame& T = s.state.world_T_base;
  const Vector3d com_in_base = base.R.transpose() * base.com;  // the base frame is the world's at export
  const Vector3d R0 = vec(T * KDL::Vector(com_in_base.x(), com_in_base.y(), com_in_base.z()));
  const Vector3d w = vec(s.velocity.base_twist.rot);
  const Vector3d v0 = vec(s.velocity.base_twist.vel) + w.cross(R0 - vec(T.p));  // the centroid's velocity
  const int n = int(e.groups.size()) - 1;
  Eigen::MatrixXd q(n, 1), qd(n, 1);
  for (int k = 1; k <= n; ++k) {
    const int j = e.model.bodies()[e.groups[k].body].joint;
    q(k - 1, 0) = s.state.q.rows() ? s.state.q(j) : 0.0;
    qd(k - 1, 0) = s.velocity.qdot.rows() ? s.velocity.qdot(j) : 0.0;
  }
  const Matrix3d A0 = mat(T.M) * base.R;
  o << "SV.R0 = " << matrix(R0) << ";\nSV.A0 = " << matrix(A0) << ";\nSV.Q0 = " << matrix(formats::spaceDynAngles(A0)) << ";\n";
  o << "SV.v0 = " << matrix(v0) << ";\nSV.w0 = " << matrix(w) << ";\nSV.q = " << matrix(q) << ";\nSV.qd = " << matrix(qd) << ";\n";
  const std::string N = std::to_string(n);  // the rest of init_SV.m's fields
  o << "SV.vd0 = zeros(3,1);\nSV.wd0 = zeros(3,1);\nSV.qdd = zeros(" << N << ",1);\nSV.AA = zeros(3," << 3 * n << ");\n";
  for (const char* f : {"RR", "vv", "ww", "vd", "wd", "Fe", "Te"}) o << "SV." << f << " = zeros(3," << N << ");\n";
  o << "SV.F0 = zeros(3,1);\nSV.T0 = zeros(3,1);\nSV.tau = zeros(" << N << ",1);\n";
}

}  // namespace

SpaceDynFiles writeSpaceDyn(const FloatingSystem& system, const std::string& name) {
  if (!system.model) throw ModelError("SpaceDyn's LP: no model");
  if (!system.model->mimic().empty())
    throw ModelError("SpaceDyn's LP: joint " + detail::quoted(system.model->mimic().front().joint) +
                     " follows another (mimic): SpaceDyn's joints are independent; export the model without the coupling");
  Export e(system);
  e.group();
  e.massProperties();
  e.frames();
  e.endPoints();
  SpaceDynFiles f;
  f.name = identifier(name);
  std::ostringstream lp, sv;
  lp << "% " << f.name << "_LP: SpaceDyn link parameters (SpaceDyn's definitions: calc_aa.m, calc_pos.m), written by kdl_space.\n"
     << "% Link i turns about (slides along) z of its frame; vectors from each link's centroid, in its frame [m, kg, kg m^2].\n"
     << "function LP = " << f.name << "_LP()\n";
  writeLp(e, lp);
  lp << "end\n";
  sv << "% " << f.name << "_SV: the initial state for " << f.name << "_LP (init_SV.m's fields; q, qd in LP.joint_names' order).\n"
     << "function SV = " << f.name << "_SV()\n";
  writeSv(e, sv);
  sv << "end\n";
  f.lp = lp.str();
  f.sv = sv.str();
  f.notes = std::move(e.notes);
  f.notes.push_back({"", "SpaceDyn's LP holds no joint limits, damping, friction or rotor inertia: left out", "", Severity::Note});
  return f;
}

}  // namespace kdl_space
