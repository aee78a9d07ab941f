// Spring-damper between two body points: tension T = k (Z - Z0) + c dZ/dt, Z their distance,
// force T n on point 1 (n = d / Z, d = P2 - P1) and -T n on point 2; potential 1/2 k (Z - Z0)^2.
#include "formulation/forces/element.h"

namespace mbdae {
namespace {
using namespace force_element;

void spring_law(const Force& f, const TwoPoint& tp, double, Vec3& force, Mat3* df_dd, Mat3* df_ddd) {
  const double z = tp.d.norm();
  const Vec3 n = tp.d / z;
  const double zd = n.dot(tp.dd);
  const double tension = f.stiffness * (z - f.free_length) + f.damping * zd;
  force = tension * n;
  if (df_dd) {
    const Mat3 proj = Mat3::Identity() - n * n.transpose();
    const Eigen::RowVector3d dt_dd = f.stiffness * n.transpose() + f.damping * (proj * tp.dd).transpose() / z;
    *df_dd = tension / z * proj + n * dt_dd;
    *df_ddd = f.damping * n * n.transpose();
  }
}

void eval(const Force& f, const LocalState& x, const LocalState& v, double t, bool, Vec14& q, Mat14* dqx,
          Mat14* dqv, const LoadInput*, Mat14x3*) {
  two_point_eval(spring_law, f, x, v, t, q, dqx, dqv);
}

double magnitude(const Force& f, const LocalState& x, const LocalState& v, double t, bool, const LoadInput*) {
  return two_point_tension(spring_law, f, x, v, t);
}

double potential(const Force& f, const LocalState& x, double t, bool, const LoadInput*) {
  const double stretch = two_point_length(f, x, t) - f.free_length;
  return 0.5 * f.stiffness * stretch * stretch;
}
}  // namespace

const ForceType& spring_damper_type() {
  static const ForceType row = {
      "spring_damper", ForceAttach::kTwoPoints,
      {"name", "type", "body1", "point1", "body2", "point2", "stiffness", "damping", "free_length"},
      {{"free_length", "m", "", ParameterRange::kNonNegative, false, true,
        [](ForceSpec& s) { return &s.free_length; }, [](Force& f) { return &f.free_length; }},
       {"stiffness", "N/m", "", ParameterRange::kNonNegative, true, true,
        [](ForceSpec& s) { return &s.stiffness; }, [](Force& f) { return &f.stiffness; }},
       {"damping", "N s/m", "", ParameterRange::kNonNegative, false, true,
        [](ForceSpec& s) { return &s.damping; }, [](Force& f) { return &f.damping; }}},
      {nullptr, nullptr, nullptr}, ForceGlyph::kLine, "m", "N",
      eval, two_point_length, magnitude, potential, nullptr};
  return row;
}

}  // namespace mbdae
