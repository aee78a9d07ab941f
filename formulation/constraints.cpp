#include "formulation/constraints.h"

#include <cmath>

namespace mbdae {
namespace {
constexpr double kPi = 3.14159265358979323846;

// Offsets of r and p of body i and j in the local 14-vector.
constexpr int kRi = 0, kPi4 = 3, kRj = 7, kPj = 10;

// World point and world vector of a body (or of ground, whose local data is world data).
Vec3 world_point(int b, const Vec3& r, const Vec4& p, const Vec3& s) {
  return b < 0 ? s : Vec3(r + rotate(p, s));
}
Vec3 world_vector(int b, const Vec4& p, const Vec3& a) { return b < 0 ? a : rotate(p, a); }

// Value, gradient and Hessian of (A_i a).(A_j b): a dot product of two body-fixed vectors.
ScalarJet dot1_jet(int bi, int bj, const LocalState& s, const Vec3& a, const Vec3& b) {
  ScalarJet j;
  const Vec3 u = world_vector(bi, s.pi, a), w = world_vector(bj, s.pj, b);
  j.value = u.dot(w);
  Mat34 bu = Mat34::Zero(), bw = Mat34::Zero();
  if (bi >= 0) {
    bu = B_matrix(s.pi, a);
    j.grad.segment<4>(kPi4) = w.transpose() * bu;
    j.hess.block<4, 4>(kPi4, kPi4) = K_matrix(a, w);
  }
  if (bj >= 0) {
    bw = B_matrix(s.pj, b);
    j.grad.segment<4>(kPj) = u.transpose() * bw;
    j.hess.block<4, 4>(kPj, kPj) = K_matrix(b, u);
  }
  if (bi >= 0 && bj >= 0) {
    j.hess.block<4, 4>(kPi4, kPj) = bu.transpose() * bw;
    j.hess.block<4, 4>(kPj, kPi4) = bw.transpose() * bu;
  }
  return j;
}

// (A_i a).(P_j - P_i) with P_i = r_i + A_i si, P_j = r_j + A_j sj.
ScalarJet dot2_jet(int bi, int bj, const LocalState& s, const Vec3& a, const Vec3& si,
                   const Vec3& sj) {
  ScalarJet j;
  const Vec3 u = world_vector(bi, s.pi, a);
  const Vec3 d = world_point(bj, s.rj, s.pj, sj) - world_point(bi, s.ri, s.pi, si);
  j.value = u.dot(d);
  Mat34 ba = Mat34::Zero(), bs = Mat34::Zero();
  if (bi >= 0) {
    ba = B_matrix(s.pi, a);
    bs = B_matrix(s.pi, si);
    j.grad.segment<3>(kRi) = -u.transpose();
    j.grad.segment<4>(kPi4) = d.transpose() * ba - u.transpose() * bs;
    j.hess.block<3, 4>(kRi, kPi4) = -ba;
    j.hess.block<4, 3>(kPi4, kRi) = -ba.transpose();
    j.hess.block<4, 4>(kPi4, kPi4) =
        K_matrix(a, d) - K_matrix(si, u) - ba.transpose() * bs - bs.transpose() * ba;
  }
  if (bj >= 0) {
    const Mat34 bsj = B_matrix(s.pj, sj);
    j.grad.segment<3>(kRj) = u.transpose();
    j.grad.segment<4>(kPj) = u.transpose() * bsj;
    j.hess.block<4, 4>(kPj, kPj) = K_matrix(sj, u);
    if (bi >= 0) {
      j.hess.block<4, 3>(kPi4, kRj) = ba.transpose();
      j.hess.block<3, 4>(kRj, kPi4) = ba;
      j.hess.block<4, 4>(kPi4, kPj) = ba.transpose() * bsj;
      j.hess.block<4, 4>(kPj, kPi4) = bsj.transpose() * ba;
    }
  }
  return j;
}

// theta = atan2(y, x) from the jets of y and x.
ScalarJet atan2_jet(const ScalarJet& y, const ScalarJet& x) {
  ScalarJet j;
  const double r2 = x.value * x.value + y.value * y.value;
  j.value = std::atan2(y.value, x.value);
  const double tx = -y.value / r2, ty = x.value / r2;
  const double txx = 2 * x.value * y.value / (r2 * r2), tyy = -txx;
  const double txy = (y.value * y.value - x.value * x.value) / (r2 * r2);
  j.grad = tx * x.grad + ty * y.grad;
  j.hess = tx * x.hess + ty * y.hess + txx * x.grad.transpose() * x.grad +
           tyy * y.grad.transpose() * y.grad +
           txy * (x.grad.transpose() * y.grad + y.grad.transpose() * x.grad);
  return j;
}

ScalarJet asin_jet(const ScalarJet& z) {
  ScalarJet j;
  const double c2 = 1.0 - z.value * z.value;
  j.value = std::asin(z.value);
  const double d1 = 1.0 / std::sqrt(c2), d2 = z.value / (c2 * std::sqrt(c2));
  j.grad = d1 * z.grad;
  j.hess = d1 * z.hess + d2 * z.grad.transpose() * z.grad;
  return j;
}

ScalarJet scaled(ScalarJet j, double f) {
  j.value *= f;
  j.grad *= f;
  j.hess *= f;
  return j;
}

// +1 if (a, b, c) is a cyclic permutation of (0, 1, 2), -1 otherwise.
double parity(int a, int b, int c) {
  return ((a + 1) % 3 == b && (b + 1) % 3 == c) ? 1.0 : -1.0;
}

void add_point_jacobian(int b, const Vec4& p, const Vec3& s, double sign, int r_off, int p_off,
                        Row14* rows) {
  if (b < 0) return;
  const Mat34 bm = B_matrix(p, s);
  for (int k = 0; k < 3; ++k) {
    rows[k](r_off + k) += sign;
    rows[k].segment<4>(p_off) += sign * bm.row(k);
  }
}
}  // namespace

double wrap_angle(double a) {
  a = std::fmod(a + kPi, 2 * kPi);
  if (a <= 0) a += 2 * kPi;
  return a - kPi;
}

LocalState gather(const double* q, int bi, int bj) {
  LocalState s;
  if (bi >= 0) {
    s.ri = Eigen::Map<const Vec3>(q + 7 * bi);
    s.pi = Eigen::Map<const Vec4>(q + 7 * bi + 3);
  }
  if (bj >= 0) {
    s.rj = Eigen::Map<const Vec3>(q + 7 * bj);
    s.pj = Eigen::Map<const Vec4>(q + 7 * bj + 3);
  }
  return s;
}

Vec14 gather_local(const double* x, int bi, int bj) {
  Vec14 v = Vec14::Zero();
  if (bi >= 0) v.head<7>() = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(x + 7 * bi);
  if (bj >= 0) v.tail<7>() = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(x + 7 * bj);
  return v;
}

ScalarJet coordinate_jet(const CoordinateFunction& f, const LocalState& s) {
  const int bp = f.body_parent, bc = f.body_child;
  if (!f.rotation) {
    // Offset of the child origin from the anchor along a frame axis.
    if (!f.child_frame)
      return dot2_jet(bp, bc, s, f.frame_parent.col(f.axis), f.anchor, f.origin);
    // Axis fixed in the child: swap the roles (body i = child) and flip the sign.
    LocalState sw;
    sw.ri = s.rj;
    sw.pi = s.pj;
    sw.rj = s.ri;
    sw.pj = s.pi;
    ScalarJet j = dot2_jet(bc, bp, sw, f.frame_child.col(f.axis), f.origin, f.anchor);
    ScalarJet out = scaled(j, -1.0);
    // Swap the local blocks back.
    Eigen::Matrix<int, 14, 1> perm;
    for (int k = 0; k < 14; ++k) perm[k] = (k + 7) % 14;
    for (int a = 0; a < 14; ++a) {
      out.grad(perm[a]) = -j.grad(a);
      for (int b = 0; b < 14; ++b) out.hess(perm[a], perm[b]) = -j.hess(a, b);
    }
    return out;
  }
  // Relative rotation entries R[m][n] = (A_p fp_m).(A_c fc_n).
  auto entry = [&](int m, int n) {
    return dot1_jet(bp, bc, s, f.frame_parent.col(m), f.frame_child.col(n));
  };
  const int i0 = f.ax[0], i1 = f.ax[1], i2 = f.ax[2];
  const double sg = parity(i0, i1, i2);
  switch (f.index) {
    case 0: return atan2_jet(scaled(entry(i1, i2), -sg), entry(i2, i2));
    case 1: return asin_jet(scaled(entry(i0, i2), sg));
    default: return atan2_jet(scaled(entry(i0, i1), -sg), entry(i0, i0));
  }
}

void constraint_value(const Constraint& c, const LocalState& s, double t, double* v) {
  switch (c.type) {
    case Constraint::Type::kNorm: v[0] = s.pi.squaredNorm() - 1.0; return;
    case Constraint::Type::kPoint: {
      const Vec3 d = world_point(c.bi, s.ri, s.pi, c.si) - world_point(c.bj, s.rj, s.pj, c.sj);
      for (int k = 0, r = 0; k < 3; ++k)
        if (c.mask & (1 << k)) v[r++] = d[k];
      return;
    }
    case Constraint::Type::kDot1:
      v[0] = world_vector(c.bi, s.pi, c.ai).dot(world_vector(c.bj, s.pj, c.aj));
      return;
    case Constraint::Type::kDot2:
      v[0] = world_vector(c.bi, s.pi, c.ai)
                 .dot(world_point(c.bj, s.rj, s.pj, c.sj) - world_point(c.bi, s.ri, s.pi, c.si));
      return;
    case Constraint::Type::kDistance: {
      const Vec3 d = world_point(c.bj, s.rj, s.pj, c.sj) - world_point(c.bi, s.ri, s.pi, c.si);
      v[0] = d.squaredNorm() - c.distance * c.distance;
      return;
    }
    case Constraint::Type::kCoordinate: {
      const double g = coordinate_jet(c.coord, s).value - c.target.value(t);
      v[0] = c.coord.rotation ? wrap_angle(g) : g;
      return;
    }
  }
}

void constraint_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  for (int k = 0; k < c.rows(); ++k) rows[k].setZero();
  switch (c.type) {
    case Constraint::Type::kNorm: rows[0].segment<4>(kPi4) = 2.0 * s.pi.transpose(); return;
    case Constraint::Type::kPoint: {
      if (c.mask == 7) {
        add_point_jacobian(c.bi, s.pi, c.si, 1.0, kRi, kPi4, rows);
        add_point_jacobian(c.bj, s.pj, c.sj, -1.0, kRj, kPj, rows);
        return;
      }
      Row14 full[3];
      for (auto& f : full) f.setZero();
      add_point_jacobian(c.bi, s.pi, c.si, 1.0, kRi, kPi4, full);
      add_point_jacobian(c.bj, s.pj, c.sj, -1.0, kRj, kPj, full);
      for (int k = 0, r = 0; k < 3; ++k)
        if (c.mask & (1 << k)) rows[r++] = full[k];
      return;
    }
    case Constraint::Type::kDot1: rows[0] = dot1_jet(c.bi, c.bj, s, c.ai, c.aj).grad; return;
    case Constraint::Type::kDot2:
      rows[0] = dot2_jet(c.bi, c.bj, s, c.ai, c.si, c.sj).grad;
      return;
    case Constraint::Type::kDistance: {
      const Vec3 d = world_point(c.bj, s.rj, s.pj, c.sj) - world_point(c.bi, s.ri, s.pi, c.si);
      Row14 dd[3];
      for (auto& r : dd) r.setZero();
      add_point_jacobian(c.bj, s.pj, c.sj, 1.0, kRj, kPj, dd);
      add_point_jacobian(c.bi, s.pi, c.si, -1.0, kRi, kPi4, dd);
      rows[0] = 2.0 * (d[0] * dd[0] + d[1] * dd[1] + d[2] * dd[2]);
      return;
    }
    case Constraint::Type::kCoordinate: rows[0] = coordinate_jet(c.coord, s).grad; return;
  }
}

void constraint_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  switch (c.type) {
    case Constraint::Type::kNorm: h.block<4, 4>(kPi4, kPi4) += 2.0 * w[0] * Mat4::Identity(); return;
    case Constraint::Type::kPoint: {
      Vec3 lam = Vec3::Zero();
      for (int k = 0, r = 0; k < 3; ++k)
        if (c.mask & (1 << k)) lam[k] = w[r++];
      if (c.bi >= 0) h.block<4, 4>(kPi4, kPi4) += K_matrix(c.si, lam);
      if (c.bj >= 0) h.block<4, 4>(kPj, kPj) -= K_matrix(c.sj, lam);
      return;
    }
    case Constraint::Type::kDot1: h += w[0] * dot1_jet(c.bi, c.bj, s, c.ai, c.aj).hess; return;
    case Constraint::Type::kDot2:
      h += w[0] * dot2_jet(c.bi, c.bj, s, c.ai, c.si, c.sj).hess;
      return;
    case Constraint::Type::kDistance: {
      // Phi = d.d - D^2: Hessian = 2 (Jd^T Jd + sum_k d_k d2(d_k)).
      const Vec3 d = world_point(c.bj, s.rj, s.pj, c.sj) - world_point(c.bi, s.ri, s.pi, c.si);
      Row14 dd[3];
      for (auto& r : dd) r.setZero();
      add_point_jacobian(c.bj, s.pj, c.sj, 1.0, kRj, kPj, dd);
      add_point_jacobian(c.bi, s.pi, c.si, -1.0, kRi, kPi4, dd);
      Mat14 hh = Mat14::Zero();
      for (int k = 0; k < 3; ++k) hh += dd[k].transpose() * dd[k];
      if (c.bj >= 0) hh.block<4, 4>(kPj, kPj) += K_matrix(c.sj, d);
      if (c.bi >= 0) hh.block<4, 4>(kPi4, kPi4) -= K_matrix(c.si, d);
      h += 2.0 * w[0] * hh;
      return;
    }
    case Constraint::Type::kCoordinate: h += w[0] * coordinate_jet(c.coord, s).hess; return;
  }
}

void constraint_time_derivatives(const Constraint& c, double t, double* phi_t, double* phi_tt) {
  for (int k = 0; k < c.rows(); ++k) phi_t[k] = phi_tt[k] = 0.0;
  if (c.type == Constraint::Type::kCoordinate) {
    phi_t[0] = -c.target.derivative(t);
    phi_tt[0] = -c.target.second_derivative(t);
  }
}

}  // namespace mbdae
