// Bushing: six coordinates y = (d, theta) of frame 2 relative to frame 1, d = C1^T A1^T (P2 - P1)
// and theta = 2 sign(w0) w_vec, w = conj(p1 c1) (p2 c2) the relative Euler parameters (c_k the
// frame's axes in its body): theta is the rotation vector to first order (2 sin(phi/2) u exactly).
// Q = -J^T (K y + C J v), J = dy/dx; dQ/dv = -J^T C J exactly, dQ/dx by central differences of Q
// (step 1e-6 max(1, |x_k|), truncation and rounding both below 1e-9 relative). Potential 1/2 y^T K y.
#include <algorithm>

#include "formulation/forces/element.h"

namespace mbdae {
namespace {
using namespace force_element;

// Quaternion products as matrices: a (x) b = left(a) b = right(b) a.
Mat4 quat_left(const Vec4& a) {
  Mat4 m;
  m << a[0], -a[1], -a[2], -a[3], a[1], a[0], -a[3], a[2], a[2], a[3], a[0], -a[1], a[3], -a[2], a[1], a[0];
  return m;
}
Mat4 quat_right(const Vec4& b) {
  Mat4 m;
  m << b[0], -b[1], -b[2], -b[3], b[1], b[0], b[3], -b[2], b[2], -b[3], b[0], b[1], b[3], b[2], -b[1], b[0];
  return m;
}
Vec4 conj(const Vec4& p) { return Vec4(p[0], -p[1], -p[2], -p[3]); }

// Bushing coordinates y = (d, theta) and their Jacobian J = dy/dx (6 x 14).
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

void eval(const Force& f, const LocalState& x, const LocalState& v, double, bool, Vec14& q, Mat14* dqx,
          Mat14* dqv, const LoadInput*, Mat14x3*) {
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

double length(const Force& f, const LocalState& x, double) {
  Eigen::Matrix<double, 6, 1> y;
  Eigen::Matrix<double, 6, 14> jac;
  bushing_coordinates(f, x, y, jac);
  return y.head<3>().norm();
}

// Magnitude of the force on body 1, |K_t d + C_t d'| (frame-1 axes).
double magnitude(const Force& f, const LocalState& x, const LocalState& v, double, bool, const LoadInput*) {
  Eigen::Matrix<double, 6, 1> y;
  Eigen::Matrix<double, 6, 14> jac;
  bushing_coordinates(f, x, y, jac);
  const Vec14 vl = local_vector(v);
  return (f.kt.cwiseProduct(y.head<3>()) + f.ct.cwiseProduct((jac * vl).head<3>())).norm();
}

double potential(const Force& f, const LocalState& x, double, bool, const LoadInput*) {
  Eigen::Matrix<double, 6, 1> y, k;
  Eigen::Matrix<double, 6, 14> jac;
  bushing_coordinates(f, x, y, jac);
  k << f.kt, f.kr;
  return 0.5 * y.dot(k.cwiseProduct(y));
}
}  // namespace

const ForceType& bushing_type() {
  static const ForceType row = {
      "bushing", ForceAttach::kTwoPoints,
      {"name", "type", "body1", "point1", "body2", "point2", "stiffness", "damping", "rotational_stiffness",
       "rotational_damping"},
      {}, {nullptr, nullptr, nullptr}, ForceGlyph::kLine, "m", "N",
      eval, length, magnitude, potential, nullptr};
  return row;
}

}  // namespace mbdae
