#include "formulation/sensors.h"

#include "formulation/forces.h"

namespace mbdae {

void evaluate_sensors(const System& sys, const std::vector<char>& modes, const double* q,
                      const double* v, const double* a, double t, double* out) {
  for (size_t k = 0; k < sys.sensors.size(); ++k) {
    const Sensor& s = sys.sensors[k];
    const int b = s.body;
    Vec3 r = Vec3::Zero(), rd = Vec3::Zero(), rdd = Vec3::Zero();
    Vec4 p(1, 0, 0, 0), pd = Vec4::Zero(), pdd = Vec4::Zero();
    if (b >= 0) {
      r = Eigen::Map<const Vec3>(q + 7 * b);
      p = Eigen::Map<const Vec4>(q + 7 * b + 3);
      rd = Eigen::Map<const Vec3>(v + 7 * b);
      pd = Eigen::Map<const Vec4>(v + 7 * b + 3);
      if (a) {
        rdd = Eigen::Map<const Vec3>(a + 7 * b);
        pdd = Eigen::Map<const Vec4>(a + 7 * b + 3);
      }
    }
    double value = 0;
    switch (s.type) {
      case SensorSpec::Type::kPosition:
        value = (b < 0 ? s.point : Vec3(r + rotate(p, s.point)))[s.component];
        break;
      case SensorSpec::Type::kVelocity:
        value = b < 0 ? 0.0 : (rd + B_matrix(p, s.point) * pd)[s.component];
        break;
      case SensorSpec::Type::kAcceleration:
        value = b < 0 ? 0.0
                      : (rdd + B_matrix(p, s.point) * pdd + B_matrix(pd, s.point) * pd)[s.component];
        break;
      case SensorSpec::Type::kAxis:
        value = (b < 0 ? s.axis : rotate(p, s.axis))[s.component];
        break;
      case SensorSpec::Type::kCoordinate: value = coordinate_value(sys, s.target, q); break;
      case SensorSpec::Type::kCoordinateRate: value = coordinate_rate(sys, s.target, q, v); break;
      case SensorSpec::Type::kForceLength: {
        const Force& f = sys.forces[s.target];
        value = force_length(f, gather(q, f.bi, f.bj));
        break;
      }
      case SensorSpec::Type::kForceValue: {
        const Force& f = sys.forces[s.target];
        value = force_magnitude(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[s.target]);
        break;
      }
      case SensorSpec::Type::kExpression: value = s.expression.evaluate(out); break;
    }
    out[k] = value;
  }
}

}  // namespace mbdae
