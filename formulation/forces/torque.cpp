// Applied torque: magnitude T(t) (or an expression) about a world or body-fixed axis. A torque n
// in world axes contributes Q_p = 2 E(p)^T n, in body axes Q_p = 2 L(p)^T n'; both are linear in
// p: Q_p = 2 T M(a) p with M_world(a) = [0 -a^T; a [a]x], M_body(a) = [0 -a^T; a -[a]x] (forces.h).
#include "formulation/forces/element.h"

namespace mbdae {
namespace {
using namespace force_element;

// The constant matrix M(a) of the torque map Q_p = 2 T M(a) p.
Mat4 torque_map(const Vec3& a, bool body_axes) {
  Mat4 m;
  m(0, 0) = 0;
  m.block<1, 3>(0, 1) = -a.transpose();
  m.block<3, 1>(1, 0) = a;
  m.block<3, 3>(1, 1) = body_axes ? Mat3(-skew(a)) : skew(a);
  return m;
}

void eval(const Force& f, const LocalState& x, const LocalState&, double t, bool, Vec14& q, Mat14* dqx, Mat14*,
          const LoadInput* in, Mat14x3* dqin) {
  if (f.bi < 0) return;
  const double magnitude = component(f, 0, t, in);
  const Mat4 m = torque_map(f.axis, f.body_frame);
  q.segment<4>(kPi4) += 2.0 * magnitude * (m * x.pi);
  if (dqx) dqx->block<4, 4>(kPi4, kPi4) += 2.0 * magnitude * m;
  if (dqin) dqin->block<4, 1>(kPi4, 0) += 2.0 * (m * x.pi);
}

double length(const Force&, const LocalState&, double) { return 0.0; }

double magnitude(const Force& f, const LocalState&, const LocalState&, double t, bool, const LoadInput* in) {
  return component(f, 0, t, in);
}
}  // namespace

const ForceType& torque_type() {
  static const ForceType row = {
      "torque", ForceAttach::kBody,
      {"name", "type", "body", "axis", "frame", "torque", "parameters"},
      {}, {"torque", nullptr, nullptr}, ForceGlyph::kNone, "1", "N m",
      eval, length, magnitude, nullptr, nullptr};
  return row;
}

}  // namespace mbdae
