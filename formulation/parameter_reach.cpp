#include "formulation/parameter_reach.h"

namespace mbdae {
namespace {

bool same(const TimeFunction& a, const TimeFunction& b) {
  return a.kind == b.kind && a.a == b.a && a.b == b.b && a.c == b.c && a.d == b.d && a.t0 == b.t0 && a.t1 == b.t1 &&
         a.ts == b.ts && a.ys == b.ys;
}

bool same(const CoordinateFunction& a, const CoordinateFunction& b) {
  return a.rotation == b.rotation && a.ax[0] == b.ax[0] && a.ax[1] == b.ax[1] && a.ax[2] == b.ax[2] &&
         a.index == b.index && a.axis == b.axis && a.child_frame == b.child_frame && a.body_parent == b.body_parent &&
         a.body_child == b.body_child && a.frame_parent == b.frame_parent && a.frame_child == b.frame_child &&
         a.anchor == b.anchor && a.origin == b.origin;
}

bool same_structure(const Constraint& a, const Constraint& b) {
  return a.type == b.type && a.owner == b.owner && a.bi == b.bi && a.bj == b.bj && a.mask == b.mask;
}

bool same(const Constraint& a, const Constraint& b) {
  return same_structure(a, b) && a.si == b.si && a.sj == b.sj && a.ai == b.ai && a.aj == b.aj &&
         a.distance == b.distance && a.w == b.w && same(a.coord, b.coord) && same(a.target, b.target);
}

// A force whose law reads only the numbers compared below.
bool plain(const Force& f) {
  return !f.has_expression() && f.law == nullptr && f.inputs.empty() && f.coordinate_index < 0;
}

bool same(const Force& a, const Force& b) {
  if (a.type != b.type || a.bi != b.bi || a.bj != b.bj || a.si != b.si || a.sj != b.sj) return false;
  if (a.stiffness != b.stiffness || a.damping != b.damping || a.free_length != b.free_length) return false;
  if (!same(a.fx, b.fx) || !same(a.fy, b.fy) || !same(a.fz, b.fz) || !same(a.ground, b.ground)) return false;
  if (a.radius != b.radius || a.axis != b.axis || a.parameters != b.parameters) return false;
  if (a.body_frame != b.body_frame || a.frame_i != b.frame_i || a.frame_j != b.frame_j) return false;
  if (a.kt != b.kt || a.ct != b.ct || a.kr != b.kr || a.cr != b.cr) return false;
  for (int i = 0; i < kForceCoefficients; ++i)
    if (a.coefficient[i] != b.coefficient[i]) return false;
  return true;
}

bool same_size(const System& a, const System& b) {
  return a.bodies.size() == b.bodies.size() && a.constraints.size() == b.constraints.size() &&
         a.forces.size() == b.forces.size();
}

}  // namespace

ParameterReach parameter_reach(const System& run, const System& plus, const System& minus) {
  ParameterReach r;
  for (const System* twin : {&plus, &minus}) {
    if (!same_size(run, *twin)) return r;
    for (size_t k = 0; k < run.constraints.size(); ++k)
      if (!same_structure(run.constraints[k], twin->constraints[k])) return r;
  }
  for (size_t k = 0; k < run.constraints.size(); ++k)
    if (!same(run.constraints[k], plus.constraints[k]) || !same(run.constraints[k], minus.constraints[k]))
      r.constraints.push_back(static_cast<int>(k));
  const bool gravity = run.gravity != plus.gravity || run.gravity != minus.gravity;  // every body's weight
  for (size_t b = 0; b < run.bodies.size(); ++b)
    for (const System* twin : {&plus, &minus})
      if (gravity || run.bodies[b].mass != twin->bodies[b].mass || run.bodies[b].inertia != twin->bodies[b].inertia) {
        r.bodies.push_back(static_cast<int>(b));
        break;
      }
  for (size_t k = 0; k < run.forces.size(); ++k) {
    bool listed = !plain(run.forces[k]);
    for (const System* twin : {&plus, &minus}) listed = listed || !plain(twin->forces[k]) || !same(run.forces[k], twin->forces[k]);
    if (listed) r.forces.push_back(static_cast<int>(k));
  }
  r.local = true;
  return r;
}

}  // namespace mbdae
