#include "formulation/joint_tree.h"

namespace mbdae {

std::string chain_text(const std::vector<ElementaryJoint>& chain) {
  std::string s;
  for (const auto& e : chain) {
    if (!s.empty()) s += ' ';
    s += (e.rotation ? 'R' : 'T');
    s += static_cast<char>('1' + e.axis);
  }
  return s.empty() ? "weld" : s;
}

ChainParts split_chain(const std::vector<ElementaryJoint>& chain) {
  ChainParts parts;
  for (const auto& e : chain) (e.rotation ? parts.rot : parts.trans).push_back(e.axis);
  parts.rotations_first = !chain.empty() && chain.front().rotation;
  return parts;
}

std::vector<std::string> chain_problems(const std::vector<ElementaryJoint>& chain) {
  std::vector<std::string> out;
  int switches = 0;
  for (size_t k = 1; k < chain.size(); ++k)
    if (chain[k].rotation != chain[k - 1].rotation) ++switches;
  const std::string text = "chain " + chain_text(chain);
  if (switches > 1)
    out.push_back(text + " interleaves rotations and translations; split it with an intermediate body");
  const ChainParts parts = split_chain(chain);
  for (const auto* axes : {&parts.rot, &parts.trans}) {
    const std::set<int> s(axes->begin(), axes->end());
    if (s.size() != axes->size())
      out.push_back(text + " repeats a " + (axes == &parts.rot ? "rotation" : "translation") +
                    " axis (proper Euler sequences are not supported)");
  }
  return out;
}

bool joint_is_merged(const JointSpec& j, const std::map<std::string, CoordinateSpec>& coordinates) {
  for (const auto& e : j.chain) {
    auto it = coordinates.find(e.coordinate);
    if (it == coordinates.end() || it->second.mode != CoordinateSpec::Mode::kLocked) return false;
  }
  return true;
}

JointTree resolve_joint_tree(const std::vector<JointSpec>& joints,
                             const std::map<std::string, const JointSpec*>& joint_of_child,
                             const std::map<std::string, CoordinateSpec>& coordinates) {
  JointTree tree;
  tree.placed.insert(kGround);
  tree.host[kGround] = kGround;
  // Breadth-first from ground over the joints by parent (linear in the number of joints).
  std::map<std::string, std::vector<const JointSpec*>> by_parent;
  for (const auto& j : joints) {
    auto it = joint_of_child.find(j.child);
    if (it != joint_of_child.end() && it->second == &j) by_parent[j.parent].push_back(&j);
  }
  std::vector<std::string> frontier = {kGround};
  while (!frontier.empty()) {
    std::vector<std::string> next;
    for (const auto& parent : frontier)
      for (const JointSpec* j : by_parent[parent])
        if (tree.placed.insert(j->child).second) {
          tree.order.push_back(j);
          next.push_back(j->child);
        }
    frontier.swap(next);
  }
  for (const JointSpec* j : tree.order) {
    const bool merge = joint_is_merged(*j, coordinates);
    tree.host[j->child] = merge ? tree.host[j->parent] : j->child;
    if (merge)
      for (const auto& e : j->chain) tree.merged_coordinates.insert(e.coordinate);
  }
  return tree;
}

}  // namespace mbdae
