// User force laws: a registered function f(d, d_dot, t, parameters) of the relative position and
// velocity of two points (force on point 1, reaction on point 2); no potential is known for it.
#include <algorithm>
#include <map>

#include "formulation/forces/element.h"

namespace mbdae {
namespace {
using namespace force_element;

// The force laws, built once on first use and never changed afterwards (no global mutable
// state: runs in several threads read it at once). A new law is one more entry here.
// Built-in example: a linear bushing. With d = P2 - P1, the force on point 1 is f = k d + c d_dot,
// which pulls it towards point 2 (restoring); point 2 gets -f.
std::map<std::string, UserForceLaw> builtin_laws() {
  std::map<std::string, UserForceLaw> laws;
  UserForceLaw bushing;
  bushing.name = "linear_bushing";
  bushing.parameter_names = {"stiffness", "damping"};
  bushing.force = [](const Vec3& d, const Vec3& dd, double, const double* p) -> Vec3 {
    return p[0] * d + p[1] * dd;  // pulls point 1 towards point 2
  };
  laws[bushing.name] = bushing;
  return laws;
}

// The law's force and its Jacobians (the law's own, or central differences).
void user_law(const Force& f, const TwoPoint& tp, double t, Vec3& force, Mat3* df_dd, Mat3* df_ddd) {
  const double* prm = f.parameters.data();
  force = f.law->force(tp.d, tp.dd, t, prm);
  if (!df_dd) return;
  if (f.law->jacobian) {
    f.law->jacobian(tp.d, tp.dd, t, prm, *df_dd, *df_ddd);
    return;
  }
  for (int k = 0; k < 3; ++k) {
    const double h1 = 1e-6 * std::max(1.0, std::fabs(tp.d[k]));
    const double h2 = 1e-6 * std::max(1.0, std::fabs(tp.dd[k]));
    Vec3 a = tp.d, b = tp.d;
    a[k] += h1;
    b[k] -= h1;
    df_dd->col(k) = (f.law->force(a, tp.dd, t, prm) - f.law->force(b, tp.dd, t, prm)) / (2 * h1);
    a = tp.dd;
    b = tp.dd;
    a[k] += h2;
    b[k] -= h2;
    df_ddd->col(k) = (f.law->force(tp.d, a, t, prm) - f.law->force(tp.d, b, t, prm)) / (2 * h2);
  }
}

void eval(const Force& f, const LocalState& x, const LocalState& v, double t, bool, Vec14& q, Mat14* dqx,
          Mat14* dqv, const LoadInput*, Mat14x3*) {
  two_point_eval(user_law, f, x, v, t, q, dqx, dqv);
}

double magnitude(const Force& f, const LocalState& x, const LocalState& v, double t, bool, const LoadInput*) {
  return two_point_tension(user_law, f, x, v, t);
}
}  // namespace

const UserForceLaw* find_force_law(const std::string& name) {
  static const std::map<std::string, UserForceLaw> laws = builtin_laws();  // thread-safe initialization
  auto it = laws.find(name);
  return it == laws.end() ? nullptr : &it->second;
}

const ForceType& user_force_type() {
  static const ForceType row = {
      "user", ForceAttach::kTwoPoints,
      {"name", "type", "body1", "point1", "body2", "point2", "law", "parameters"},
      {}, {nullptr, nullptr, nullptr}, ForceGlyph::kLine, "m", "N",
      eval, two_point_length, magnitude, nullptr, nullptr};
  return row;
}

}  // namespace mbdae
