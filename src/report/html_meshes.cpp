// The meshes of the --html page: where package:// meshes are looked for, each STL and COLLADA file
// read once (or its link drawn as its box of inertia, with a warning), and the mesh files a page
// reads as inputs no output may replace.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "kdl_space/report/html_writer.hpp"
#include "report/page_parts.hpp"

namespace kdl_space::report {
namespace {

/// "stl" or "dae" by the file's extension (any case); "" for a format the page does not read.
std::string meshFormat(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".stl" ? "stl" : ext == ".dae" ? "dae" : "";
}

}  // namespace

std::vector<std::string> meshSearchPath(const std::vector<std::string>& mesh_path_options) {
  std::vector<std::string> dirs = mesh_path_options;
  if (const char* ros = std::getenv("ROS_PACKAGE_PATH")) {
    std::istringstream list(ros);
    for (std::string dir; std::getline(list, dir, ':');)
      if (!dir.empty()) dirs.push_back(dir);
  }
  return dirs;
}

int HtmlWriter::meshIndex(const std::string& path) const {
  for (std::size_t i = 0; i < meshes_.size(); ++i)
    if (meshes_[i].path == path) return static_cast<int>(i);
  return -1;
}

/// Each STL and COLLADA file read once; every other mesh is left to its box of inertia (its
/// mesh_path cleared) with a warning that says why and what to do.
void HtmlWriter::readMeshes() {
  for (auto& [link, list] : visuals_)
    for (LinkVisual& v : list) readMesh(link, v);
}

/// One mesh visual of `link` (a name for the warning): read into meshes_ once per file, or its
/// mesh_path cleared with a warning.
void HtmlWriter::readMesh(const std::string& link, LinkVisual& v) {
  if (v.shape != LinkVisual::Shape::Mesh) return;
  const std::string format = meshFormat(v.mesh_path.empty() ? v.mesh_file : v.mesh_path);
  std::string why;
  if (v.mesh_path.empty()) {
    why = "was not found (" + v.mesh_problem +
          "): give --mesh-path DIR (the folder holding the package's folder) or set ROS_PACKAGE_PATH";
  } else if (format.empty()) {
    why = "(" + v.mesh_path + ") is not drawn: only STL and COLLADA (.dae) meshes are read; convert it to one of them";
  } else if (std::ifstream(format == "stl" ? kStlLoaderJs : kColladaLoaderJs).fail()) {
    why = "is not drawn: three.js's loader is not installed (Debian package libjs-three; tools/deps.sh installs it)";
  } else if (meshIndex(v.mesh_path) < 0) {
    MeshBytes read = readMeshFile(v.mesh_path, format == "dae");
    if (!read.problem.empty()) why = "(" + v.mesh_path + ") " + read.problem + ": check the file";
    else meshes_.push_back({v.mesh_path, format, std::move(read.bytes)});
    if (!read.dropped.empty())
      warnings_.push_back({link, "--html: the mesh " + v.mesh_file + " is drawn without its " + read.dropped,
                           "mesh_reference_dropped", Severity::Warning});
  }
  if (why.empty()) return;
  warnings_.push_back({link, "--html: the mesh " + v.mesh_file + " " + why + "; the page draws the link's box of inertia",
                       "mesh_not_drawn", Severity::Warning});
  v.mesh_path.clear();
}

// --- The meshes a page reads, as inputs no output may replace (issue 25's rule) ----------------
PageVisuals readPageVisuals(const Scenario& sc, const std::vector<std::string>& mesh_search_path) {
  PageVisuals visuals;
  visuals.robot = robotVisuals(sc, mesh_search_path);
  visuals.target = targetVisuals(sc, mesh_search_path);
  return visuals;
}

std::vector<InputFile> meshInputs(const PageVisuals& visuals) {
  std::vector<InputFile> inputs;
  const std::pair<const std::map<std::string, std::vector<LinkVisual>>&, const char*> urdfs[] = {
      {visuals.robot, "link "}, {visuals.target, "the target's link "}};
  for (const auto& [read, whose] : urdfs)
    for (const auto& [link, list] : read)
      for (const LinkVisual& v : list)
        if (v.shape == LinkVisual::Shape::Mesh && !v.mesh_path.empty())
          inputs.push_back({"the mesh " + v.mesh_file + " of " + whose + link, v.mesh_path});
  return inputs;
}

std::vector<InputFile> meshInputs(const Scenario& sc, const std::vector<std::string>& mesh_search_path) {
  return meshInputs(readPageVisuals(sc, mesh_search_path));
}

void checkHtmlLibrary(const std::string& option, const std::string& path) {
  for (const char* file : {kThreeJs, kOrbitControlsJs})
    if (std::ifstream(file).fail())
      throw InputError(option + " " + path + ": three.js is not installed (" + file +
                       "; Debian package libjs-three; tools/deps.sh installs it)");
}

}  // namespace kdl_space::report
