#include "formulation/sensors.h"

#include "formulation/forces.h"

namespace mbdae {
namespace {

// Whole-system energies (sensor types kinetic_energy and potential_energy).
//
// Kinetic energy, body b with mass m, inertia J about its centre of mass in body axes, centre of
// mass r and Euler parameters p (Haug ch. 11):
//   T = sum_b  1/2 m |r'|^2 + 1/2 w^T J w,   w = 2 L(p) p'   (angular velocity, body axes).
// Bodies merged into ground do not move and carry none.
double kinetic_energy(const System& sys, const double* q, const double* v) {
  double t = 0;
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const SystemBody& body = sys.bodies[b];
    const Vec3 rd = Eigen::Map<const Vec3>(v + 7 * b);
    const Vec4 p = Eigen::Map<const Vec4>(q + 7 * b + 3);
    const Vec4 pd = Eigen::Map<const Vec4>(v + 7 * b + 3);
    const Vec3 w = 2.0 * L_matrix(p) * pd;
    t += 0.5 * body.mass * rd.squaredNorm() + 0.5 * w.dot(body.inertia * w);
  }
  return t;
}

// Potential energy of the conservative loads, zero at the world origin / free length:
//   gravity          V = - sum_b m_b g.r_b               (r_b the centre of mass; g = System::gravity)
//   spring_damper    V = 1/2 k (Z - Z0)^2                (Z the distance of its two points, Z0 the
//                                                         free length; the damper stores nothing)
//   wheel_contact    V = 1/2 K e^2 when in contact       (e = r cos(camber) - (z - z_g(t)), the
//                    (mode) and 0 otherwise               penetration of force_switch_value)
//   point_force      nothing (an imposed f(t), not derived from a potential)
//   user laws        nothing: a registered law is an arbitrary f(d, d_dot, t) with no potential
//                    known to the engine (linear_bushing's 1/2 k |d|^2 is left out as well),
//                    so energy balances of models with user forces must account for them.
// The wheel-contact term is the exact potential of the applied force only while the camber and
// the ground height are constant: the force is vertical, K e, at the wheel centre, which is the
// gradient of 1/2 K e^2 with respect to the centre height alone (a moving ground does work).
double potential_energy(const System& sys, const std::vector<char>& modes, const double* q,
                        double t) {
  double u = 0;
  for (int b = 0; b < sys.num_bodies(); ++b)
    u -= sys.bodies[b].mass * sys.gravity.dot(Eigen::Map<const Vec3>(q + 7 * b));
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    switch (f.type) {
      case ForceSpec::Type::kSpringDamper: {
        const double stretch = force_length(f, gather(q, f.bi, f.bj), t) - f.free_length;
        u += 0.5 * f.stiffness * stretch * stretch;
        break;
      }
      case ForceSpec::Type::kWheelContact:
        if (modes[k]) {
          const double e = force_switch_value(f, gather(q, f.bi, f.bj), t);
          u += 0.5 * f.stiffness * e * e;
        }
        break;
      case ForceSpec::Type::kPointForce:
      case ForceSpec::Type::kUser: break;
    }
  }
  return u;
}

}  // namespace

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
        value = force_length(f, gather(q, f.bi, f.bj), t);
        break;
      }
      case SensorSpec::Type::kForceValue: {
        const Force& f = sys.forces[s.target];
        value = force_magnitude(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[s.target]);
        break;
      }
      case SensorSpec::Type::kExpression: value = s.expression.evaluate(out); break;
      case SensorSpec::Type::kKineticEnergy: value = kinetic_energy(sys, q, v); break;
      case SensorSpec::Type::kPotentialEnergy: value = potential_energy(sys, modes, q, t); break;
    }
    out[k] = value;
  }
}

}  // namespace mbdae
