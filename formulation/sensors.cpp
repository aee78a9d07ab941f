#include "formulation/sensors.h"

#include "formulation/forces.h"

#include <algorithm>
#include <cmath>

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
//   joint_spring_damper  V = 1/2 k w(q - q0)^2        (w: wrapped to (-pi, pi] for rotations)
//   bushing          V = 1/2 y^T K y                     (y = (d, theta), forces.h)
//   point_force, torque  nothing (imposed loads, not derived from a potential)
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
    u += force_potential(f, gather(q, f.bi, f.bj), t, modes[k]);
  }
  return u;
}

// Value of sensor k; `earlier` holds the sensors before it (for expressions).
double sensor_value(const System& sys, int k, const std::vector<char>& modes, const double* q,
                    const double* v, const double* a, double t, const double* earlier);

// Derivatives of a sensor with respect to the local positions and velocities of its two bodies
// (bi, bj as in gather): exact for points, axes and coordinates; for force lengths and values by
// central differences (step 1e-6 max(1, |x_l|) on each local coordinate).
struct SensorGradient {
  int bi = -1, bj = -1;
  Row14 dq = Row14::Zero(), dv = Row14::Zero();
};

SensorGradient force_sensor_gradient(const System& sys, const Sensor& s,
                                     const std::vector<char>& modes, const double* q,
                                     const double* v, double t) {
  const Force& f = sys.forces[s.target];
  SensorGradient g;
  g.bi = f.bi;
  g.bj = f.bj;
  const bool in_contact = modes[s.target];
  auto value = [&](const Vec14& x, const Vec14& xd) {
    return s.type == SensorSpec::Type::kForceLength
               ? force_length(f, local_state(x), t)
               : force_magnitude(f, local_state(x), local_state(xd), t, in_contact);
  };
  const Vec14 x = local_vector(gather(q, f.bi, f.bj)), xd = local_vector(gather(v, f.bi, f.bj));
  for (int l = 0; l < 14; ++l) {
    if ((l < 7 && f.bi < 0) || (l >= 7 && f.bj < 0)) continue;
    const double hx = 1e-6 * std::max(1.0, std::fabs(x[l])), hv = 1e-6 * std::max(1.0, std::fabs(xd[l]));
    Vec14 xp = x, xm = x, vp = xd, vm = xd;
    xp[l] += hx;
    xm[l] -= hx;
    vp[l] += hv;
    vm[l] -= hv;
    g.dq(l) = (value(xp, xd) - value(xm, xd)) / (2 * hx);
    if (s.type == SensorSpec::Type::kForceValue) g.dv(l) = (value(x, vp) - value(x, vm)) / (2 * hv);
  }
  return g;
}

SensorGradient sensor_gradient(const System& sys, const Sensor& s, const std::vector<char>& modes,
                               const double* q, const double* v, double t) {
  using T = SensorSpec::Type;
  SensorGradient g;
  if (s.type == T::kForceLength || s.type == T::kForceValue)
    return force_sensor_gradient(sys, s, modes, q, v, t);
  if (s.type == T::kCoordinate || s.type == T::kCoordinateRate) {
    const JointCoordinate& jc = sys.coordinates[s.target];
    if (jc.merged) return g;
    g.bi = jc.function.body_parent;
    g.bj = jc.function.body_child;
    const ScalarJet jet = coordinate_jet(jc.function, gather(q, g.bi, g.bj));
    if (s.type == T::kCoordinate) {
      g.dq = jet.grad;
    } else {
      g.dq = (jet.hess * gather_local(v, g.bi, g.bj)).transpose();
      g.dv = jet.grad;
    }
    return g;
  }
  g.bi = s.body;
  if (s.body < 0) return g;
  const Vec4 p = Eigen::Map<const Vec4>(q + 7 * s.body + 3);
  const Vec4 pd = Eigen::Map<const Vec4>(v + 7 * s.body + 3);
  const int c = s.component;
  switch (s.type) {
    case T::kPosition:  // (r + A s)_c
      g.dq(c) = 1.0;
      g.dq.segment<4>(3) = B_matrix(p, s.point).row(c);
      break;
    case T::kVelocity:  // (r' + B(p, s) p')_c
      g.dv(c) = 1.0;
      g.dv.segment<4>(3) = B_matrix(p, s.point).row(c);
      g.dq.segment<4>(3) = B_matrix(pd, s.point).row(c);
      break;
    case T::kAxis: g.dq.segment<4>(3) = B_matrix(p, s.axis).row(c); break;
    default: break;  // refused for loads by build_system
  }
  return g;
}

double sensor_value(const System& sys, int k, const std::vector<char>& modes, const double* q,
                    const double* v, const double* a, double t, const double* earlier) {
  const Sensor& s = sys.sensors[k];
  const int b = s.body;
  const BodyPose x = body_pose(q, b), xd = body_pose(v, b, true);
  switch (s.type) {
    case SensorSpec::Type::kPosition: return (b < 0 ? s.point : point_position(x, s.point))[s.component];
    case SensorSpec::Type::kVelocity: return point_velocity(x, xd, s.point)[s.component];
    case SensorSpec::Type::kAcceleration:
      return point_acceleration(x, xd, a ? body_pose(a, b, true) : body_pose(nullptr, -1, true), s.point)[s.component];
    case SensorSpec::Type::kAxis: return (b < 0 ? s.axis : rotate(x.p, s.axis))[s.component];
    case SensorSpec::Type::kCoordinate: return coordinate_value(sys, s.target, q);
    case SensorSpec::Type::kCoordinateRate: return coordinate_rate(sys, s.target, q, v);
    case SensorSpec::Type::kForceLength: {
      const Force& f = sys.forces[s.target];
      return force_length(f, gather(q, f.bi, f.bj), t);
    }
    case SensorSpec::Type::kForceValue: {
      const Force& f = sys.forces[s.target];
      LoadInput in;
      if (f.has_expression()) in = load_input(sys, f, modes, q, v, t, false);
      return force_magnitude(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[s.target], &in);
    }
    case SensorSpec::Type::kExpression: return s.expression.evaluate(earlier);
    case SensorSpec::Type::kKineticEnergy: return kinetic_energy(sys, q, v);
    case SensorSpec::Type::kPotentialEnergy: return potential_energy(sys, modes, q, t);
  }
  return 0.0;
}

}  // namespace

void evaluate_sensors(const System& sys, const std::vector<char>& modes, const double* q,
                      const double* v, const double* a, double t, double* out,
                      const double* previous) {
  for (int k = 0; k < static_cast<int>(sys.sensors.size()); ++k) {
    const Sensor& s = sys.sensors[k];
    const double reference = previous ? previous[k] : s.reference;  // read before out[k] is set
    double value = sensor_value(sys, k, modes, q, v, a, t, out);
    if (s.unwrap) value += 2 * M_PI * std::round((reference - value) / (2 * M_PI));
    out[k] = value;
  }
}

LoadInput load_input(const System& sys, const Force& f, const std::vector<char>& modes,
                     const double* q, const double* v, double t, bool with_gradient) {
  LoadInput in;
  const int np = static_cast<int>(f.parameters.size()), ni = static_cast<int>(f.inputs.size());
  double vars[kMaxLoadVariables];
  vars[0] = t;
  for (int k = 0; k < np; ++k) vars[1 + k] = f.parameters[k];
  for (int k = 0; k < ni; ++k) vars[1 + np + k] = sensor_value(sys, f.inputs[k], modes, q, v, nullptr, t, nullptr);
  const int nr = static_cast<int>(f.reads.size());
  for (int c = 0; c < 3; ++c) {
    std::fill(in.dq[c], in.dq[c] + 7 * nr, 0.0);
    std::fill(in.dv[c], in.dv[c] + 7 * nr, 0.0);
    if (f.expression[c].empty()) continue;
    if (!with_gradient) {
      in.value[c] = f.expression[c].evaluate(vars);
      continue;
    }
    double grad[kMaxLoadVariables] = {};
    in.value[c] = f.expression[c].gradient(vars, grad);
    for (int k = 0; k < ni; ++k) {
      const double w = grad[1 + np + k];
      if (w == 0) continue;
      const SensorGradient g = sensor_gradient(sys, sys.sensors[f.inputs[k]], modes, q, v, t);
      for (int side = 0; side < 2; ++side) {
        const int body = side == 0 ? g.bi : g.bj;
        if (body < 0) continue;
        const int slot = static_cast<int>(std::lower_bound(f.reads.begin(), f.reads.end(), body) - f.reads.begin());
        for (int l = 0; l < 7; ++l) {
          in.dq[c][7 * slot + l] += w * g.dq(7 * side + l);
          in.dv[c][7 * slot + l] += w * g.dv(7 * side + l);
        }
      }
    }
  }
  return in;
}

}  // namespace mbdae
