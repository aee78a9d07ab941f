// Joint spring-damper: tau = k (q - q0) + c q' on a joint coordinate q(x) with gradient G and
// Hessian H (coordinate_jet): Q = -tau G^T, dQ/dx = -G^T (k G + c (H v)^T) - tau H,
// dQ/dv = -c G^T G. A rotation q counts whole turns (LoadInput::turns, from CoordinateTurns: a
// spring wound 10 rad gives -10 k), or with `wrap` q - q0 is wrapped to (-pi, pi].
#include "formulation/forces/element.h"

namespace mbdae {
namespace {

// q - rest: wrapped to (-pi, pi] if asked, else with the whole turns of the load input added.
double joint_stretch(const Force& f, double measured, const LoadInput* in) {
  if (f.wrap && f.coordinate.rotation) return wrap_angle(measured - f.free_length);
  return measured + (in ? in->turns : 0.0) - f.free_length;
}

void eval(const Force& f, const LocalState& x, const LocalState& v, double, bool, Vec14& q, Mat14* dqx,
          Mat14* dqv, const LoadInput* in, Mat14x3*) {
  const ScalarJet jet = coordinate_jet(f.coordinate, x);
  const Vec14 vl = local_vector(v);
  const double stretch = joint_stretch(f, jet.value, in);
  const double rate = jet.grad.dot(vl);
  const double tau = f.stiffness * stretch + f.damping * rate;
  q.noalias() -= tau * jet.grad.transpose();
  if (!dqx) return;
  const Row14 drate_dx = (jet.hess * vl).transpose();
  dqx->noalias() -= jet.grad.transpose() * (f.stiffness * jet.grad + f.damping * drate_dx);
  *dqx -= tau * jet.hess;
  dqv->noalias() -= f.damping * jet.grad.transpose() * jet.grad;
}

double length(const Force& f, const LocalState& x, double) { return coordinate_jet(f.coordinate, x).value; }

// The generalized force on the coordinate, -tau (a torque for a rotation).
double magnitude(const Force& f, const LocalState& x, const LocalState& v, double t, bool, const LoadInput* in) {
  Vec14 q = Vec14::Zero();
  eval(f, x, v, t, false, q, nullptr, nullptr, in, nullptr);
  const ScalarJet jet = coordinate_jet(f.coordinate, x);
  return q.dot(jet.grad.transpose()) / jet.grad.squaredNorm();
}

double potential(const Force& f, const LocalState& x, double, bool, const LoadInput* in) {
  const double stretch = joint_stretch(f, coordinate_jet(f.coordinate, x).value, in);
  return 0.5 * f.stiffness * stretch * stretch;
}
}  // namespace

const ForceType& joint_spring_damper_type() {
  static const ForceType row = {
      "joint_spring_damper", ForceAttach::kCoordinate,
      {"name", "type", "coordinate", "stiffness", "damping", "rest", "rest_deg", "wrap"},
      {{"stiffness", "N m/rad", "N/m", ParameterRange::kNonNegative, true, false,
        [](ForceSpec& s) { return &s.stiffness; }, [](Force& f) { return &f.stiffness; }},
       {"damping", "N m s/rad", "N s/m", ParameterRange::kNonNegative, false, false,
        [](ForceSpec& s) { return &s.damping; }, [](Force& f) { return &f.damping; }},
       {"rest", "rad", "m", ParameterRange::kAny, false, false,
        [](ForceSpec& s) { return &s.free_length; }, [](Force& f) { return &f.free_length; }}},
      {nullptr, nullptr, nullptr}, ForceGlyph::kNone, "rad", "N m",
      eval, length, magnitude, potential, nullptr};
  return row;
}

}  // namespace mbdae
