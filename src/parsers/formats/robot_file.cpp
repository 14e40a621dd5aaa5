#include "kdl_space/parsers/formats/robot_file.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "kdl_space/parsers/formats/mjcf.hpp"
#include "kdl_space/parsers/formats/sdf_reader.hpp"
#include "kdl_space/parsers/formats/spacedyn_lp.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

/// The first element's name of an XML document's first 64 kB ("" when none is found).
std::string rootElement(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return "";  // a folder, a device, a pipe: never opened here
  std::ifstream in(path, std::ios::binary);
  std::string head(65536, '\0');
  in.read(&head[0], std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  for (std::size_t i = head.find('<'); i != std::string::npos; i = head.find('<', i + 1)) {
    const char c = i + 1 < head.size() ? head[i + 1] : '\0';
    if (c == '?' || c == '!') continue;  // the declaration, a comment, a doctype
    std::size_t e = i + 1;
    while (e < head.size() && (std::isalnum(static_cast<unsigned char>(head[e])) || head[e] == '_' || head[e] == ':')) ++e;
    return head.substr(i + 1, e - i - 1);
  }
  return "";
}

}  // namespace

const char* formatName(RobotFormat format) {
  switch (format) {
    case RobotFormat::Sdf: return "SDF";
    case RobotFormat::Mjcf: return "MJCF";
    case RobotFormat::SpaceDyn: return "SpaceDyn LP";
    default: return "URDF";
  }
}

std::string robotFileKind(const std::string& path) {
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext == ".sdf") return "SDF file";
  if (ext == ".m") return "SpaceDyn LP file";
  if (ext == ".mjcf") return "MJCF file";
  if (ext == ".xml") return "MJCF or URDF file";
  return "URDF file";
}

RobotFormat robotFormat(const std::string& path) {
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext == ".urdf") return RobotFormat::Urdf;
  if (ext == ".sdf") return RobotFormat::Sdf;
  if (ext == ".m") return RobotFormat::SpaceDyn;
  if (ext == ".mjcf") return RobotFormat::Mjcf;
  const std::string root = rootElement(path);
  if (root == "sdf") return RobotFormat::Sdf;
  if (root == "mujoco") return RobotFormat::Mjcf;
  return RobotFormat::Urdf;
}

RobotDocument readRobotDocument(const std::string& path) {
  RobotDocument d;
  d.format = robotFormat(path);
  switch (d.format) {
    case RobotFormat::Sdf: d.urdf = sdfToUrdf(path, d.notes); break;
    case RobotFormat::SpaceDyn: d.urdf = spaceDynToUrdf(path, d.notes); break;
    case RobotFormat::Mjcf: {
      checkInputFile(path, "MJCF file", max_input_file_bytes);
      std::ifstream in(path, std::ios::binary);
      std::stringstream text;
      text << in.rdbuf();
      d.urdf = mjcfToUrdf(text.str(), path, d.notes);
      break;
    }
    case RobotFormat::Urdf: break;
  }
  return d;
}

FloatingModel loadRobotFile(const std::string& path) {
  RobotDocument d = readRobotDocument(path);
  if (d.format == RobotFormat::Urdf) return loadUrdfFile(path);
  return loadUrdfString(d.urdf, path, std::move(d.notes));
}

UrdfReport checkRobotFile(const std::string& path, const std::vector<std::string>& tips) {
  if (robotFormat(path) == RobotFormat::Urdf) return checkUrdfFile(path, tips);
  RobotDocument d;
  try {
    d = readRobotDocument(path);
  } catch (const Error& e) {
    UrdfReport report;
    report.source = path;
    Finding f;
    f.kind = "unreadable";
    f.message = e.what();
    report.errors.push_back(f);
    return report;
  }
  UrdfReport report = checkUrdfString(d.urdf, path, tips);
  for (const Diagnostic& n : d.notes) {
    Finding f;
    f.severity = Severity::Note;
    f.kind = "converted";
    f.message = (n.element.empty() ? "" : "'" + n.element + "': ") + n.message;
    report.notes.push_back(f);
  }
  return report;
}

}  // namespace kdl_space
