#include "formulation/sensors.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/finite_check.h"
#include "formulation/force_types.h"
#include "formulation/forces.h"

namespace mbdae {

std::string load_field(const Force& f, int c) {
  const char* field = force_type(f.type).components[c];
  return field ? field : c == 0 ? "fx" : c == 1 ? "fy" : "fz";
}

double joint_turns(const System& sys, const Force& f, const double* q, double t, const CoordinateTurns* turns) {
  if (force_type(f.type).attach != ForceAttach::kCoordinate || f.wrap || f.coordinate_index < 0) return 0.0;
  const double raw = coordinate_value(sys, f.coordinate_index, q);
  return continuous_coordinate(sys, f.coordinate_index, raw, t, turns) - raw;
}

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
//   bushing          V = 1/2 y^T K y                     (y = (d, theta), forces/bushing.cpp)
//   point_force, torque  nothing (imposed loads, not derived from a potential)
//   joint_friction   nothing (dissipative)
//   user laws        nothing: a registered law is an arbitrary f(d, d_dot, t) with no potential
//                    known to the engine (linear_bushing's 1/2 k |d|^2 is left out as well),
//                    so energy balances of models with user forces must account for them.
// Each load's term comes from its row of the force-type table (ForceType::potential).
// The wheel-contact term is the exact potential of the applied force only while the camber and
// the ground height are constant: the force is vertical, K e, at the wheel centre, which is the
// gradient of 1/2 K e^2 with respect to the centre height alone (a moving ground does work).
double potential_energy(const System& sys, const std::vector<char>& modes, const double* q,
                        double t, const CoordinateTurns* turns) {
  double u = 0;
  for (int b = 0; b < sys.num_bodies(); ++b)
    u -= sys.bodies[b].mass * sys.gravity.dot(Eigen::Map<const Vec3>(q + 7 * b));
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    LoadInput in;
    in.turns = joint_turns(sys, f, q, t, turns);
    u += force_potential(f, gather(q, f.bi, f.bj), t, modes[k], &in);
  }
  return u;
}

// Angular velocity of body b: world omega = 2 E(p) p', body-axes omega' = 2 L(p) p', with
// E(p) = [-e, [e]x + e0 I]. Both are bilinear, E(p) p' = -E(p') p (likewise L), which gives the
// exact derivatives: d omega/dp = -2 E(p'), d omega/dp' = 2 E(p).
Mat34 E_matrix(const Vec4& p) {
  Mat34 m;
  m.col(0) = -p.tail<3>();
  m.rightCols<3>() = skew(p.tail<3>()) + p[0] * Mat3::Identity();
  return m;
}
Mat34 omega_matrix(const Sensor& s, const Vec4& p) { return s.body_frame ? L_matrix(p) : E_matrix(p); }

// Angular momentum (world components) about the world point c of body b:
//   H_b = m (r - c) x r' + A(p) J omega',  omega' = 2 L(p) p'.
// Bodies merged into ground carry none; a merged body is part of its host's rigid composite.
Vec3 body_angular_momentum(const System& sys, int b, const double* q, const double* v, const Vec3& c) {
  const SystemBody& body = sys.bodies[b];
  const Vec3 r = Eigen::Map<const Vec3>(q + 7 * b), rd = Eigen::Map<const Vec3>(v + 7 * b);
  const Vec4 p = Eigen::Map<const Vec4>(q + 7 * b + 3), pd = Eigen::Map<const Vec4>(v + 7 * b + 3);
  const Vec3 w = 2.0 * L_matrix(p) * pd;
  return body.mass * (r - c).cross(rd) + rotate(p, body.inertia * w);
}

double angular_momentum(const System& sys, const Sensor& s, const double* q, const double* v) {
  Vec3 h = Vec3::Zero();
  if (s.whole_system) {
    for (int b = 0; b < sys.num_bodies(); ++b) h += body_angular_momentum(sys, b, q, v, s.point);
  } else if (s.body >= 0) {
    h = body_angular_momentum(sys, s.body, q, v, s.point);
  }
  return h[s.component];
}

// Value of sensor k; `earlier` holds the sensors before it (for expressions).
double sensor_value(const System& sys, int k, const std::vector<char>& modes, const double* q,
                    const double* v, const double* a, double t, const double* earlier,
                    const CoordinateTurns* turns);

// Derivatives of a sensor with respect to the local positions and velocities of its two bodies
// (bi, bj as in gather): exact for points, axes and coordinates; for force lengths and values by
// central differences (step 1e-6 max(1, |x_l|) on each local coordinate).
struct SensorGradient {
  int bi = -1, bj = -1;
  Row14 dq = Row14::Zero(), dv = Row14::Zero();
};

SensorGradient force_sensor_gradient(const System& sys, const Sensor& s,
                                     const std::vector<char>& modes, const double* q,
                                     const double* v, double t, const CoordinateTurns* turns) {
  SensorGradient g;
  const bool momentum = s.type == SensorSpec::Type::kAngularMomentum;  // of one body (loads)
  const Force* f = momentum ? nullptr : &sys.forces[s.target];
  g.bi = momentum ? s.body : f->bi;
  g.bj = momentum ? -1 : f->bj;
  // The turns of a joint spring are constant near the state: they shift its length and value only.
  LoadInput in;
  if (f) in.turns = joint_turns(sys, *f, q, t, turns);
  auto value = [&](const Vec14& x, const Vec14& xd) {
    if (momentum) {
      double qb[7], vb[7];
      for (int l = 0; l < 7; ++l) qb[l] = x[l], vb[l] = xd[l];
      const SystemBody& body = sys.bodies[s.body];
      const Vec3 r(qb[0], qb[1], qb[2]), rd(vb[0], vb[1], vb[2]);
      const Vec4 p(qb[3], qb[4], qb[5], qb[6]), pd(vb[3], vb[4], vb[5], vb[6]);
      const Vec3 w = 2.0 * L_matrix(p) * pd;
      return Vec3(body.mass * (r - s.point).cross(rd) + rotate(p, body.inertia * w))[s.component];
    }
    return s.type == SensorSpec::Type::kForceLength
               ? force_length(*f, local_state(x), t) + in.turns
               : force_magnitude(*f, local_state(x), local_state(xd), t, modes[s.target], &in);
  };
  const Vec14 x = local_vector(gather(q, g.bi, g.bj)), xd = local_vector(gather(v, g.bi, g.bj));
  for (int l = 0; l < 14; ++l) {
    if ((l < 7 && g.bi < 0) || (l >= 7 && g.bj < 0)) continue;
    const double hx = 1e-6 * std::max(1.0, std::fabs(x[l])), hv = 1e-6 * std::max(1.0, std::fabs(xd[l]));
    Vec14 xp = x, xm = x, vp = xd, vm = xd;
    xp[l] += hx;
    xm[l] -= hx;
    vp[l] += hv;
    vm[l] -= hv;
    g.dq(l) = (value(xp, xd) - value(xm, xd)) / (2 * hx);
    if (s.type != SensorSpec::Type::kForceLength) g.dv(l) = (value(x, vp) - value(x, vm)) / (2 * hv);
  }
  return g;
}

SensorGradient sensor_gradient(const System& sys, const Sensor& s, const std::vector<char>& modes,
                               const double* q, const double* v, double t, const CoordinateTurns* turns) {
  using T = SensorSpec::Type;
  SensorGradient g;
  if (s.type == T::kForceLength || s.type == T::kForceValue || (s.type == T::kAngularMomentum && s.body >= 0))
    return force_sensor_gradient(sys, s, modes, q, v, t, turns);
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
    case T::kAngularVelocity:  // axis . 2 E(p) p' (or L): bilinear in p and p'
      g.dq.segment<4>(3) = -2.0 * s.axis.transpose() * omega_matrix(s, pd);
      g.dv.segment<4>(3) = 2.0 * s.axis.transpose() * omega_matrix(s, p);
      break;
    default: break;  // refused for loads by build_system
  }
  return g;
}

double sensor_value(const System& sys, int k, const std::vector<char>& modes, const double* q,
                    const double* v, const double* a, double t, const double* earlier,
                    const CoordinateTurns* turns) {
  const Sensor& s = sys.sensors[k];
  const int b = s.body;
  const BodyPose x = body_pose(q, b), xd = body_pose(v, b, true);
  switch (s.type) {
    case SensorSpec::Type::kPosition: return (b < 0 ? s.point : point_position(x, s.point))[s.component];
    case SensorSpec::Type::kVelocity: return point_velocity(x, xd, s.point)[s.component];
    case SensorSpec::Type::kAcceleration:
      return point_acceleration(x, xd, a ? body_pose(a, b, true) : body_pose(nullptr, -1, true), s.point)[s.component];
    case SensorSpec::Type::kAxis: return (b < 0 ? s.axis : rotate(x.p, s.axis))[s.component];
    case SensorSpec::Type::kCoordinate: {
      const double raw = coordinate_value(sys, s.target, q);
      return s.unwrap ? continuous_coordinate(sys, s.target, raw, t, turns) : raw;
    }
    case SensorSpec::Type::kCoordinateRate: return coordinate_rate(sys, s.target, q, v);
    case SensorSpec::Type::kForceLength: {
      const Force& f = sys.forces[s.target];
      return force_length(f, gather(q, f.bi, f.bj), t) + joint_turns(sys, f, q, t, turns);
    }
    case SensorSpec::Type::kForceValue: {
      const Force& f = sys.forces[s.target];
      const LoadInput in = load_input(sys, f, modes, q, v, t, false, turns);
      return force_magnitude(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[s.target], &in);
    }
    case SensorSpec::Type::kExpression: return s.expression.evaluate(earlier);
    case SensorSpec::Type::kKineticEnergy: return kinetic_energy(sys, q, v);
    case SensorSpec::Type::kPotentialEnergy: return potential_energy(sys, modes, q, t, turns);
    case SensorSpec::Type::kAngularVelocity:
      return b < 0 ? 0.0 : s.axis.dot(2.0 * omega_matrix(s, x.p) * xd.p);
    case SensorSpec::Type::kAngularMomentum: return angular_momentum(sys, s, q, v);
  }
  return 0.0;
}

}  // namespace

void evaluate_sensors(const System& sys, const std::vector<char>& modes, const double* q,
                      const double* v, const double* a, double t, double* out,
                      const double* previous, const CoordinateTurns* turns) {
  for (int k = 0; k < static_cast<int>(sys.sensors.size()); ++k) {
    const Sensor& s = sys.sensors[k];
    const double reference = previous ? previous[k] : s.reference;  // read before out[k] is set
    double value = sensor_value(sys, k, modes, q, v, a, t, out, turns);
    if (s.unwrap && !turns) value += 2 * M_PI * std::round((reference - value) / (2 * M_PI));
    out[k] = value;
  }
}

LoadInput load_input(const System& sys, const Force& f, const std::vector<char>& modes,
                     const double* q, const double* v, double t, bool with_gradient,
                     const CoordinateTurns* turns) {
  LoadInput in;
  in.turns = joint_turns(sys, f, q, t, turns);
  if (!f.has_expression()) return in;
  const int np = static_cast<int>(f.parameters.size()), ni = static_cast<int>(f.inputs.size());
  double vars[kMaxLoadVariables];
  vars[0] = t;
  for (int k = 0; k < np; ++k) vars[1 + k] = f.parameters[k];
  for (int k = 0; k < ni; ++k) vars[1 + np + k] = sensor_value(sys, f.inputs[k], modes, q, v, nullptr, t, nullptr, turns);
  const int nr = static_cast<int>(f.reads.size());
  for (int k = 0; k < ni; ++k)
    if (!std::isfinite(vars[1 + np + k]))
      throw non_finite_error("sensor '" + sys.sensors[f.inputs[k]].name + "' read by load '" + f.name + "'",
                             vars[1 + np + k], t);
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
      const SensorGradient g = sensor_gradient(sys, sys.sensors[f.inputs[k]], modes, q, v, t, turns);
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
  // A load that is not finite where everything it reads is stops the run at once, by name: a
  // Newton iteration cannot recover from it (an expression such as sqrt(0.01 - t) past its
  // domain), and the integrator would only shrink its step until it gives up.
  for (int c = 0; c < 3; ++c)
    if (!f.expression[c].empty() && !std::isfinite(in.value[c]))
      throw non_finite_error("load '" + f.name + "' (" + load_field(f, c) + " = " + f.expression[c].source + ")",
                             in.value[c], t);
  return in;
}

}  // namespace mbdae
