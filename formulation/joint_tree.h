// The joint tree of a model, shared by build_system() and the scene validation so that both
// apply the same rules: how a Robotran chain splits into rotations and translations (and which
// chains are refused), the order of the tree from ground outwards, and which bodies are merged
// into one rigid body because every coordinate of their tree joint is locked (an empty chain,
// a weld, counts as locked). Nothing here throws: callers report the problems their own way.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "formulation/model.h"

namespace mbdae {

// "R1 T3" for a chain, "weld" for an empty one.
std::string chain_text(const std::vector<ElementaryJoint>& chain);

// A chain's rotation and translation axes, in chain order.
struct ChainParts {
  std::vector<int> rot, trans;
  bool rotations_first = false;
};
ChainParts split_chain(const std::vector<ElementaryJoint>& chain);

// What the formulation cannot express in a chain ("chain R1 T1 R2 interleaves rotations and
// translations; ...", "chain R1 R1 repeats a rotation axis ..."), first the interleaving, then
// repeated rotation, then repeated translation axes; empty if none.
std::vector<std::string> chain_problems(const std::vector<ElementaryJoint>& chain);

// Whether a tree joint is merged (its child rigidly attached to its parent): every coordinate
// of its chain exists and is locked. A weld (empty chain) is merged.
bool joint_is_merged(const JointSpec& j, const std::map<std::string, CoordinateSpec>& coordinates);

struct JointTree {
  std::vector<const JointSpec*> order;          // tree joints from ground outwards
  std::set<std::string> placed;                 // ground and the bodies with a path to it
  std::map<std::string, std::string> host;      // placed body -> the rigid body it is part of
  std::set<std::string> merged_coordinates;     // coordinates of merged joints
};

// Orders the tree joints (`joint_of_child`: the one tree joint of each body) breadth-first from
// ground, visiting the joints of one parent in file order (`joints`), and finds each placed
// body's host: ground or the child of its nearest joint that is not merged. Bodies on a loop or
// below a body without a joint are not placed.
JointTree resolve_joint_tree(const std::vector<JointSpec>& joints,
                             const std::map<std::string, const JointSpec*>& joint_of_child,
                             const std::map<std::string, CoordinateSpec>& coordinates);

}  // namespace mbdae
