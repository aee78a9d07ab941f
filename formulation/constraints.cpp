#include "formulation/constraints.h"

#include <cmath>
#include <type_traits>

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

// Gradient of (A_i a).(A_j b), the Jacobian row alone (B(p, a)^T w = d(A(p) a . w)/dp).
Row14 dot1_gradient(int bi, int bj, const LocalState& s, const Vec3& a, const Vec3& b) {
  Row14 g = Row14::Zero();
  const Vec3 u = world_vector(bi, s.pi, a), w = world_vector(bj, s.pj, b);
  if (bi >= 0) g.segment<4>(kPi4) = w.transpose() * B_matrix(s.pi, a);
  if (bj >= 0) g.segment<4>(kPj) = u.transpose() * B_matrix(s.pj, b);
  return g;
}

// The jets below are templates over J: ScalarJet (value, gradient and Hessian) or ScalarSlope
// (value and gradient only, for the turns and the sensors, which read no Hessian). Value and
// gradient are the same expressions in both, so the same bits.
template <class J>
constexpr bool kHessian = std::is_same_v<J, ScalarJet>;

// Value, gradient and Hessian of (A_i a).(A_j b): a dot product of two body-fixed vectors.
template <class J>
J dot1_jet(int bi, int bj, const LocalState& s, const Vec3& a, const Vec3& b) {
  J j;
  const Vec3 u = world_vector(bi, s.pi, a), w = world_vector(bj, s.pj, b);
  j.value = u.dot(w);
  j.grad = dot1_gradient(bi, bj, s, a, b);
  if constexpr (kHessian<J>) {
    if (bi >= 0) j.hess.template block<4, 4>(kPi4, kPi4) = K_matrix(a, w);
    if (bj >= 0) j.hess.template block<4, 4>(kPj, kPj) = K_matrix(b, u);
    if (bi >= 0 && bj >= 0) {
      const Mat34 bu = B_matrix(s.pi, a), bw = B_matrix(s.pj, b);
      j.hess.template block<4, 4>(kPi4, kPj) = bu.transpose() * bw;
      j.hess.template block<4, 4>(kPj, kPi4) = bw.transpose() * bu;
    }
  }
  return j;
}

// Gradient of (A_i a).(P_j - P_i) with P_i = r_i + A_i si, P_j = r_j + A_j sj (the Jacobian row).
Row14 dot2_gradient(int bi, int bj, const LocalState& s, const Vec3& a, const Vec3& si, const Vec3& sj) {
  Row14 g = Row14::Zero();
  const Vec3 u = world_vector(bi, s.pi, a);
  const Vec3 d = world_point(bj, s.rj, s.pj, sj) - world_point(bi, s.ri, s.pi, si);
  if (bi >= 0) {
    g.segment<3>(kRi) = -u.transpose();
    g.segment<4>(kPi4) = d.transpose() * B_matrix(s.pi, a) - u.transpose() * B_matrix(s.pi, si);
  }
  if (bj >= 0) {
    g.segment<3>(kRj) = u.transpose();
    g.segment<4>(kPj) = u.transpose() * B_matrix(s.pj, sj);
  }
  return g;
}

// Its value, gradient and Hessian.
template <class J>
J dot2_jet(int bi, int bj, const LocalState& s, const Vec3& a, const Vec3& si, const Vec3& sj) {
  J j;
  const Vec3 u = world_vector(bi, s.pi, a);
  const Vec3 d = world_point(bj, s.rj, s.pj, sj) - world_point(bi, s.ri, s.pi, si);
  j.value = u.dot(d);
  j.grad = dot2_gradient(bi, bj, s, a, si, sj);
  if constexpr (kHessian<J>) {
    Mat34 ba = Mat34::Zero();
    if (bi >= 0) {
      ba = B_matrix(s.pi, a);
      const Mat34 bs = B_matrix(s.pi, si);
      j.hess.template block<3, 4>(kRi, kPi4) = -ba;
      j.hess.template block<4, 3>(kPi4, kRi) = -ba.transpose();
      j.hess.template block<4, 4>(kPi4, kPi4) =
          K_matrix(a, d) - K_matrix(si, u) - ba.transpose() * bs - bs.transpose() * ba;
    }
    if (bj >= 0) {
      const Mat34 bsj = B_matrix(s.pj, sj);
      j.hess.template block<4, 4>(kPj, kPj) = K_matrix(sj, u);
      if (bi >= 0) {
        j.hess.template block<4, 3>(kPi4, kRj) = ba.transpose();
        j.hess.template block<3, 4>(kRj, kPi4) = ba;
        j.hess.template block<4, 4>(kPi4, kPj) = ba.transpose() * bsj;
        j.hess.template block<4, 4>(kPj, kPi4) = bsj.transpose() * ba;
      }
    }
  }
  return j;
}

// theta = atan2(y, x) from the jets of y and x.
template <class J>
J atan2_jet(const J& y, const J& x) {
  J j;
  const double r2 = x.value * x.value + y.value * y.value;
  j.value = std::atan2(y.value, x.value);
  const double tx = -y.value / r2, ty = x.value / r2;
  j.grad = tx * x.grad + ty * y.grad;
  if constexpr (kHessian<J>) {
    const double txx = 2 * x.value * y.value / (r2 * r2), tyy = -txx;
    const double txy = (y.value * y.value - x.value * x.value) / (r2 * r2);
    j.hess = tx * x.hess + ty * y.hess + txx * x.grad.transpose() * x.grad +
             tyy * y.grad.transpose() * y.grad +
             txy * (x.grad.transpose() * y.grad + y.grad.transpose() * x.grad);
  }
  return j;
}

template <class J>
J asin_jet(const J& z) {
  J j;
  const double c2 = 1.0 - z.value * z.value;
  j.value = std::asin(z.value);
  const double d1 = 1.0 / std::sqrt(c2);
  j.grad = d1 * z.grad;
  if constexpr (kHessian<J>) {
    const double d2 = z.value / (c2 * std::sqrt(c2));
    j.hess = d1 * z.hess + d2 * z.grad.transpose() * z.grad;
  }
  return j;
}

template <class J>
J scaled(J j, double f) {
  j.value *= f;
  j.grad *= f;
  if constexpr (kHessian<J>) j.hess *= f;
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

namespace {

// A coordinate function's jet (J = ScalarJet) or slope (J = ScalarSlope).
template <class J>
J coordinate_function(const CoordinateFunction& f, const LocalState& s) {
  const int bp = f.body_parent, bc = f.body_child;
  if (!f.rotation) {
    // Offset of the child origin from the anchor along a frame axis.
    if (!f.child_frame)
      return dot2_jet<J>(bp, bc, s, f.frame_parent.col(f.axis), f.anchor, f.origin);
    // Axis fixed in the child: swap the roles (body i = child) and flip the sign.
    LocalState sw;
    sw.ri = s.rj;
    sw.pi = s.pj;
    sw.rj = s.ri;
    sw.pj = s.pi;
    J j = dot2_jet<J>(bc, bp, sw, f.frame_child.col(f.axis), f.origin, f.anchor);
    J out = scaled(j, -1.0);
    // Swap the local blocks back.
    Eigen::Matrix<int, 14, 1> perm;
    for (int k = 0; k < 14; ++k) perm[k] = (k + 7) % 14;
    for (int a = 0; a < 14; ++a) {
      out.grad(perm[a]) = -j.grad(a);
      if constexpr (kHessian<J>)
        for (int b = 0; b < 14; ++b) out.hess(perm[a], perm[b]) = -j.hess(a, b);
    }
    return out;
  }
  // Relative rotation entries R[m][n] = (A_p fp_m).(A_c fc_n).
  auto entry = [&](int m, int n) {
    return dot1_jet<J>(bp, bc, s, f.frame_parent.col(m), f.frame_child.col(n));
  };
  const int i0 = f.ax[0], i1 = f.ax[1], i2 = f.ax[2];
  const double sg = parity(i0, i1, i2);
  switch (f.index) {
    case 0: return atan2_jet(scaled(entry(i1, i2), -sg), entry(i2, i2));
    case 1: return asin_jet(scaled(entry(i0, i2), sg));
    default: return atan2_jet(scaled(entry(i0, i1), -sg), entry(i0, i0));
  }
}

}  // namespace

ScalarJet coordinate_jet(const CoordinateFunction& f, const LocalState& s) {
  return coordinate_function<ScalarJet>(f, s);
}

ScalarSlope coordinate_slope(const CoordinateFunction& f, const LocalState& s) {
  return coordinate_function<ScalarSlope>(f, s);
}

// --- The primitives -----------------------------------------------------------------------
// Each primitive's value, Jacobian rows, weighted Hessian sum_k w_k d2Phi_k/dq2 and velocity
// term -qdot^T d2Phi_k/dq2 qdot (the acceleration right side gamma without -Phi_tt), side by
// side. The velocity terms of norm, point and dot-1 are closed forms, with B(p', s) p' the
// second time derivative of A(p) s at p'' = 0 (d/dt A s = B(p, s) p'), cheaper than v^T H v
// (measured in docs/formulation.md, "Constraint primitives"); the others use the Hessian.
namespace {

inline Vec3 quad(int b, const Vec4& pd, const Vec3& x) {
  return b < 0 ? Vec3::Zero() : Vec3(B_matrix(pd, x) * pd);
}
inline Vec3 rate(int b, const Vec4& p, const Vec4& pd, const Vec3& x) {
  return b < 0 ? Vec3::Zero() : Vec3(B_matrix(p, x) * pd);
}

// -v^T H_k v for each row k, from the Hessian.
void hessian_velocity_terms(const Constraint& c, const LocalState& s, const LocalState& v, double* out);

// kNorm: p_i.p_i - 1 (1 row).
void norm_value(const Constraint& c, const LocalState& s, double, double* v) { v[0] = s.pi.squaredNorm() - 1.0; }
void norm_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  rows[0].segment<4>(kPi4) = 2.0 * s.pi.transpose();
}
void norm_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  h.block<4, 4>(kPi4, kPi4) += 2.0 * w[0] * Mat4::Identity();
}
void norm_velocity(const Constraint& c, const LocalState& s, const LocalState& v, double* g) {
  g[0] = -2.0 * v.pi.squaredNorm();
}

// kPoint: r_i + A_i s_i - r_j - A_j s_j, the components in `mask`.
void point_value(const Constraint& c, const LocalState& s, double, double* v) {
  const Vec3 d = world_point(c.bi, s.ri, s.pi, c.si) - world_point(c.bj, s.rj, s.pj, c.sj);
  for (int k = 0, r = 0; k < 3; ++k)
    if (c.mask & (1 << k)) v[r++] = d[k];
}
void point_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
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
}
void point_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  Vec3 lam = Vec3::Zero();
  for (int k = 0, r = 0; k < 3; ++k)
    if (c.mask & (1 << k)) lam[k] = w[r++];
  if (c.bi >= 0) h.block<4, 4>(kPi4, kPi4) += K_matrix(c.si, lam);
  if (c.bj >= 0) h.block<4, 4>(kPj, kPj) -= K_matrix(c.sj, lam);
}
void point_velocity(const Constraint& c, const LocalState& s, const LocalState& v, double* g) {
  const Vec3 h = quad(c.bi, v.pi, c.si) - quad(c.bj, v.pj, c.sj);
  for (int k = 0, r = 0; k < 3; ++k)
    if (c.mask & (1 << k)) g[r++] = -h[k];
}

// kDot1: (A_i a_i).(A_j a_j).
void dot1_value(const Constraint& c, const LocalState& s, double, double* v) {
  v[0] = world_vector(c.bi, s.pi, c.ai).dot(world_vector(c.bj, s.pj, c.aj));
}
void dot1_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  rows[0] = dot1_gradient(c.bi, c.bj, s, c.ai, c.aj);
}
void dot1_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  h += w[0] * dot1_jet<ScalarJet>(c.bi, c.bj, s, c.ai, c.aj).hess;
}
void dot1_velocity(const Constraint& c, const LocalState& s, const LocalState& v, double* g) {
  const Vec3 u = world_vector(c.bi, s.pi, c.ai), w = world_vector(c.bj, s.pj, c.aj);
  const double h = quad(c.bi, v.pi, c.ai).dot(w) + u.dot(quad(c.bj, v.pj, c.aj)) +
                   2.0 * rate(c.bi, s.pi, v.pi, c.ai).dot(rate(c.bj, s.pj, v.pj, c.aj));
  g[0] = -h;
}

// kDot2: (A_i a_i).(r_j + A_j s_j - r_i - A_i s_i).
void dot2_value(const Constraint& c, const LocalState& s, double, double* v) {
  v[0] = world_vector(c.bi, s.pi, c.ai)
             .dot(world_point(c.bj, s.rj, s.pj, c.sj) - world_point(c.bi, s.ri, s.pi, c.si));
}
void dot2_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  rows[0] = dot2_gradient(c.bi, c.bj, s, c.ai, c.si, c.sj);
}
void dot2_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  h += w[0] * dot2_jet<ScalarJet>(c.bi, c.bj, s, c.ai, c.si, c.sj).hess;
}

// kDistance: |d|^2 - D^2, d = r_j + A_j s_j - r_i - A_i s_i.
Vec3 distance_vector(const Constraint& c, const LocalState& s) {
  return world_point(c.bj, s.rj, s.pj, c.sj) - world_point(c.bi, s.ri, s.pi, c.si);
}
// Jacobian of d (3 rows).
void distance_vector_jacobian(const Constraint& c, const LocalState& s, Row14* dd) {
  for (int k = 0; k < 3; ++k) dd[k].setZero();
  add_point_jacobian(c.bj, s.pj, c.sj, 1.0, kRj, kPj, dd);
  add_point_jacobian(c.bi, s.pi, c.si, -1.0, kRi, kPi4, dd);
}
void distance_value(const Constraint& c, const LocalState& s, double, double* v) {
  v[0] = distance_vector(c, s).squaredNorm() - c.distance * c.distance;
}
void distance_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  const Vec3 d = distance_vector(c, s);
  Row14 dd[3];
  distance_vector_jacobian(c, s, dd);
  rows[0] = 2.0 * (d[0] * dd[0] + d[1] * dd[1] + d[2] * dd[2]);
}
void distance_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  // Hessian = 2 (Jd^T Jd + sum_k d_k d2(d_k)).
  const Vec3 d = distance_vector(c, s);
  Row14 dd[3];
  distance_vector_jacobian(c, s, dd);
  Mat14 hh = Mat14::Zero();
  for (int k = 0; k < 3; ++k) hh += dd[k].transpose() * dd[k];
  if (c.bj >= 0) hh.block<4, 4>(kPj, kPj) += K_matrix(c.sj, d);
  if (c.bi >= 0) hh.block<4, 4>(kPi4, kPi4) -= K_matrix(c.si, d);
  h += 2.0 * w[0] * hh;
}

// kCoordinate: g(q) - f(t), wrapped into (-pi, pi] for a rotation.
void coordinate_value(const Constraint& c, const LocalState& s, double t, double* v) {
  const double g = coordinate_jet(c.coord, s).value - c.target.value(t);
  v[0] = c.coord.rotation ? wrap_angle(g) : g;
}
void coordinate_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  rows[0] = coordinate_jet(c.coord, s).grad;
}
void coordinate_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  h += w[0] * coordinate_jet(c.coord, s).hess;
}

// kOrientation: (p_i (x) w).p_j = p_j^T R(w) p_i with R(w) p = p (x) w.
Vec4 quaternion_product(const Vec4& a, const Vec4& b) {
  Vec4 r;
  r[0] = a[0] * b[0] - a.tail<3>().dot(b.tail<3>());
  r.tail<3>() = a[0] * b.tail<3>() + b[0] * a.tail<3>() + a.tail<3>().cross(b.tail<3>());
  return r;
}
Mat4 right_product_matrix(const Vec4& w) {
  Mat4 m;
  for (int a = 0; a < 4; ++a) m.col(a) = quaternion_product(Vec4::Unit(a), w);
  return m;
}
void orientation_value(const Constraint& c, const LocalState& s, double, double* v) {
  v[0] = quaternion_product(s.pi, c.w).dot(s.pj);
}
void orientation_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  const Mat4 r = right_product_matrix(c.w);
  if (c.bi >= 0) rows[0].segment<4>(kPi4) = s.pj.transpose() * r;
  if (c.bj >= 0) rows[0].segment<4>(kPj) = (r * s.pi).transpose();
}
void orientation_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  if (c.bi < 0 || c.bj < 0) return;  // linear in the one moving body's p
  const Mat4 r = right_product_matrix(c.w);
  h.block<4, 4>(kPi4, kPj) += w[0] * r.transpose();
  h.block<4, 4>(kPj, kPi4) += w[0] * r;
}
void orientation_velocity(const Constraint& c, const LocalState& s, const LocalState& v, double* g) {
  g[0] = c.bi < 0 || c.bj < 0 ? 0.0 : -2.0 * quaternion_product(v.pi, c.w).dot(v.pj);
}

struct Primitive {
  void (*value)(const Constraint&, const LocalState&, double t, double* v);
  void (*jacobian)(const Constraint&, const LocalState&, Row14* rows);  // rows zeroed before
  void (*hessian)(const Constraint&, const LocalState&, const double* w, Mat14& h);
  void (*velocity)(const Constraint&, const LocalState&, const LocalState& v, double* g);
  bool hessian_touches_r;  // whether d2Phi/dq2 has entries in the r rows and columns
};

// In the order of Constraint::Type.
const Primitive kPrimitives[] = {
    {norm_value, norm_jacobian, norm_hessian, norm_velocity, false},
    {point_value, point_jacobian, point_hessian, point_velocity, false},
    {dot1_value, dot1_jacobian, dot1_hessian, dot1_velocity, false},
    {dot2_value, dot2_jacobian, dot2_hessian, hessian_velocity_terms, true},
    {distance_value, distance_jacobian, distance_hessian, hessian_velocity_terms, true},
    {coordinate_value, coordinate_jacobian, coordinate_hessian, hessian_velocity_terms, false},
    {orientation_value, orientation_jacobian, orientation_hessian, orientation_velocity, false},
};
static_assert(sizeof(kPrimitives) / sizeof(kPrimitives[0]) == 7, "one entry per Constraint::Type");

const Primitive& primitive(const Constraint& c) { return kPrimitives[static_cast<int>(c.type)]; }

void hessian_velocity_terms(const Constraint& c, const LocalState& s, const LocalState& sv, double* out) {
  Vec14 v = Vec14::Zero();
  if (c.bi >= 0) v.head<7>() << sv.ri, sv.pi;
  if (c.bj >= 0) v.tail<7>() << sv.rj, sv.pj;
  for (int r = 0; r < c.rows(); ++r) {
    double w[3] = {0, 0, 0};
    w[r] = 1.0;
    Mat14 h = Mat14::Zero();
    primitive(c).hessian(c, s, w, h);
    out[r] = -v.dot(h * v);
  }
}

}  // namespace

void constraint_value(const Constraint& c, const LocalState& s, double t, double* v) {
  primitive(c).value(c, s, t, v);
}

void constraint_jacobian(const Constraint& c, const LocalState& s, Row14* rows) {
  for (int k = 0; k < c.rows(); ++k) rows[k].setZero();
  primitive(c).jacobian(c, s, rows);
}

void constraint_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h) {
  primitive(c).hessian(c, s, w, h);
}

void constraint_gamma(const Constraint& c, const LocalState& s, const LocalState& v, const double* phi_tt,
                      double* gamma) {
  primitive(c).velocity(c, s, v, gamma);
  for (int r = 0; r < c.rows(); ++r) gamma[r] -= phi_tt[r];
}

bool constraint_hessian_touches_r(const Constraint& c) {
  return primitive(c).hessian_touches_r || (c.type == Constraint::Type::kCoordinate && !c.coord.rotation);
}

// The closed forms: A(p) s is quadratic in the Euler parameters and B(p, s) = d(A(p) s)/dp
// linear, so K(s, w) x = B(x, s)^T w (formulation/euler_parameters.h).
bool constraint_hessian_products(const Constraint& c, const LocalState& s, const Vec14& x, const Vec14& v,
                                 const double* mu, const double* lambda, Vec14& f1, Vec14& f2, double* g) {
  switch (c.type) {
    case Constraint::Type::kPoint: {  // r_i + A_i s_i - r_j - A_j s_j: H_r x on p_i is row r of B(x_pi, s_i)
      Vec3 m3 = Vec3::Zero(), l3 = Vec3::Zero(), gv = Vec3::Zero();
      for (int k = 0, r = 0; k < 3; ++k)
        if (c.mask & (1 << k)) {
          m3[k] = mu[r];
          l3[k] = lambda[r++];
        }
      for (int side = 0; side < 2; ++side) {
        const int b = side == 0 ? c.bi : c.bj, o = side == 0 ? kPi4 : kPj;
        if (b < 0) continue;
        const double sign = side == 0 ? 1.0 : -1.0;
        const Mat34 bx = B_matrix(x.segment<4>(o), side == 0 ? c.si : c.sj);
        f1.segment<4>(o) += sign * (bx.transpose() * m3);
        f2.segment<4>(o) += sign * (bx.transpose() * l3);
        gv += sign * (bx * v.segment<4>(o));
      }
      for (int k = 0, r = 0; k < 3; ++k)
        if (c.mask & (1 << k)) g[r++] = gv[k];
      return true;
    }
    case Constraint::Type::kDot1: {  // u.w, u = A_i a_i, w = A_j a_j: H x on p_i is B(p_i, a_i)^T B(p_j, a_j) x_pj + B(x_pi, a_i)^T w
      const Vec3 u = world_vector(c.bi, s.pi, c.ai), w = world_vector(c.bj, s.pj, c.aj);
      Mat34 bi = Mat34::Zero(), bj = Mat34::Zero();
      Vec3 du = Vec3::Zero(), dw = Vec3::Zero();  // u and w along x
      if (c.bi >= 0) {
        bi = B_matrix(s.pi, c.ai);
        du = bi * x.segment<4>(kPi4);
      }
      if (c.bj >= 0) {
        bj = B_matrix(s.pj, c.aj);
        dw = bj * x.segment<4>(kPj);
      }
      Vec14 hx = Vec14::Zero();
      if (c.bi >= 0) hx.segment<4>(kPi4) = bi.transpose() * dw + B_matrix(x.segment<4>(kPi4), c.ai).transpose() * w;
      if (c.bj >= 0) hx.segment<4>(kPj) = bj.transpose() * du + B_matrix(x.segment<4>(kPj), c.aj).transpose() * u;
      f1 += mu[0] * hx;
      f2 += lambda[0] * hx;
      g[0] = v.dot(hx);
      return true;
    }
    case Constraint::Type::kNorm:  // p_i.p_i - 1: H = 2 I on p_i
      f1.segment<4>(kPi4) += (2.0 * mu[0]) * x.segment<4>(kPi4);
      f2.segment<4>(kPi4) += (2.0 * lambda[0]) * x.segment<4>(kPi4);
      g[0] = 2.0 * v.segment<4>(kPi4).dot(x.segment<4>(kPi4));
      return true;
    default:
      return false;
  }
}

void orientation_rows(const Vec4& c_i, const Vec4& c_j, Vec4 w[3]) {
  const Vec4 cj_conj(c_j[0], -c_j[1], -c_j[2], -c_j[3]);
  const Vec4 d = quaternion_product(c_i, cj_conj);
  const Vec4 d_conj(d[0], -d[1], -d[2], -d[3]);
  // Row k of the matrix of q -> conj(d) (x) q.
  for (int k = 0; k < 3; ++k)
    for (int b = 0; b < 4; ++b) w[k][b] = quaternion_product(d_conj, Vec4::Unit(b))[k + 1];
}

std::string row_label(const Constraint& c, int row) {
  if (c.type != Constraint::Type::kPoint) return c.label;
  for (int comp = 0, r = 0; comp < 3; ++comp)
    if (c.mask & (1 << comp) && r++ == row) return c.label + " [" + "xyz"[comp] + "]";
  return c.label;
}

std::string constraint_group(const Constraint& c) {
  switch (c.owner) {
    case Constraint::Owner::kNorm: return "body " + c.owner_name;
    case Constraint::Owner::kJoint: return "joint " + c.owner_name;
    case Constraint::Owner::kCut: return "cut " + c.owner_name;
    case Constraint::Owner::kDrive: return "drive " + c.owner_name;
    case Constraint::Owner::kLock: return "lock " + c.owner_name;
    case Constraint::Owner::kHold: return "hold " + c.owner_name;
  }
  return c.owner_name;
}

void constraint_time_derivatives(const Constraint& c, double t, double* phi_t, double* phi_tt) {
  for (int k = 0; k < c.rows(); ++k) phi_t[k] = phi_tt[k] = 0.0;
  if (c.type == Constraint::Type::kCoordinate) {
    phi_t[0] = -c.target.derivative(t);
    phi_tt[0] = -c.target.second_derivative(t);
  }
}

}  // namespace mbdae
