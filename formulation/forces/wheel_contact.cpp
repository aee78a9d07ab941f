// Wheel contact: vertical f_z = K_t e at point1 of body1 when in contact, e = r cos(camber) -
// (z - z_g(t)), camber from the wheel's spin axis u: cos(camber) = sqrt(1 - u_z^2). Whether the
// wheel is in contact is a mode switched by events (root of e), not a max() inside the Newton
// iteration. Potential 1/2 K e^2 in contact.
#include <algorithm>

#include "formulation/forces/element.h"

namespace mbdae {
namespace {
using namespace force_element;

struct Contact {
  double e;
  Eigen::Matrix<double, 1, 14> de;
};
Contact contact(const Force& f, const LocalState& x, double t, bool with_gradient) {
  Contact c;
  const Vec3 u = rotate(x.pi, f.axis);
  const Vec3 pc = point(f.bi, x.ri, x.pi, f.si);
  const double cosc = std::sqrt(std::max(0.0, 1.0 - u.z() * u.z()));
  c.e = f.radius * cosc - (pc.z() - f.ground.value(t));
  if (with_gradient) {
    c.de.setZero();
    c.de(kRi + 2) = -1.0;
    c.de.segment<4>(kPi4) = -B_matrix(x.pi, f.si).row(2);
    c.de.segment<4>(kPi4) += -f.radius * u.z() / cosc * B_matrix(x.pi, f.axis).row(2);
  }
  return c;
}

void eval(const Force& f, const LocalState& x, const LocalState&, double t, bool in_contact, Vec14& q, Mat14* dqx,
          Mat14*, const LoadInput*, Mat14x3*) {
  if (!in_contact) return;
  const Contact c = contact(f, x, t, dqx != nullptr);
  const Vec3 force(0, 0, f.stiffness * c.e);
  apply_point_force(f.bi, x.pi, f.si, force, false, q, dqx);
  if (dqx) {
    const Eigen::Matrix<double, 3, 14> g = point_jacobian(f.bi, x.pi, f.si, false);
    dqx->noalias() += g.row(2).transpose() * (f.stiffness * c.de);
  }
}

// The penetration e (depends on the ground height at t): length and switching function.
double penetration(const Force& f, const LocalState& x, double t) { return contact(f, x, t, false).e; }

double magnitude(const Force& f, const LocalState& x, const LocalState&, double t, bool in_contact,
                 const LoadInput*) {
  return in_contact ? f.stiffness * contact(f, x, t, false).e : 0.0;
}

double potential(const Force& f, const LocalState& x, double t, bool in_contact, const LoadInput*) {
  if (!in_contact) return 0.0;
  const double e = penetration(f, x, t);
  return 0.5 * f.stiffness * e * e;
}
}  // namespace

const ForceType& wheel_contact_type() {
  static const ForceType row = {
      "wheel_contact", ForceAttach::kBodyPoint,
      {"name", "type", "body", "point", "stiffness", "radius", "axis", "ground"},
      {{"stiffness", "N/m", "", ParameterRange::kPositive, true, true,
        [](ForceSpec& s) { return &s.stiffness; }, [](Force& f) { return &f.stiffness; }},
       {"radius", "m", "", ParameterRange::kPositive, true, true,
        [](ForceSpec& s) { return &s.radius; }, [](Force& f) { return &f.radius; }}},
      {nullptr, nullptr, nullptr}, ForceGlyph::kWheel, "m", "N",
      eval, penetration, magnitude, potential, penetration};
  return row;
}

}  // namespace mbdae
