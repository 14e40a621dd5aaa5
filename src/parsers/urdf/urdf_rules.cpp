#include "parsers/urdf/urdf_rules.hpp"

#include <expat.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "spatial/message_text.hpp"

namespace kdl_space::rules {

void checkRootInertia(const std::string& root, bool has_inertial, Findings& out) {
  if (has_inertial)
    out.push_back(note("root_inertia_dropped_by_kdl_parser", ElementType::Link, root,
                       "root link inertia kept as the base body's inertia (kdl_parser drops it: tools "
                       "built on kdl_parser alone see a massless base)"));
}

bool dropsRootJoint(bool root_massless, std::size_t root_child_joints, const std::string& child_joint_type) {
  // A mobile base's planar joint from the world is dropped as a floating one: in orbit the base
  // floats in all six directions.
  return root_massless && root_child_joints == 1 && (child_joint_type == "floating" || child_joint_type == "planar");
}

void checkJointType(const std::string& joint, const std::string& type, Findings& out) {
  if (type != "floating" && type != "planar") return;
  std::string message = "a " + type +
                        " joint inside the tree is not supported (only the base floats; use revolute, "
                        "continuous, prismatic or fixed joints)";
  if (type == "floating")
    message += "; a floating joint is accepted only from a massless root link (such as 'world') to "
               "its only child, the base";
  else
    message += "; a planar joint is accepted only from a massless root link (such as 'world') to its only "
               "child, the base, which then floats";
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

void checkRevoluteWithoutLimit(const std::string& joint, Findings& out) {
  out.push_back(warning("revolute_without_limit", ElementType::Joint, joint,
                        "a revolute joint without <limit> (urdfdom refuses it): read as continuous, "
                        "without position, effort or velocity limits"));
}

void checkMimic(const std::string& joint, const std::string& leader, bool leader_movable, double multiplier,
                double offset, Findings& out) {
  if (!leader_movable) {
    out.push_back(error("bad_mimic", ElementType::Joint, joint,
                        "mimics " + detail::quoted(leader) + ", which is no movable joint of the file: name a "
                        "revolute, continuous or prismatic joint, or remove the <mimic>"));
    return;
  }
  if (!std::isfinite(multiplier) || multiplier == 0.0 || !std::isfinite(offset)) {
    out.push_back(error("bad_mimic", ElementType::Joint, joint,
                        "its <mimic> multiplier must be finite and non-zero, its offset finite"));
    return;
  }
  if (std::abs(multiplier) > kMaxMimicMultiplier) {  // T^T H T would overflow; no coupling is such
    out.push_back(error("bad_mimic", ElementType::Joint, joint,
                        "its <mimic> multiplier " + number(multiplier) + " is beyond +-" + number(kMaxMimicMultiplier) +
                            " (a coupling's ratio is a few units; the coupled inertia, multiplier^2 times the "
                            "follower's, would overflow): check the number"));
    return;
  }
  out.push_back(note("mimic_joint", ElementType::Joint, joint,
                     "follows joint " + detail::quoted(leader) + " (q = " + number(multiplier) + " q_" + leader +
                         (offset == 0.0 ? std::string() : " + " + number(offset)) +
                         "): not a coordinate"));
}

void checkMimicCycles(const std::vector<std::pair<std::string, std::string>>& follows, Findings& out) {
  const auto leaderOf = [&follows](const std::string& joint) -> const std::string* {
    for (const auto& [follower, leader] : follows)
      if (follower == joint) return &leader;
    return nullptr;
  };
  for (const auto& [joint, first] : follows) {
    const std::string* at = &first;
    for (std::size_t steps = 0; at && steps <= follows.size(); ++steps) {
      if (*at == joint) {
        out.push_back(error("bad_mimic", ElementType::Joint, joint,
                            "its <mimic> joints form a cycle: none is a coordinate; let one of them "
                            "follow no other"));
        break;
      }
      at = leaderOf(*at);
    }
  }
}

void checkDepth(const std::string& link, int depth, Findings& out) {
  if (depth > kMaxTreeDepth)
    out.push_back(error("too_deep", ElementType::Link, link,
                        std::to_string(depth) + " joints below the base: kdl_space reads trees at most " +
                            std::to_string(kMaxTreeDepth) + " deep (kdl_parser recurses once per joint)"));
}

std::string xacroProblem(const std::string& xml) {
  std::size_t at = std::string::npos;
  std::string what;
  // Not the xmlns:xacro attribute alone: xacro's output keeps it on <robot>.
  const std::pair<const char*, const char*> marks[] = {{"<xacro:", "a <xacro:...> element"},
                                                       {"$(arg ", "an $(arg ...)"},
                                                       {"$(find ", "a $(find ...)"},
                                                       {"${", "a ${...} expression"}};
  // Outside comments: xacro copies them into its output as written, ${...} and all.
  const auto outsideComments = [&xml](const char* mark) {
    for (std::size_t from = 0;;) {
      const std::size_t found = xml.find(mark, from);
      if (found == std::string::npos) return found;
      const std::size_t open = xml.rfind("<!--", found);
      const std::size_t close = open == std::string::npos ? std::string::npos : xml.find("-->", open + 4);
      if (open == std::string::npos || close == std::string::npos || close + 3 <= found) return found;
      from = close + 3;  // inside a comment: look after it
    }
  };
  for (const auto& [mark, name] : marks) {
    const std::size_t found = outsideComments(mark);
    if (found < at) at = found, what = name;
  }
  if (at == std::string::npos) return "";
  const long line = 1 + std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  return "an unexpanded xacro file (" + what + " at line " + std::to_string(line) +
         "): expand it first, e.g. xacro FILE.urdf.xacro > FILE.urdf (Debian's ros-xacro, or ROS's xacro), "
         "then give kdl_space the .urdf";
}

// --- XML nesting ------------------------------------------------------------------------------

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
