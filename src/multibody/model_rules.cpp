#include "multibody/model_rules.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "detail/text.hpp"

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
  if (mass == 0.0) {
    if (!I_com.isZero(0.0))
      out.push_back(error("non_positive_mass", ElementType::Link, link,
                          "has rotational inertia but zero mass: give the link its mass, or no "
                          "<inertial> if it only carries a frame"));
    return;
  }
  const InertiaVerdict v = judgeInertia(I_com);
  const Eigen::Vector3d& l = v.moments;
  const std::string moments = number(l(0)) + ", " + number(l(1)) + ", " + number(l(2)) + " kg m^2";
  const double round_off = std::max(kRoundOffRelative * std::max(l(2), 0.0), mass * kRoundOffLength * kRoundOffLength);
  if (l(0) < -round_off) {
    out.push_back(error("inertia_not_positive_definite", ElementType::Link, link,
                        "inertia is not positive definite (principal moments " + moments +
                            "): a body with mass has principal moments >= 0; check the signs, the "
                            "products of inertia and the units"));
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

Eigen::Matrix3d withoutNegativeMoments(const Eigen::Matrix3d& I) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (I + I.transpose()));
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(0) < 0.0)) return I;
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

void checkBaseComposite(const std::vector<MassNode>& nodes, Findings& out) {
  if (nodes.empty()) return;
  double mass = 0.0;
  std::vector<std::string> links;
  for (const int i : composite(nodes, 0)) {
    mass += nodes[i].mass;
    links.push_back(detail::quoted(nodes[i].link));
  }
  if (mass != 0.0) return;  // massive, or unknown (NaN)
  const std::string fix = "(kdl_space reads the root link's <inertial>, which kdl_parser drops)";
  out.push_back(error("base_without_mass", ElementType::Link, nodes[0].link,
                      links.size() == 1
                          ? "the free-floating base has no mass: give this link an <inertial> with its mass and "
                            "inertia " + fix
                          : "the free-floating base has no mass: it is the links " + detail::listNames(links) +
                                " (the root and the links fixed to it); give one of them an <inertial> with its "
                                "mass and inertia " + fix));
}

void checkMassDistribution(const std::vector<MassNode>& nodes, Findings& out) {
  // Mass of each subtree, children first (parents precede children in `nodes`).
  std::vector<double> subtree(nodes.size(), 0.0);
  for (std::size_t i = 0; i < nodes.size(); ++i) subtree[i] = nodes[i].mass;
  for (std::size_t i = nodes.size(); i-- > 1;)
    if (nodes[i].parent >= 0) subtree[nodes[i].parent] += subtree[i];
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    const MassNode& n = nodes[i];
    if (n.movable && subtree[i] == 0.0 && !(n.armature > 0.0)) {
      out.push_back(warning("joint_moves_no_mass", ElementType::Joint, n.joint,
                            "moves only massless links (" + detail::quoted(n.link) +
                                " and below): it has no inertia, so it is treated as fixed at q = 0 and is "
                                "not a coordinate (give the links their mass, or the joint an armature)"));
    }
    if (n.mass == 0.0)  // massive, or unknown (NaN): no note
      out.push_back(note("massless_link", ElementType::Link, n.link,
                         subtree[i] == 0.0 ? "massless link: it only carries a frame"
                                           : "massless link: it carries no inertia of its own"));
  }
}

const Finding* firstError(const Findings& findings) {
  for (const Finding& f : findings)
    if (f.severity == Severity::Error) return &f;
  return nullptr;
}

}  // namespace kdl_space::rules
