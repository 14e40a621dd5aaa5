#include "multibody/model_rules.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "spatial/message_text.hpp"

namespace kdl_space::rules {

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

Finding error(std::string kind, ElementType type, std::string element, std::string message) {
  return {Severity::Error, std::move(kind), type, std::move(element), std::move(message)};
}

Finding warning(std::string kind, ElementType type, std::string element, std::string message) {
  return {Severity::Warning, std::move(kind), type, std::move(element), std::move(message)};
}

Finding note(std::string kind, ElementType type, std::string element, std::string message) {
  return {Severity::Note, std::move(kind), type, std::move(element), std::move(message)};
}

InertiaVerdict judgeInertia(const Eigen::Matrix3d& I) {
  InertiaVerdict v;
  if (!I.allFinite()) {
    v.kind = InertiaVerdict::NotFinite;
    return v;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (I + I.transpose()), Eigen::EigenvaluesOnly);
  v.moments = eig.eigenvalues();  // ascending
  v.symmetric = (I - I.transpose()).norm() <= 1e-12 * I.norm();
  if (!(v.moments(0) > 0.0)) v.kind = InertiaVerdict::NotPositiveDefinite;
  else if (v.moments(0) + v.moments(1) < v.moments(2) * (1.0 - 1e-9)) v.kind = InertiaVerdict::TriangleInequality;
  return v;
}

namespace {
/// Principal moments within this of zero are round-off (see kRoundOffRelative).
double roundOff(double mass, const Eigen::Vector3d& moments) {
  return std::max(kRoundOffRelative * std::max(moments(2), 0.0), mass * kRoundOffLength * kRoundOffLength);
}

std::string momentsText(const Eigen::Vector3d& l) {
  return number(l(0)) + ", " + number(l(1)) + ", " + number(l(2)) + " kg m^2";
}
}  // namespace

bool negativeBeyondRoundOff(double mass, const Eigen::Matrix3d& I_com) {
  const InertiaVerdict v = judgeInertia(I_com);
  return v.kind != InertiaVerdict::NotFinite && v.moments(0) < -roundOff(mass, v.moments);
}

void checkInertia(const std::string& link, double mass, const Eigen::Matrix3d& I_com, Findings& out) {
  if (!std::isfinite(mass) || !I_com.allFinite()) {
    out.push_back(error("not_finite", ElementType::Link, link, "inertial values hold NaN or infinite numbers"));
    return;
  }
  if (mass < 0.0) {
    out.push_back(error("non_positive_mass", ElementType::Link, link,
                        "negative mass (" + number(mass) + " kg): a link's mass is > 0, or 0 for a link "
                        "that only carries a frame"));
    return;
  }
  if (mass == 0.0 && I_com.isZero(0.0)) return;  // a frame
  const InertiaVerdict v = judgeInertia(I_com);
  const Eigen::Vector3d& l = v.moments;
  const std::string moments = momentsText(l);
  const double round_off = roundOff(mass, l);
  if (l(0) < -round_off) return;  // the rigid body it belongs to is judged (checkRigidBodies)
  // Files written for visualisers and planners give frames a placeholder inertia and no mass.
  if (mass == 0.0) {
    out.push_back(warning("inertia_without_mass", ElementType::Link, link,
                          "zero mass with a rotational inertia (principal moments " + moments +
                              "): read as written, a body that resists rotation but not translation (give the "
                              "link its mass if it has one; no <inertial> if it only carries a frame)"));
    return;
  }
  // A point mass: no moment beyond the round-off of moving an inertia between the CoM and the
  // link origin (KDL keeps it about the origin: m |c|^2 eps for |c| up to 10 m).
  if (l(2) <= mass * 1e-12) {
    out.push_back(warning("point_mass", ElementType::Link, link,
                          "a point mass (" + number(mass) + " kg, no rotational inertia): read as one; the "
                          "body it belongs to needs its inertia from other links"));
    return;
  }
  if (l(0) <= 0.0) {
    out.push_back(warning("inertia_round_off", ElementType::Link, link,
                          "principal moments " + moments + ": the smallest is " +
                              (l(0) < 0.0 ? "negative" : "zero") + " within round-off (|I1| <= " +
                              number(round_off) + " kg m^2), read as 0"));
  }
  const double I1 = std::max(l(0), 0.0), I2 = std::max(l(1), 0.0), I3 = l(2);
  if (I1 + I2 < I3 * (1.0 - 1e-9)) {
    const double short_by = I3 - I1 - I2;
    out.push_back(warning("triangle_inequality", ElementType::Link, link,
                          "principal moments " + moments + " break the triangle inequality I1 + I2 >= I3 by " +
                              number(short_by) + " kg m^2 (" + number(100.0 * short_by / I3) +
                              " % of I3): no rigid body has this inertia; read as written (the dynamics "
                              "are defined while the bodies are positive definite)"));
  }
}

Eigen::Matrix3d withoutNegativeMoments(double mass, const Eigen::Matrix3d& I) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (I + I.transpose()));
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(0) < 0.0)) return I;
  if (eig.eigenvalues()(0) < -roundOff(mass, eig.eigenvalues())) return I;  // beyond round-off: as written
  const Eigen::Vector3d clamped = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
}

std::vector<int> composite(const std::vector<MassNode>& nodes, int head) {
  std::vector<int> members{head};
  std::vector<bool> in(nodes.size(), false);
  in[head] = true;
  for (std::size_t i = head + 1; i < nodes.size(); ++i)  // parents precede children
    if (nodes[i].parent >= 0 && in[nodes[i].parent] && !nodes[i].movable) {
      in[i] = true;
      members.push_back(static_cast<int>(i));
    }
  return members;
}

std::pair<double, bool> compositeMass(const std::vector<MassNode>& nodes, int head) {
  double mass = 0.0;
  bool rotational = false;
  for (const int i : composite(nodes, head)) {
    mass += nodes[i].mass;
    rotational |= nodes[i].rotational;
  }
  return {mass, rotational};
}

void checkRigidBodies(const std::vector<MassNode>& nodes, Findings& out) {
  // Each link's pose in the frame of the head of its composite (fixed joints at their poses).
  std::vector<Eigen::Matrix3d> R(nodes.size(), Eigen::Matrix3d::Identity());
  std::vector<Eigen::Vector3d> p(nodes.size(), Eigen::Vector3d::Zero());
  for (std::size_t i = 1; i < nodes.size(); ++i)
    if (!nodes[i].movable && nodes[i].parent >= 0) {
      R[i] = R[nodes[i].parent] * nodes[i].R;
      p[i] = R[nodes[i].parent] * nodes[i].p + p[nodes[i].parent];
    }
  for (std::size_t h = 0; h < nodes.size(); ++h) {
    if (h > 0 && !nodes[h].movable) continue;
    const std::vector<int> members = composite(nodes, static_cast<int>(h));
    std::vector<int> failing;
    for (const int i : members)
      if (nodes[i].inertia_known && std::isfinite(nodes[i].mass) && negativeBeyondRoundOff(nodes[i].mass, nodes[i].I_com))
        failing.push_back(i);
    if (failing.empty()) continue;
    // The composite's inertia about its own CoM (about the head's origin when it has no mass).
    double m = 0.0;
    Eigen::Vector3d first = Eigen::Vector3d::Zero();
    Eigen::Matrix3d I_origin = Eigen::Matrix3d::Zero();
    std::vector<std::string> names;
    for (const int i : members) {
      names.push_back(detail::quoted(nodes[i].link));
      if (!nodes[i].inertia_known || !std::isfinite(nodes[i].mass)) continue;
      const Eigen::Vector3d c = R[i] * nodes[i].com + p[i];
      const double mi = nodes[i].mass;
      m += mi;
      first += mi * c;
      I_origin += R[i] * nodes[i].I_com * R[i].transpose() +
                  mi * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    }
    const Eigen::Vector3d r = m > 0.0 ? Eigen::Vector3d(first / m) : Eigen::Vector3d::Zero();
    const Eigen::Matrix3d I_c = I_origin - m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    const bool body_ok = !negativeBeyondRoundOff(m, I_c);
    const Eigen::Vector3d body_moments = judgeInertia(I_c).moments;
    for (const int i : failing) {
      const std::string own = "inertia is not positive definite (principal moments " +
                              momentsText(judgeInertia(nodes[i].I_com).moments) + ")";
      std::vector<std::string> others;
      for (const std::string& name : names)
        if (name != detail::quoted(nodes[i].link)) others.push_back(name);
      const std::string body = "the rigid body it forms by fixed joints with " + detail::listNames(others) +
                               " (principal moments " + momentsText(body_moments) + " about its CoM)";
      if (body_ok)
        out.push_back(warning("link_inertia_not_positive_definite", ElementType::Link, nodes[i].link,
                              own + ", but " + body + " is positive definite: read as written (the dynamics "
                              "see that rigid body, not the link alone)"));
      else if (others.empty())
        out.push_back(error("inertia_not_positive_definite", ElementType::Link, nodes[i].link,
                            own + ": a body with mass has principal moments >= 0; check the signs, the "
                            "products of inertia and the units"));
      else
        out.push_back(error("inertia_not_positive_definite", ElementType::Link, nodes[i].link,
                            own + ", nor is " + body + ": a body with mass has principal moments >= 0; check "
                            "the signs, the products of inertia and the units"));
    }
  }
}

void checkMassDistribution(const std::vector<MassNode>& nodes, Findings& out) {
  // Mass of each subtree, children first (parents precede children in `nodes`).
  std::vector<double> subtree(nodes.size(), 0.0);
  for (std::size_t i = 0; i < nodes.size(); ++i) subtree[i] = nodes[i].mass;
  std::vector<bool> rotational(nodes.size(), false);  // a rotational inertia in the subtree
  for (std::size_t i = 0; i < nodes.size(); ++i) rotational[i] = nodes[i].rotational;
  for (std::size_t i = nodes.size(); i-- > 1;)
    if (nodes[i].parent >= 0) {
      subtree[nodes[i].parent] += subtree[i];
      if (rotational[i]) rotational[nodes[i].parent] = true;
    }
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    const MassNode& n = nodes[i];
    if (n.movable && subtree[i] == 0.0 && !rotational[i] && !(n.armature > 0.0)) {
      out.push_back(warning("joint_moves_no_mass", ElementType::Joint, n.joint,
                            "moves only massless links (" + detail::quoted(n.link) +
                                " and below): it has no inertia, so it is treated as fixed at q = 0 and is "
                                "not a coordinate (give the links their mass, or the joint an armature)"));
    }
    if (n.mass == 0.0 && !n.rotational)  // massive, unknown (NaN), or with its own warning: no note
      out.push_back(note("massless_link", ElementType::Link, n.link,
                         subtree[i] == 0.0 && !rotational[i] ? "massless link: it only carries a frame"
                                           : "massless link: it carries no inertia of its own"));
  }
}

RuleError::RuleError(Finding finding) : ModelError(describe(finding)), finding_(std::move(finding)) {}

RuleError::~RuleError() = default;

std::exception_ptr RuleError::renamed(const std::string& what) const {
  return std::make_exception_ptr(RuleError(finding_, what));
}

const Finding* firstError(const Findings& findings) {
  for (const Finding& f : findings)
    if (f.severity == Severity::Error) return &f;
  return nullptr;
}

}  // namespace kdl_space::rules
