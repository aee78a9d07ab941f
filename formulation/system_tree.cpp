// Stage 1 of build_system(): the bodies and joints by name, and the joint tree
// (formulation/joint_tree.h). The rules a model must meet are check_model()'s
// (formulation/model_rules.h); the lookups here fail only on a model that skipped them.
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

// The model passed check_model() (build_system): names are unique, references resolve and
// every body has a path to ground.
ModelIndex resolve_tree(const Model& model) {
  ModelIndex index{model, {}, {}, {}};
  for (const auto& b : model.bodies) index.bodies.emplace(b.name, &b);
  for (const auto& j : model.joints) index.joint_of_child.emplace(j.child, &j);
  index.tree = resolve_joint_tree(model.joints, index.joint_of_child, model.coordinates);
  return index;
}

}  // namespace mbdae
