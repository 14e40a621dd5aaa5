#include "model_rules.hpp"

#include <Eigen/Eigenvalues>
#include <expat.h>

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
  InertiaVerdict v = judgeInertia(I_com);
  const Eigen::Vector3d& l = v.moments;
  const std::string moments = number(l(0)) + ", " + number(l(1)) + ", " + number(l(2)) + " kg m^2";
  if (v.kind == InertiaVerdict::NotPositiveDefinite) {
    out.push_back(error("inertia_not_positive_definite", ElementType::Link, link,
                        "inertia is not positive definite (principal moments " + moments +
                            "): a body with mass has three positive principal moments; check the "
                            "signs, the products of inertia and the units"));
  } else if (v.kind == InertiaVerdict::TriangleInequality) {
    out.push_back(error("triangle_inequality", ElementType::Link, link,
                        "principal moments " + moments +
                            " break the triangle inequality I1 + I2 >= I3: no rigid body has this "
                            "inertia; check the values and the units"));
  }
}

void checkBaseMass(const std::string& base, double mass, Findings& out) {
  if (mass == 0.0)
    out.push_back(error("base_without_mass", ElementType::Link, base,
                        "the free-floating base has no mass: give this link an <inertial> with its mass "
                        "and inertia (kdl_space reads the root link's <inertial>, which kdl_parser drops)"));
}

void checkRootInertia(const std::string& root, bool has_inertial, Findings& out) {
  if (has_inertial)
    out.push_back(warning("root_inertia_dropped_by_kdl_parser", ElementType::Link, root,
                          "root link inertia kept as the base body's inertia (kdl_parser drops it: "
                          "tools built on kdl_parser alone see a massless base)"));
}

bool dropsRootJoint(bool root_massless, std::size_t root_child_joints, const std::string& child_joint_type) {
  return root_massless && root_child_joints == 1 && child_joint_type == "floating";
}

void checkJointType(const std::string& joint, const std::string& type, Findings& out) {
  if (type != "floating" && type != "planar") return;
  std::string message = "a " + type +
                        " joint inside the tree is not supported (only the base floats; use revolute, "
                        "continuous, prismatic or fixed joints)";
  if (type == "floating")
    message += "; a floating joint is accepted only from a massless root link (such as 'world') to "
               "its only child, the base";
  out.push_back(error("free_joint_inside", ElementType::Joint, joint, message));
}

bool isMovable(const std::string& type) {
  return type == "revolute" || type == "continuous" || type == "prismatic";
}

void checkAxis(const std::string& joint, const Eigen::Vector3d& axis, Findings& out) {
  const double norm = axis.norm();
  const std::string written = "(" + number(axis.x()) + " " + number(axis.y()) + " " + number(axis.z()) + ")";
  if (!std::isfinite(norm) || norm == 0.0) {
    out.push_back(error("zero_axis", ElementType::Joint, joint,
                        "its axis " + written + " has zero length (or is not finite): give its direction, "
                        "e.g. <axis xyz=\"0 0 1\"/>"));
  } else if (std::abs(norm - 1.0) > 1e-9) {
    out.push_back(warning("axis_not_unit", ElementType::Joint, joint,
                          "axis " + written + " is not unit length (norm " + number(norm) +
                              "): it is normalised"));
  }
}

void checkLimits(const std::string& joint, double lower, double upper, Findings& out) {
  if (lower > 0.0 || upper < 0.0)
    out.push_back(warning("limits_exclude_zero", ElementType::Joint, joint,
                          "limits [" + number(lower) + ", " + number(upper) +
                              "] exclude 0, where inspect, capture and simulate put every joint not "
                              "given a position: give q explicitly (kdl_space does not enforce limits)"));
}

void checkMassDistribution(const std::vector<MassNode>& nodes, Findings& out) {
  // Mass of each subtree, children first (parents precede children in `nodes`).
  std::vector<double> subtree(nodes.size(), 0.0);
  for (std::size_t i = 0; i < nodes.size(); ++i) subtree[i] = nodes[i].mass;
  for (std::size_t i = nodes.size(); i-- > 1;)
    if (nodes[i].parent >= 0) subtree[nodes[i].parent] += subtree[i];
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    const MassNode& n = nodes[i];
    if (n.mass != 0.0) continue;  // massive, or unknown (NaN)
    if (n.movable && subtree[i] == 0.0) {
      out.push_back(error("non_positive_mass", ElementType::Link, n.link,
                          "massless, and joint " + detail::quoted(n.joint) + " moves only massless links (" +
                              detail::quoted(n.link) + " and below): that joint has no inertia and H* is "
                              "singular; give the link its mass, or make the joint fixed"));
    } else {
      out.push_back(warning("massless_link", ElementType::Link, n.link,
                            subtree[i] == 0.0 ? "massless link: it only carries a frame"
                                              : "massless link: it carries no inertia of its own"));
    }
  }
}

void checkDepth(const std::string& link, int depth, Findings& out) {
  if (depth > kMaxTreeDepth)
    out.push_back(error("too_deep", ElementType::Link, link,
                        std::to_string(depth) + " joints below the base: kdl_space reads trees at most " +
                            std::to_string(kMaxTreeDepth) + " deep (kdl_parser recurses once per joint)"));
}

const Finding* firstError(const Findings& findings) {
  for (const Finding& f : findings)
    if (f.severity == Severity::Error) return &f;
  return nullptr;
}

}  // namespace kdl_space::rules

// --- XML nesting ------------------------------------------------------------------------------

namespace kdl_space::rules {
namespace {

/// \brief An upper bound of TinyXML's nesting depth: TinyXML 2.6.2 (TiXmlNode::Identify) opens
/// an element only at a '<' followed by a letter, '_' or a byte of 127 or more, so the number
/// of such places bounds the elements it can open, whatever it makes of the rest of the text.
std::size_t elementTags(const std::string& xml) {
  std::size_t n = 0;
  for (std::size_t i = xml.find('<'); i != std::string::npos && i + 1 < xml.size(); i = xml.find('<', i + 1)) {
    const unsigned char c = static_cast<unsigned char>(xml[i + 1]);
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c >= 127) ++n;
  }
  return n;
}

/// Expat's view of the document: element depth, and the constructs TinyXML reads otherwise.
struct Nesting {
  XML_Parser parser = nullptr;
  int depth = 0;
  int deepest = 0;
  std::string refused;  ///< a construct met that makes the measurement unsafe
};

void XMLCALL onStart(void* data, const XML_Char*, const XML_Char**) {
  auto* n = static_cast<Nesting*>(data);
  n->deepest = std::max(n->deepest, ++n->depth);
  if (n->deepest > kMaxXmlDepth) XML_StopParser(n->parser, XML_FALSE);
}

void XMLCALL onEnd(void* data, const XML_Char*) { --static_cast<Nesting*>(data)->depth; }

void refuse(Nesting* n, const std::string& what) {
  n->refused = what + " at line " + std::to_string(XML_GetCurrentLineNumber(n->parser)) +
               " (a URDF needs none; TinyXML reads it differently from XML)";
  XML_StopParser(n->parser, XML_FALSE);
}

void XMLCALL onDoctype(void* data, const XML_Char*, const XML_Char*, const XML_Char*, int) {
  refuse(static_cast<Nesting*>(data), "a DOCTYPE");
}

void XMLCALL onInstruction(void* data, const XML_Char*, const XML_Char*) {
  refuse(static_cast<Nesting*>(data), "a processing instruction");
}

}  // namespace

std::string xmlDepthProblem(const std::string& xml) {
  if (elementTags(xml) <= static_cast<std::size_t>(kMaxXmlDepth)) return "";
  Nesting n;
  n.parser = XML_ParserCreate(nullptr);
  if (!n.parser) return "out of memory while measuring the element nesting";
  XML_SetUserData(n.parser, &n);
  XML_SetElementHandler(n.parser, onStart, onEnd);
  XML_SetStartDoctypeDeclHandler(n.parser, onDoctype);
  XML_SetProcessingInstructionHandler(n.parser, onInstruction);
  constexpr std::size_t kChunk = std::size_t{1} << 30;  // XML_Parse takes an int length
  XML_Status status;
  std::size_t at = 0;
  do {
    const std::size_t len = std::min(kChunk, xml.size() - at);
    at += len;
    status = XML_Parse(n.parser, xml.data() + at - len, static_cast<int>(len), at == xml.size());
  } while (status == XML_STATUS_OK && at < xml.size());
  std::string problem;
  if (n.deepest > kMaxXmlDepth)
    problem = "elements nested more than " + std::to_string(kMaxXmlDepth) + " deep (a URDF nests 4 or 5)";
  else if (!n.refused.empty())
    problem = n.refused + ", in a file of more than " + std::to_string(kMaxXmlDepth) + " elements";
  else if (status != XML_STATUS_OK)
    problem = "line " + std::to_string(XML_GetCurrentLineNumber(n.parser)) + ": " +
              XML_ErrorString(XML_GetErrorCode(n.parser)) + " (a file of more than " +
              std::to_string(kMaxXmlDepth) + " elements is read only when it is well-formed XML)";
  XML_ParserFree(n.parser);
  return problem;
}

}  // namespace kdl_space::rules
