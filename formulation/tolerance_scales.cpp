#include "formulation/tolerance_scales.h"

#include <algorithm>
#include <cmath>

#include "formulation/euler_parameters.h"

namespace mbdae {
namespace {

struct Box {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  double extent() const { return lo.x() > hi.x() ? 0.0 : (hi - lo).maxCoeff(); }
};

// World position of local point s of body b (b < 0: ground, s is a world point).
Vec3 world_point(const double* q, int b, const Vec3& s) {
  if (b < 0) return s;
  const Vec3 r(q[7 * b], q[7 * b + 1], q[7 * b + 2]);
  const Vec4 p(q[7 * b + 3], q[7 * b + 4], q[7 * b + 5], q[7 * b + 6]);
  return r + rotate(p, s);
}

double element_mass(const System& sys, int bi, int bj) {
  double m = 0;
  for (int b : {bi, bj})
    if (b >= 0 && sys.bodies[b].mass > 0) m = m > 0 ? std::min(m, sys.bodies[b].mass) : sys.bodies[b].mass;
  return m;
}

}  // namespace

ModelScales model_scales(const System& sys, const double* q, double t0, double t1) {
  Box box;
  for (int b = 0; b < sys.num_bodies(); ++b) box.add(world_point(q, b, Vec3::Zero()));
  for (const auto& c : sys.constraints) {
    if (c.type != Constraint::Type::kPoint && c.type != Constraint::Type::kDot2 &&
        c.type != Constraint::Type::kDistance)
      continue;
    box.add(world_point(q, c.bi, c.si));
    box.add(world_point(q, c.bj, c.sj));
  }
  for (const auto& f : sys.forces) {
    if (f.bi >= 0) box.add(world_point(q, f.bi, f.si));
    if (f.bj >= 0) box.add(world_point(q, f.bj, f.sj));
  }
  for (const auto& s : sys.sensors)
    if (s.body >= 0) box.add(world_point(q, s.body, s.point));
  ModelScales s;
  s.length = box.extent() > 0 ? box.extent() : 1.0;
  const double span = t1 > t0 ? t1 - t0 : 1.0, g = sys.gravity.norm();
  s.time = g > 0 ? std::min(span, std::sqrt(s.length / g)) : span;
  s.span = span;
  s.fast_time = s.time;
  for (const auto& f : sys.forces) {
    const double m = element_mass(sys, f.bi, f.bj);
    if (f.stiffness > 0 && m > 0) s.fast_time = std::min(s.fast_time, std::sqrt(m / f.stiffness));
  }
  return s;
}

AbsoluteTolerances absolute_tolerances(const ModelScales& s, double position_atol) {
  AbsoluteTolerances a;
  a.position = position_atol;
  a.rotation = position_atol / s.length;
  a.velocity = position_atol / s.time;
  a.rotation_rate = a.rotation / s.time;
  a.time = s.time;
  a.length = s.length;
  a.span = s.span;
  return a;
}

double default_position_atol(const ModelScales& s, double rtol) {
  return kPositionAtolFactor * rtol * s.length;
}

double default_baumgarte_rate(const ModelScales& s, double per_fast_time) { return per_fast_time / s.fast_time; }

}  // namespace mbdae
