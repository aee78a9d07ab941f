// Point force: f given in world components, or in body axes (a follower force: f = A(p) F, so
// dQ_r/dp = B(p, F), dQ_p/dp = K(s, f) + B(p, s)^T B(p, F)); each component a function of time
// or an expression (LoadInput). Imposed: no potential.
#include "formulation/forces/element.h"

namespace mbdae {
namespace {
using namespace force_element;

void eval(const Force& f, const LocalState& x, const LocalState&, double t, bool, Vec14& q, Mat14* dqx, Mat14*,
          const LoadInput* in, Mat14x3* dqin) {
  if (f.bi < 0) return;
  const Vec3 given(component(f, 0, t, in), component(f, 1, t, in), component(f, 2, t, in));
  Mat3 to_world = Mat3::Identity();  // d(world force)/d(components)
  if (f.body_frame) to_world = rotation(x.pi) * f.frame_i;
  const Vec3 force = to_world * given;
  apply_point_force(f.bi, x.pi, f.si, force, false, q, dqx);
  if (dqx && f.body_frame) {
    const Mat34 dforce = B_matrix(x.pi, f.frame_i * given);
    dqx->block<3, 4>(kRi, kPi4) += dforce;
    dqx->block<4, 4>(kPi4, kPi4) += B_matrix(x.pi, f.si).transpose() * dforce;
  }
  if (dqin) {
    dqin->block<3, 3>(kRi, 0) += to_world;
    dqin->block<4, 3>(kPi4, 0) += B_matrix(x.pi, f.si).transpose() * to_world;
  }
}

double magnitude(const Force& f, const LocalState&, const LocalState&, double t, bool, const LoadInput* in) {
  return Vec3(component(f, 0, t, in), component(f, 1, t, in), component(f, 2, t, in)).norm();
}
}  // namespace

const ForceType& point_force_type() {
  static const ForceType row = {
      "point_force", ForceAttach::kBodyPoint,
      {"name", "type", "body", "point", "fx", "fy", "fz", "frame", "parameters"},
      {}, {"fx", "fy", "fz"}, ForceGlyph::kVector, "m", "N",
      eval, two_point_length, magnitude, nullptr, nullptr};
  return row;
}

}  // namespace mbdae
