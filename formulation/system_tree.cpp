// Stage 1 of build_system(): names and references of bodies and joints, and the joint tree
// (formulation/joint_tree.h, the rules the scene validation applies too).
#include "core/errors.h"
#include "formulation/system_build.h"

namespace mbdae {

void fail(const SourceLocation& w, const std::string& field, const std::string& m) {
  throw ModelError(w.file, w.line, field, m);
}

Vec3 ModelIndex::anchor_of(const JointSpec& j) const {
  if (j.anchor_point.empty()) return j.anchor;
  const auto& pts = j.parent == kGround ? model.ground_points : bodies.at(j.parent)->points;
  auto it = pts.find(j.anchor_point);
  if (it == pts.end())
    fail(j.where, "anchor", "body '" + j.parent + "' has no point '" + j.anchor_point + "'");
  return it->second;
}

std::pair<const BodyFrame*, Vec3> point_of(const ModelIndex& index, const System& sys,
                                           const std::string& body, const std::string& point,
                                           const SourceLocation& w, const std::string& field) {
  auto it = sys.frames.find(body);
  if (it == sys.frames.end()) fail(w, field, "no body named '" + body + "'");
  if (point.empty() || point == "origin") return {&it->second, it->second.local_point(Vec3::Zero())};
  if (body == kGround) {
    auto gp = index.model.ground_points.find(point);
    if (gp == index.model.ground_points.end()) fail(w, field, "ground has no point '" + point + "'");
    return {&it->second, gp->second};
  }
  const BodySpec* b = index.bodies.at(body);
  if (point == "com") return {&it->second, it->second.local_point(b->com)};
  auto pt = b->points.find(point);
  if (pt == b->points.end()) fail(w, field, "body '" + body + "' has no point '" + point + "'");
  return {&it->second, it->second.local_point(pt->second)};
}

ModelIndex resolve_tree(const Model& model) {
  ModelIndex index{model, {}, {}, {}};
  for (const auto& b : model.bodies) {
    if (b.name == kGround) fail(b.where, "name", "'ground' is reserved");
    if (!index.bodies.emplace(b.name, &b).second)
      fail(b.where, "name", "body '" + b.name + "' is defined twice");
  }
  for (const auto& j : model.joints) {
    if (j.parent != kGround && !index.bodies.count(j.parent))
      fail(j.where, "parent", "joint '" + j.name + "': no body named '" + j.parent + "'");
    if (!index.bodies.count(j.child))
      fail(j.where, "child", "joint '" + j.name + "': no body named '" + j.child + "'");
    if (!index.joint_of_child.emplace(j.child, &j).second)
      fail(j.where, "child", "body '" + j.child + "' is the child of two tree joints; make one a cut");
    for (const auto& e : j.chain)
      if (!model.coordinates.count(e.coordinate))
        fail(j.where, "coordinates", "joint '" + j.name + "': coordinate '" + e.coordinate + "' has no entry");
  }
  index.tree = resolve_joint_tree(model.joints, index.joint_of_child, model.coordinates);
  for (const auto& b : model.bodies)
    if (!index.tree.placed.count(b.name)) {
      auto it = index.joint_of_child.find(b.name);
      if (it != index.joint_of_child.end())
        fail(it->second->where, "parent",
             "body '" + b.name + "' has no path to ground (the joint tree has a loop)");
      fail(b.where, "name", "body '" + b.name + "' has no joint to a parent (no path to ground)");
    }
  return index;
}

}  // namespace mbdae
