// The links and joints of a URDF as a graph (src/parsers/urdf/urdf_graph.hpp), the one walk the loader and the
// checker share: from urdfdom's model (the loader's reader) and from the document (the
// checker's), it finds the same roots, loops, links not connected and depth; and the loader
// refuses what the checker reports about the graph.
#include <gtest/gtest.h>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "parsers/urdf/urdf_graph.hpp"
#include "parsers/urdf/urdf_xml.hpp"

namespace kdl_space::test {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// What the walk finds in a graph, by link names (sorted: the readers order links differently).
struct Shape {
  std::vector<std::string> roots, several_parents, in_cycles, unconnected;
  std::string reached_twice;  ///< from the only root ("" for none)
  int depth = -1;             ///< of the deepest link below the only root, when it is a tree
};

bool operator==(const Shape& a, const Shape& b) {
  return a.roots == b.roots && a.several_parents == b.several_parents && a.in_cycles == b.in_cycles &&
         a.unconnected == b.unconnected && a.reached_twice == b.reached_twice && a.depth == b.depth;
}

void PrintTo(const Shape& s, std::ostream* os) {
  *os << "roots " << ::testing::PrintToString(s.roots) << ", several parents "
      << ::testing::PrintToString(s.several_parents) << ", in cycles " << ::testing::PrintToString(s.in_cycles)
      << ", unconnected " << ::testing::PrintToString(s.unconnected) << ", reached twice '" << s.reached_twice
      << "', depth " << s.depth;
}

Shape shapeOf(const detail::LinkGraph& g) {
  auto names = [&](const std::vector<int>& links) {
    std::vector<std::string> out;
    for (const int l : links) out.push_back(g.link(l));
    std::sort(out.begin(), out.end());
    return out;
  };
  Shape s;
  const std::vector<int> roots = g.roots();
  s.roots = names(roots);
  s.several_parents = names(g.severalParents());
  std::vector<bool> reached(g.size(), false);
  for (const int r : roots) reached = g.walk(r, detail::WalkOrder::DepthFirst, std::move(reached)).reached;
  std::vector<int> in_cycles, unconnected;
  for (const detail::LinkGraph::Cycle& c : g.cycles(reached))
    in_cycles.insert(in_cycles.end(), c.links.begin(), c.links.end());
  for (int l = 0; l < g.size(); ++l)
    if (!reached[l]) unconnected.push_back(l);
  s.in_cycles = names(in_cycles);
  s.unconnected = names(unconnected);
  if (roots.size() == 1) {
    const detail::Walk w = g.walk(roots.front(), detail::WalkOrder::BreadthFirst);
    if (w.reached_twice >= 0) {
      s.reached_twice = g.link(w.reached_twice);
    } else {
      for (const detail::WalkStep& step : w.steps) s.depth = std::max(s.depth, step.depth);
    }
  }
  return s;
}

/// The checker's view: the document as its reader reads it.
Shape checkerShape(const std::string& xml) {
  detail::UrdfDocument doc;
  std::vector<Finding> findings;
  EXPECT_TRUE(detail::readUrdfXml(xml, doc, findings));
  return shapeOf(detail::linkGraph(doc));
}

/// The loader's view: urdfdom's model; false when urdfdom refuses the document.
bool loaderShape(const std::string& xml, Shape& shape) {
  const console_bridge::LogLevel level = console_bridge::getLogLevel();
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // urdfdom's refusals are expected
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception&) {
  }
  console_bridge::setLogLevel(level);
  if (!model) return false;
  shape = shapeOf(detail::linkGraph(*model));
  return true;
}

bool isGraphFinding(const Finding& f) {
  return f.kind == "no_root" || f.kind == "several_roots" || f.kind == "loop" || f.kind == "missing_link" ||
         f.kind == "too_deep";
}

/// A chain base - l1 - ... - l<n>, and a second branch of `branch` links from the base.
std::string chain(int n, int branch = 0) {
  const std::string inertial =
      R"(<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>)";
  auto link = [&](const std::string& name) { return "<link name=\"" + name + "\">" + inertial + "</link>"; };
  auto joint = [](const std::string& parent, const std::string& child) {
    return "<joint name=\"to_" + child + "\" type=\"continuous\"><parent link=\"" + parent + "\"/><child link=\"" +
           child + "\"/></joint>";
  };
  std::string xml = R"(<robot name="chain">)" + link("base");
  for (const auto& [prefix, length] : {std::pair<std::string, int>{"l", n}, {"b", branch}})
    for (int i = 1; i <= length; ++i) {
      const std::string name = prefix + std::to_string(i);
      xml += joint(i == 1 ? "base" : prefix + std::to_string(i - 1), name) + link(name);
    }
  return xml + "</robot>";
}

/// Every broken file and every fuzz regression.
std::vector<std::string> brokenFiles() {
  std::vector<std::string> files;
  for (const std::string folder : {"/broken_urdf", "/fuzz_regressions/urdf"})
    for (const auto& entry : std::filesystem::directory_iterator(dataDir() + folder))
      if (entry.path().extension() == ".urdf") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(UrdfGraph, SameWalkFromTheLoadersAndTheCheckersReading) {
  // Every broken file, every fuzz regression: where urdfdom reads the document at all, both
  // readers give the walk the same graph.
  int compared = 0;
  for (const std::string& path : brokenFiles()) {
    const std::string xml = readFile(path);
    detail::UrdfDocument doc;
    std::vector<Finding> findings;
    if (!detail::readUrdfXml(xml, doc, findings)) continue;  // not XML, not URDF: no graph
    Shape from_urdfdom;
    if (!loaderShape(xml, from_urdfdom)) continue;
    EXPECT_EQ(from_urdfdom, shapeOf(detail::linkGraph(doc))) << path;
    ++compared;
  }
  EXPECT_GE(compared, 15);
}

TEST(UrdfGraph, WhatItFindsInTheBrokenFiles) {
  const std::string dir = dataDir() + "/broken_urdf/";
  Shape s = checkerShape(readFile(dir + "valid.urdf"));
  EXPECT_EQ(s.roots, std::vector<std::string>{"world"});  // a massless root, floating joint to the base
  EXPECT_TRUE(s.unconnected.empty() && s.several_parents.empty() && s.reached_twice.empty());
  EXPECT_EQ(s.depth, 3);

  s = checkerShape(readFile(dir + "several_roots.urdf"));
  EXPECT_EQ(s.roots, (std::vector<std::string>{"camera", "world"}));
  EXPECT_EQ(s.depth, -1);

  s = checkerShape(readFile(dir + "no_root.urdf"));
  EXPECT_TRUE(s.roots.empty());
  EXPECT_EQ(s.in_cycles, (std::vector<std::string>{"base", "upper_arm"}));
  EXPECT_EQ(s.unconnected, (std::vector<std::string>{"base", "upper_arm"}));

  s = checkerShape(readFile(dir + "loop.urdf"));
  EXPECT_EQ(s.several_parents, std::vector<std::string>{"forearm"});
  EXPECT_EQ(s.reached_twice, "forearm");
  EXPECT_TRUE(s.unconnected.empty());

  s = checkerShape(readFile(dataDir() + "/fuzz_regressions/urdf/self_loop_joint.urdf"));
  EXPECT_EQ(s.in_cycles, std::vector<std::string>{"link2"});
  EXPECT_EQ(s.unconnected, (std::vector<std::string>{"link2", "link3"}));
  EXPECT_EQ(s.reached_twice, "");
}

TEST(UrdfGraph, DepthBelowTheRoot) {
  for (const auto& [n, branch] : std::vector<std::pair<int, int>>{{0, 0}, {3, 0}, {5, 7}, {1001, 2}}) {
    const std::string xml = chain(n, branch);
    Shape from_urdfdom;
    ASSERT_TRUE(loaderShape(xml, from_urdfdom));
    const Shape from_document = checkerShape(xml);
    EXPECT_EQ(from_document.depth, std::max(n, branch));
    EXPECT_EQ(from_urdfdom, from_document);
  }
  // A tree too deep in one branch: both name its first link too deep, in the same words.
  const std::string xml = chain(1001, 3);
  const UrdfReport r = checkUrdfString(xml, "deep.urdf");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind + " " + r.errors[0].element, "too_deep l1001");
  try {
    loadUrdfString(xml, "deep.urdf");
    ADD_FAILURE() << "loaded";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()), "deep.urdf: " + describe(r.errors[0]));
  }
}

TEST(UrdfGraph, TheLoaderRefusesWhatTheCheckerFindsInTheGraph) {
  // Each graph finding of the checker (roots, loops, missing links, depth) is a refusal of the
  // loader; where urdfdom reads the file, the link the checker names in a loop is the loader's.
  int graph_problems = 0;
  for (const std::string& path : brokenFiles()) {
    const UrdfReport r = checkUrdfFile(path);
    std::vector<Finding> graph;
    for (const Finding& f : r.errors)
      if (isGraphFinding(f)) graph.push_back(f);
    if (graph.empty()) continue;
    ++graph_problems;
    Shape unused;
    const bool urdfdom_reads_it = loaderShape(readFile(path), unused);
    try {
      loadUrdfFile(path);
      ADD_FAILURE() << path << " loaded";
    } catch (const ModelError& e) {
      const std::string why = e.what();
      for (const Finding& f : graph)
        if (urdfdom_reads_it && f.kind == "loop")
          EXPECT_NE(why.find("link '" + f.element + "'"), std::string::npos) << path << ": " << why;
    }
  }
  EXPECT_GE(graph_problems, 6);
}

}  // namespace
}  // namespace kdl_space::test
