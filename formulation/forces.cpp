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
}  // namespace

const UserForceLaw* find_force_law(const std::string& name) {
  static const std::map<std::string, UserForceLaw> laws = builtin_laws();  // thread-safe initialization
  auto it = laws.find(name);
  return it == laws.end() ? nullptr : &it->second;
}

void force_eval(const Force& f, const LocalState& x, const LocalState& v, double t,
                bool in_contact, Vec14& q, Mat14* dqx, Mat14* dqv) {
  switch (f.type) {
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
    case ForceSpec::Type::kPointForce: {
      const Vec3 force(f.fx.value(t), f.fy.value(t), f.fz.value(t));
      apply_point_force(f.bi, x.pi, f.si, force, false, q, dqx);
      return;
    }
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

double force_length(const Force& f, const LocalState& x) {
  if (f.type == ForceSpec::Type::kWheelContact) return contact(f, x, 0.0, false).e;
  return (point(f.bj, x.rj, x.pj, f.sj) - point(f.bi, x.ri, x.pi, f.si)).norm();
}

double force_magnitude(const Force& f, const LocalState& x, const LocalState& v, double t,
                       bool in_contact) {
  switch (f.type) {
    case ForceSpec::Type::kWheelContact:
      return in_contact ? f.stiffness * contact(f, x, t, false).e : 0.0;
    case ForceSpec::Type::kPointForce:
      return Vec3(f.fx.value(t), f.fy.value(t), f.fz.value(t)).norm();
    default: {
      const TwoPoint tp = two_point(f, x, v);
      Vec3 force;
      two_point_law(f, tp, t, force, nullptr, nullptr);
      return force.dot(tp.d.normalized());
    }
  }
}

}  // namespace mbdae
