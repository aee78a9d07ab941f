#include "formulation/forces.h"

#include <cmath>
#include <map>

namespace mbdae {
namespace {
constexpr int kRi = 0, kPi4 = 3, kRj = 7, kPj = 10;

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

Vec3 point(int b, const Vec3& r, const Vec4& p, const Vec3& s) {
  return b < 0 ? s : Vec3(r + rotate(p, s));
}
Vec3 point_velocity(int b, const Vec4& p, const Vec3& rd, const Vec4& pd, const Vec3& s) {
  return b < 0 ? Vec3::Zero() : Vec3(rd + B_matrix(p, s) * pd);
}

// d(point)/d(local q) as 3 x 14 for body slot (i or j).
Eigen::Matrix<double, 3, 14> point_jacobian(int b, const Vec4& p, const Vec3& s, bool slot_j) {
  Eigen::Matrix<double, 3, 14> g = Eigen::Matrix<double, 3, 14>::Zero();
  if (b < 0) return g;
  g.block<3, 3>(0, slot_j ? kRj : kRi) = Mat3::Identity();
  g.block<3, 4>(0, slot_j ? kPj : kPi4) = B_matrix(p, s);
  return g;
}

// Generalized force of world force f at point s of body slot, plus dQ/dp for fixed f.
void apply_point_force(int b, const Vec4& p, const Vec3& s, const Vec3& f, bool slot_j, Vec14& q,
                       Mat14* dq) {
  if (b < 0) return;
  const int ro = slot_j ? kRj : kRi, po = slot_j ? kPj : kPi4;
  q.segment<3>(ro) += f;
  q.segment<4>(po) += B_matrix(p, s).transpose() * f;
  if (dq) dq->block<4, 4>(po, po) += K_matrix(s, f);
}

// Two-point elements: relative position d = P2 - P1, velocity, and their Jacobians.
struct TwoPoint {
  Vec3 d, dd;
  Eigen::Matrix<double, 3, 14> dq;  // d(d)/dq = d(dd)/dqdot
  Eigen::Matrix<double, 3, 14> dv;  // d(dd)/dq
};
TwoPoint two_point(const Force& f, const LocalState& x, const LocalState& v) {
  TwoPoint t;
  t.d = point(f.bj, x.rj, x.pj, f.sj) - point(f.bi, x.ri, x.pi, f.si);
  t.dd = point_velocity(f.bj, x.pj, v.rj, v.pj, f.sj) - point_velocity(f.bi, x.pi, v.ri, v.pi, f.si);
  t.dq = point_jacobian(f.bj, x.pj, f.sj, true) - point_jacobian(f.bi, x.pi, f.si, false);
  t.dv.setZero();
  if (f.bj >= 0) t.dv.block<3, 4>(0, kPj) = B_matrix(v.pj, f.sj);
  if (f.bi >= 0) t.dv.block<3, 4>(0, kPi4) = -B_matrix(v.pi, f.si);
  return t;
}

// Force on point 1 (f) and its derivatives with respect to d and d_dot.
void two_point_law(const Force& f, const TwoPoint& tp, double t, Vec3& force, Mat3* df_dd,
                   Mat3* df_ddd) {
  if (f.type == ForceSpec::Type::kSpringDamper) {
    const double z = tp.d.norm();
    const Vec3 n = tp.d / z;
    const double zd = n.dot(tp.dd);
    const double tension = f.stiffness * (z - f.free_length) + f.damping * zd;
    force = tension * n;
    if (df_dd) {
      const Mat3 proj = Mat3::Identity() - n * n.transpose();
      const Eigen::RowVector3d dt_dd =
          f.stiffness * n.transpose() + f.damping * (proj * tp.dd).transpose() / z;
      *df_dd = tension / z * proj + n * dt_dd;
      *df_ddd = f.damping * n * n.transpose();
    }
    return;
  }
  // User law.
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

// Component k of a point force or torque: its expression's value if it has one, else fx/fy/fz(t).
double component(const Force& f, int k, double t, const LoadInput* in) {
  if (!f.expression[k].empty()) return in ? in->value[k] : 0.0;
  return (k == 0 ? f.fx : k == 1 ? f.fy : f.fz).value(t);
}

// The constant matrix M(a) of the torque map Q_p = 2 T M(a) p (see forces.h).
Mat4 torque_map(const Vec3& a, bool body_axes) {
  Mat4 m;
  m(0, 0) = 0;
  m.block<1, 3>(0, 1) = -a.transpose();
  m.block<3, 1>(1, 0) = a;
  m.block<3, 3>(1, 1) = body_axes ? Mat3(-skew(a)) : skew(a);
  return m;
}

void torque_eval(const Force& f, const LocalState& x, double t, const LoadInput* in, Vec14& q,
                 Mat14* dqx, Mat14x3* dqin) {
  if (f.bi < 0) return;
  const double magnitude = component(f, 0, t, in);
  const Mat4 m = torque_map(f.axis, f.body_frame);
  q.segment<4>(kPi4) += 2.0 * magnitude * (m * x.pi);
  if (dqx) dqx->block<4, 4>(kPi4, kPi4) += 2.0 * magnitude * m;
  if (dqin) dqin->block<4, 1>(kPi4, 0) += 2.0 * (m * x.pi);
}

// Point force in world axes, or in body axes (follower force: f = A(p) F).
void point_force_eval(const Force& f, const LocalState& x, double t, const LoadInput* in,
                      Vec14& q, Mat14* dqx, Mat14x3* dqin) {
  if (f.bi < 0) return;
  const Vec3 given(component(f, 0, t, in), component(f, 1, t, in), component(f, 2, t, in));
  Mat3 to_world = Mat3::Identity();  // d(world force)/d(components)
  if (f.body_frame) to_world = rotation(x.pi) * f.frame_i;
  const Vec3 force = to_world * given;
  apply_point_force(f.bi, x.pi, f.si, force, false, q, dqx);
  if (dqx && f.body_frame) {
    const Mat34 dforce = B_matrix(x.pi, f.frame_i * given);
    dqx->block<3, 4>(kRi, kPi4) += dforce;
    dqx->block<4, 4>(kPi4, kPi4) += B_matrix(x.pi, f.si).transpose() * dforce;
  }
  if (dqin) {
    dqin->block<3, 3>(kRi, 0) += to_world;
    dqin->block<4, 3>(kPi4, 0) += B_matrix(x.pi, f.si).transpose() * to_world;
  }
}

// q - rest of a joint spring-damper: wrapped to (-pi, pi] if asked, else with the whole turns of
// the load input (LoadInput::turns) added to the measured coordinate.
double joint_stretch(const Force& f, double measured, const LoadInput* in) {
  if (f.wrap && f.coordinate.rotation) return wrap_angle(measured - f.free_length);
  return measured + (in ? in->turns : 0.0) - f.free_length;
}

void joint_spring_eval(const Force& f, const LocalState& x, const LocalState& v, Vec14& q,
                       Mat14* dqx, Mat14* dqv, const LoadInput* in) {
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

// Quaternion products as matrices: a (x) b = left(a) b = right(b) a.
Mat4 quat_left(const Vec4& a) {
  Mat4 m;
  m << a[0], -a[1], -a[2], -a[3], a[1], a[0], -a[3], a[2], a[2], a[3], a[0], -a[1], a[3], -a[2],
      a[1], a[0];
  return m;
}
Mat4 quat_right(const Vec4& b) {
  Mat4 m;
  m << b[0], -b[1], -b[2], -b[3], b[1], b[0], b[3], -b[2], b[2], -b[3], b[0], b[1], b[3], b[2],
      -b[1], b[0];
  return m;
}
Vec4 conj(const Vec4& p) { return Vec4(p[0], -p[1], -p[2], -p[3]); }

// Bushing coordinates y = (d, theta) and their Jacobian J = dy/dx (6 x 14), see forces.h.
void bushing_coordinates(const Force& f, const LocalState& x, Eigen::Matrix<double, 6, 1>& y,
                         Eigen::Matrix<double, 6, 14>& jac) {
  const Vec4 c1 = euler_parameters_from_rotation(f.frame_i);
  const Vec4 c2 = euler_parameters_from_rotation(f.frame_j);
  const Vec4 p1 = f.bi < 0 ? Vec4(1, 0, 0, 0) : Vec4(x.pi), p2 = f.bj < 0 ? Vec4(1, 0, 0, 0) : Vec4(x.pj);
  const Vec3 delta = point(f.bj, x.rj, x.pj, f.sj) - point(f.bi, x.ri, x.pi, f.si);
  const Mat3 c1t = f.frame_i.transpose();
  const Mat3 a1t = rotation(p1).transpose();
  y.head<3>() = c1t * (a1t * delta);
  jac = Eigen::Matrix<double, 6, 14>::Zero();
  const Eigen::Matrix<double, 3, 14> ddelta =
      point_jacobian(f.bj, p2, f.sj, true) - point_jacobian(f.bi, p1, f.si, false);
  jac.topRows<3>() = c1t * a1t * ddelta;
  const Mat4 flip = Vec4(1, -1, -1, -1).asDiagonal();
  if (f.bi >= 0) jac.block<3, 4>(0, kPi4) += c1t * B_matrix(conj(p1), delta) * flip;
  // w = conj(c1) conj(p1) p2 c2.
  const Vec4 g2 = quat_left(p2) * c2;
  const Vec4 w = quat_left(conj(c1)) * (quat_left(conj(p1)) * g2);
  const double sign = w[0] < 0 ? -1.0 : 1.0;
  y.tail<3>() = 2.0 * sign * w.tail<3>();
  if (f.bi >= 0)
    jac.block<3, 4>(3, kPi4) = 2.0 * sign * (quat_left(conj(c1)) * quat_right(g2) * flip).bottomRows<3>();
  if (f.bj >= 0)
    jac.block<3, 4>(3, kPj) =
        2.0 * sign * (quat_left(conj(c1)) * quat_left(conj(p1)) * quat_right(c2)).bottomRows<3>();
}

Vec14 bushing_force(const Force& f, const LocalState& x, const Vec14& vl) {
  Eigen::Matrix<double, 6, 1> y, k, c;
  Eigen::Matrix<double, 6, 14> jac;
  bushing_coordinates(f, x, y, jac);
  k << f.kt, f.kr;
  c << f.ct, f.cr;
  const Eigen::Matrix<double, 6, 1> gen = k.cwiseProduct(y) + c.cwiseProduct(jac * vl);
  return -jac.transpose() * gen;
}

LocalState shifted(const LocalState& x, int l, double h) {
  Vec14 y = local_vector(x);
  y[l] += h;
  return local_state(y);
}

void bushing_eval(const Force& f, const LocalState& x, const LocalState& v, Vec14& q, Mat14* dqx,
                  Mat14* dqv) {
  const Vec14 vl = local_vector(v);
  q += bushing_force(f, x, vl);
  if (!dqx) return;
  Eigen::Matrix<double, 6, 1> y, c;
  Eigen::Matrix<double, 6, 14> jac;
  bushing_coordinates(f, x, y, jac);
  c << f.ct, f.cr;
  *dqv -= jac.transpose() * c.asDiagonal() * jac;
  const Vec14 xl = local_vector(x);
  for (int l = 0; l < 14; ++l) {
    if ((l < 7 && f.bi < 0) || (l >= 7 && f.bj < 0)) continue;
    const double h = 1e-6 * std::max(1.0, std::fabs(xl[l]));
    dqx->col(l) += (bushing_force(f, shifted(x, l, h), vl) - bushing_force(f, shifted(x, l, -h), vl)) / (2 * h);
  }
}
}  // namespace

const UserForceLaw* find_force_law(const std::string& name) {
  static const std::map<std::string, UserForceLaw> laws = builtin_laws();  // thread-safe initialization
  auto it = laws.find(name);
  return it == laws.end() ? nullptr : &it->second;
}

void force_eval(const Force& f, const LocalState& x, const LocalState& v, double t,
                bool in_contact, Vec14& q, Mat14* dqx, Mat14* dqv, const LoadInput* in,
                Mat14x3* dqin) {
  switch (f.type) {
    case ForceSpec::Type::kTorque: torque_eval(f, x, t, in, q, dqx, dqin); return;
    case ForceSpec::Type::kJointSpringDamper: joint_spring_eval(f, x, v, q, dqx, dqv, in); return;
    case ForceSpec::Type::kBushing: bushing_eval(f, x, v, q, dqx, dqv); return;
    case ForceSpec::Type::kSpringDamper:
    case ForceSpec::Type::kUser: {
      const TwoPoint tp = two_point(f, x, v);
      Vec3 force;
      Mat3 fd, fdd;
      two_point_law(f, tp, t, force, dqx ? &fd : nullptr, dqx ? &fdd : nullptr);
      // Q = G1^T f - G2^T f = -dq^T f.
      q.noalias() -= tp.dq.transpose() * force;
      if (dqx) {
        const Eigen::Matrix<double, 3, 14> dfx = fd * tp.dq + fdd * tp.dv;
        const Eigen::Matrix<double, 3, 14> dfv = fdd * tp.dq;
        dqx->noalias() -= tp.dq.transpose() * dfx;
        dqv->noalias() -= tp.dq.transpose() * dfv;
        if (f.bi >= 0) dqx->block<4, 4>(kPi4, kPi4) += K_matrix(f.si, force);
        if (f.bj >= 0) dqx->block<4, 4>(kPj, kPj) -= K_matrix(f.sj, force);
      }
      return;
    }
    case ForceSpec::Type::kPointForce: point_force_eval(f, x, t, in, q, dqx, dqin); return;
    case ForceSpec::Type::kWheelContact: {
      if (!in_contact) return;
      const Contact c = contact(f, x, t, dqx != nullptr);
      const Vec3 force(0, 0, f.stiffness * c.e);
      apply_point_force(f.bi, x.pi, f.si, force, false, q, dqx);
      if (dqx) {
        const Eigen::Matrix<double, 3, 14> g = point_jacobian(f.bi, x.pi, f.si, false);
        dqx->noalias() += g.row(2).transpose() * (f.stiffness * c.de);
      }
      return;
    }
  }
}

double* force_parameter(Force& f, const std::string& p) {
  for (size_t k = 0; k < f.parameter_names.size(); ++k)
    if (f.parameter_names[k] == p) return &f.parameters[k];
  if (f.type == ForceSpec::Type::kBushing || f.type == ForceSpec::Type::kTorque ||
      f.type == ForceSpec::Type::kPointForce)
    return nullptr;
  if (p == "free_length") return &f.free_length;
  if (p == "stiffness") return &f.stiffness;
  if (p == "damping") return &f.damping;
  if (p == "radius") return &f.radius;
  return nullptr;
}

Vec14 force_parameter_derivative(const Force& f, const LocalState& x, const LocalState& v, double t,
                                 bool in_contact, const std::string& parameter) {
  // Generalized forces are affine in these parameters, so a central difference is exact up to
  // rounding; the step is relative to the parameter's size.
  Force g = f;
  double* p = force_parameter(g, parameter);
  const double base = *p, h = 1e-3 * std::max(1.0, std::fabs(base));
  Vec14 qp = Vec14::Zero(), qm = Vec14::Zero();
  *p = base + h;
  force_eval(g, x, v, t, in_contact, qp, nullptr, nullptr);
  *p = base - h;
  force_eval(g, x, v, t, in_contact, qm, nullptr, nullptr);
  return (qp - qm) / (2 * h);
}

bool force_has_switch(const Force& f) { return f.type == ForceSpec::Type::kWheelContact; }

double force_switch_value(const Force& f, const LocalState& x, double t) {
  return f.type == ForceSpec::Type::kWheelContact ? contact(f, x, t, false).e : 0.0;
}

double force_length(const Force& f, const LocalState& x, double t) {
  switch (f.type) {
    case ForceSpec::Type::kWheelContact: return contact(f, x, t, false).e;
    case ForceSpec::Type::kJointSpringDamper: return coordinate_jet(f.coordinate, x).value;
    case ForceSpec::Type::kTorque: return 0.0;
    case ForceSpec::Type::kBushing: {
      Eigen::Matrix<double, 6, 1> y;
      Eigen::Matrix<double, 6, 14> jac;
      bushing_coordinates(f, x, y, jac);
      return y.head<3>().norm();
    }
    default: return (point(f.bj, x.rj, x.pj, f.sj) - point(f.bi, x.ri, x.pi, f.si)).norm();
  }
}

double force_magnitude(const Force& f, const LocalState& x, const LocalState& v, double t,
                       bool in_contact, const LoadInput* in) {
  switch (f.type) {
    case ForceSpec::Type::kWheelContact:
      return in_contact ? f.stiffness * contact(f, x, t, false).e : 0.0;
    case ForceSpec::Type::kPointForce:
      return Vec3(component(f, 0, t, in), component(f, 1, t, in), component(f, 2, t, in)).norm();
    case ForceSpec::Type::kTorque: return component(f, 0, t, in);
    case ForceSpec::Type::kJointSpringDamper: {
      // The generalized force on the coordinate, -tau (a torque for a rotation).
      Vec14 q = Vec14::Zero();
      joint_spring_eval(f, x, v, q, nullptr, nullptr, in);
      const ScalarJet jet = coordinate_jet(f.coordinate, x);
      return q.dot(jet.grad.transpose()) / jet.grad.squaredNorm();
    }
    case ForceSpec::Type::kBushing: {
      // Magnitude of the force on body 1, |K_t d + C_t d'| (frame-1 axes).
      Eigen::Matrix<double, 6, 1> y;
      Eigen::Matrix<double, 6, 14> jac;
      bushing_coordinates(f, x, y, jac);
      const Vec14 vl = local_vector(v);
      return (f.kt.cwiseProduct(y.head<3>()) + f.ct.cwiseProduct((jac * vl).head<3>())).norm();
    }
    default: {
      const TwoPoint tp = two_point(f, x, v);
      Vec3 force;
      two_point_law(f, tp, t, force, nullptr, nullptr);
      return force.dot(tp.d.normalized());
    }
  }
}

double force_potential(const Force& f, const LocalState& x, double t, bool in_contact, const LoadInput* in) {
  switch (f.type) {
    case ForceSpec::Type::kSpringDamper: {
      const double stretch = force_length(f, x, t) - f.free_length;
      return 0.5 * f.stiffness * stretch * stretch;
    }
    case ForceSpec::Type::kWheelContact: {
      if (!in_contact) return 0.0;
      const double e = force_switch_value(f, x, t);
      return 0.5 * f.stiffness * e * e;
    }
    case ForceSpec::Type::kJointSpringDamper: {
      const double stretch = joint_stretch(f, coordinate_jet(f.coordinate, x).value, in);
      return 0.5 * f.stiffness * stretch * stretch;
    }
    case ForceSpec::Type::kBushing: {
      Eigen::Matrix<double, 6, 1> y, k;
      Eigen::Matrix<double, 6, 14> jac;
      bushing_coordinates(f, x, y, jac);
      k << f.kt, f.kr;
      return 0.5 * y.dot(k.cwiseProduct(y));
    }
    default: return 0.0;
  }
}

}  // namespace mbdae
