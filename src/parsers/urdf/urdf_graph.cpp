#include "parsers/urdf/urdf_graph.hpp"

#include <urdf_model/model.h>

#include <algorithm>

namespace kdl_space::detail {

LinkGraph::LinkGraph(std::vector<std::string> links, std::vector<GraphJoint> joints)
    : links_(std::move(links)), joints_(std::move(joints)),
      parent_joints_(links_.size()), child_joints_(links_.size()) {
  for (std::size_t l = 0; l < links_.size(); ++l) index_.emplace(links_[l], static_cast<int>(l));
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    GraphJoint& joint = joints_[j];
    joint.parent = joint.parent_link.empty() ? -1 : find(joint.parent_link);
    joint.child = joint.child_link.empty() ? -1 : find(joint.child_link);
    if (joint.child >= 0) parent_joints_[joint.child].push_back(static_cast<int>(j));
    if (joint.parent >= 0 && joint.child >= 0) child_joints_[joint.parent].push_back(static_cast<int>(j));
  }
}

int LinkGraph::find(const std::string& name) const {
  const auto it = index_.find(name);
  return it == index_.end() ? -1 : it->second;
}

std::vector<int> LinkGraph::roots() const {
  std::vector<int> roots;
  for (int l = 0; l < size(); ++l)
    if (parent_joints_[l].empty()) roots.push_back(l);
  return roots;
}

std::vector<int> LinkGraph::severalParents() const {
  std::vector<int> links;
  for (int l = 0; l < size(); ++l)
    if (parent_joints_[l].size() >= 2) links.push_back(l);
  return links;
}

Walk LinkGraph::walk(int from, WalkOrder order, std::vector<bool> reached) const {
  Walk w;
  w.reached = std::move(reached);
  w.reached.resize(links_.size(), false);
  struct Item {
    int link, parent_step, joint;
  };
  // Depth first: a stack, children pushed last first. Breadth first: a queue, from `next` on.
  const bool depth_first = order == WalkOrder::DepthFirst;
  std::vector<Item> pending{{from, -1, -1}};
  std::size_t next = 0;
  while (next < pending.size()) {
    const Item item = depth_first ? pending.back() : pending[next++];
    if (depth_first) pending.pop_back();
    if (w.reached[item.link]) {
      if (w.reached_twice < 0) w.reached_twice = item.link, w.reached_twice_from = item.parent_step;
      continue;
    }
    w.reached[item.link] = true;
    const int depth = item.parent_step < 0 ? 0 : w.steps[item.parent_step].depth + 1;
    const int step = static_cast<int>(w.steps.size());
    w.steps.push_back({item.link, item.parent_step, item.joint, depth});
    const std::vector<int>& children = child_joints_[item.link];
    if (depth_first)
      for (auto it = children.rbegin(); it != children.rend(); ++it) pending.push_back({joints_[*it].child, step, *it});
    else
      for (const int j : children) pending.push_back({joints_[j].child, step, j});
  }
  return w;
}

std::vector<LinkGraph::Cycle> LinkGraph::cycles(const std::vector<bool>& reached) const {
  std::vector<Cycle> found;
  std::vector<int> state(links_.size(), 0);  // 0 unvisited, 1 on the current path, 2 done
  for (int start = 0; start < size(); ++start) {
    if (reached[start] || state[start] != 0) continue;
    std::vector<int> path;  // child to parent
    int l = start;
    while (l >= 0 && state[l] == 0) {
      state[l] = 1;
      path.push_back(l);
      const std::vector<int>& up = parent_joints_[l];
      l = up.empty() ? -1 : joints_[up.front()].parent;
    }
    if (l >= 0 && state[l] == 1) {
      Cycle cycle;
      cycle.links.assign(std::find(path.begin(), path.end(), l), path.end());
      std::reverse(cycle.links.begin(), cycle.links.end());
      std::rotate(cycle.links.begin(), std::min_element(cycle.links.begin(), cycle.links.end()), cycle.links.end());
      for (std::size_t k = 0; k < cycle.links.size(); ++k)
        cycle.joints.push_back(parent_joints_[cycle.links[(k + 1) % cycle.links.size()]].front());
      found.push_back(std::move(cycle));
    }
    for (const int p : path) state[p] = 2;
  }
  return found;
}

int firstDeeperThan(const Walk& walk, int depth) {
  for (std::size_t i = 0; i < walk.steps.size(); ++i)
    if (walk.steps[i].depth > depth) return static_cast<int>(i);
  return -1;
}

LinkGraph linkGraph(const urdf::ModelInterface& model) {
  std::vector<std::string> links;
  for (const auto& entry : model.links_) links.push_back(entry.first);
  std::vector<GraphJoint> joints;
  for (const auto& [name, joint] : model.joints_)
    joints.push_back({name, joint->parent_link_name, joint->child_link_name});
  return LinkGraph(std::move(links), std::move(joints));
}

}  // namespace kdl_space::detail
