// Joint friction: Coulomb friction on a joint coordinate q, smoothly regularized,
//   tau(q') = -F tanh(q' / w)     (a torque on a rotation, a force on a translation),
// F the friction level (`friction`, >= 0) and w the slip rate (`slip_rate`, > 0) over which it
// builds up (76 % of F at q' = w, 99.9 % at 3.8 w). With G and H the coordinate's gradient and
// Hessian (coordinate_jet), s = G v its rate and phi = tau(s), phi' = -(F / w) (1 - tanh^2(s / w)):
//   Q = phi G^T,  dQ/dx = phi' G^T (H v)^T + phi H,  dQ/dv = phi' G^T G.
// At rest the law is a viscous damper of coefficient F / w: small w is closer to Coulomb's law
// but stiff (time constant J w / F for an inertia J), and under a load T < F the joint creeps at
// w atanh(T / F) instead of sticking. Dissipative: no potential; smooth: no events.
#include <cmath>

#include "formulation/forces/element.h"

namespace mbdae {
namespace {

double friction(const Force& f) { return f.coefficient[0]; }
double slip_rate(const Force& f) { return f.coefficient[1]; }

void eval(const Force& f, const LocalState& x, const LocalState& v, double, bool, Vec14& q, Mat14* dqx,
          Mat14* dqv, const LoadInput*, Mat14x3*) {
  const ScalarJet jet = coordinate_jet(f.coordinate, x);
  const Vec14 vl = local_vector(v);
  const double th = std::tanh(jet.grad.dot(vl) / slip_rate(f));
  const double phi = -friction(f) * th;
  q.noalias() += phi * jet.grad.transpose();
  if (!dqx) return;
  const double dphi = -friction(f) / slip_rate(f) * (1.0 - th * th);
  dqx->noalias() += dphi * jet.grad.transpose() * (jet.hess * vl).transpose();
  *dqx += phi * jet.hess;
  dqv->noalias() += dphi * jet.grad.transpose() * jet.grad;
}

double length(const Force& f, const LocalState& x, double) { return coordinate_jet(f.coordinate, x).value; }

// The generalized force on the coordinate, tau(q').
double magnitude(const Force& f, const LocalState& x, const LocalState& v, double, bool, const LoadInput*) {
  const ScalarJet jet = coordinate_jet(f.coordinate, x);
  return -friction(f) * std::tanh(jet.grad.dot(local_vector(v)) / slip_rate(f));
}
}  // namespace

const ForceType& joint_friction_type() {
  static const ForceType row = {
      "joint_friction", ForceAttach::kCoordinate,
      {"name", "type", "coordinate", "friction", "slip_rate"},
      {{"friction", "N m", "N", ParameterRange::kNonNegative, true, false,
        [](ForceSpec& s) { return &s.coefficient[0]; }, [](Force& f) { return &f.coefficient[0]; }},
       {"slip_rate", "rad/s", "m/s", ParameterRange::kPositive, true, false,
        [](ForceSpec& s) { return &s.coefficient[1]; }, [](Force& f) { return &f.coefficient[1]; }}},
      {nullptr, nullptr, nullptr}, ForceGlyph::kNone, "rad", "N m",
      eval, length, magnitude, nullptr, nullptr};
  return row;
}

}  // namespace mbdae
