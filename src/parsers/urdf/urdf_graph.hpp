// The links and joints of a URDF as a graph, and the one walk over it that the loader and the
// checker share: roots, links with several parents, cycles no root reaches, links not connected,
// depth below the base. Private to the library; it judges nothing (the callers word the findings).
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

namespace urdf {
class ModelInterface;  // urdfdom
}

namespace kdl_space::detail {

/// A joint as an edge between two links.
struct GraphJoint {
  std::string name;
  std::string parent_link, child_link;  ///< link names as written ("" if not given)
  int parent = -1, child = -1;          ///< their indices in the graph; -1 if not given or not defined
};

/// One link reached by LinkGraph::walk.
struct WalkStep {
  int link = -1;
  int parent_step = -1;  ///< index of the parent's step; -1 for the link the walk starts from
  int joint = -1;        ///< the joint from the parent (-1 for the start)
  int depth = 0;         ///< joints between the start and this link
};

/// The order of a walk: children in joint order either way, parents before children.
enum class WalkOrder {
  DepthFirst,    ///< a link's whole subtree before its next sibling (the checker lists links so)
  BreadthFirst,  ///< by depth (the loader's first problem is the one nearest the base)
};

/// What a walk from one link reached.
struct Walk {
  std::vector<WalkStep> steps;  ///< in the walk's order
  std::vector<bool> reached;    ///< per link: reached by this walk or held reached before it
  int reached_twice = -1;       ///< the first link met again (its joints close a loop), or -1
  int reached_twice_from = -1;  ///< the step whose joint met it again
};

/// \brief Links and joints in the order their reader met them (the checker: the document's; the
/// loader: urdfdom's, by name). Link names are unique.
class LinkGraph {
 public:
  LinkGraph() = default;
  /// Resolves each joint's link names into indices (-1 for a link that is not in `links`).
  LinkGraph(std::vector<std::string> links, std::vector<GraphJoint> joints);

  int size() const { return static_cast<int>(links_.size()); }
  const std::string& link(int l) const { return links_[l]; }
  const std::vector<GraphJoint>& joints() const { return joints_; }
  /// Index of the link named `name`, or -1.
  int find(const std::string& name) const;
  /// The joints that name link `l` as child (whether their parent exists or not).
  const std::vector<int>& parentJoints(int l) const { return parent_joints_[l]; }
  /// The joints from link `l` to a child that exists.
  const std::vector<int>& childJoints(int l) const { return child_joints_[l]; }

  /// The links no joint names as child, in order: one for a tree.
  std::vector<int> roots() const;
  /// The links that are the child of two joints or more (their joints close a loop), in order.
  std::vector<int> severalParents() const;

  /// \brief The links below `from` (no recursion: the depth may be what is being checked), each
  /// entered once: a link met again, or one already in `reached` (one flag per link, from an
  /// earlier walk; empty for none), is not entered again.
  Walk walk(int from, WalkOrder order, std::vector<bool> reached = {}) const;

  /// A closed chain of links, each the child of the one before (the last's child is the first).
  struct Cycle {
    std::vector<int> links;   ///< parent to child, from its link that comes first
    std::vector<int> joints;  ///< joints[k] goes from links[k] to the next link
  };
  /// \brief The cycles among the links not in `reached` (each link's first parent joint
  /// followed up), in the order of their first links.
  std::vector<Cycle> cycles(const std::vector<bool>& reached) const;

 private:
  std::vector<std::string> links_;
  std::unordered_map<std::string, int> index_;  ///< link name -> index
  std::vector<GraphJoint> joints_;
  std::vector<std::vector<int>> parent_joints_, child_joints_;
};

/// The index of the first step of `walk` more than `depth` joints below its start, or -1.
int firstDeeperThan(const Walk& walk, int depth);

/// \brief urdfdom's model as a graph (the loader's view): links and joints by name, the order
/// in which urdfdom links them (a link's children in the order of their joints' names).
LinkGraph linkGraph(const urdf::ModelInterface& model);

}  // namespace kdl_space::detail
