// Euler-parameter (unit quaternion) kinematics used by every body.
//
// A body's orientation is p = (e0, e1, e2, e3) with |p| = 1. With e = (e1, e2, e3),
//   A(p) = (e0^2 - e.e) I + 2 e e^T + 2 e0 [e]x          (body -> world rotation)
//   L(p) = [-e, -[e]x + e0 I]   (3x4),   omega_body = 2 L(p) pdot
// A(p) s is a homogeneous quadratic form in p, so its derivative is linear in p:
//   B(p, s) = d(A(p) s)/dp = 2 [ (e0 I + [e]x) s,  (e.s) I + e s^T - s e^T - e0 [s]x ]  (3x4)
// and B(p, s) p = 2 A(p) s. Because the Hessian of w.A(p)s is constant and symmetric,
//   d(B(p, s) x)/dp = B(x, s)   and   d(B(p, s)^T w)/dp = K(s, w) (4x4, symmetric),
// with column k of K(s, w) = B(u_k, s)^T w, u_k the k-th unit 4-vector.
// These identities make every constraint, force and sensor a few lines of code; they are
// checked against finite differences in formulation/tests/euler_parameters_test.cpp.
#pragma once

#include <Eigen/Dense>

namespace mbdae {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat43 = Eigen::Matrix<double, 4, 3>;

inline Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// Rotation matrix A(p). p need not be normalized: the formula is the quadratic form.
inline Mat3 rotation(const Vec4& p) {
  const double e0 = p[0];
  const Vec3 e = p.tail<3>();
  return (e0 * e0 - e.dot(e)) * Mat3::Identity() + 2.0 * e * e.transpose() + 2.0 * e0 * skew(e);
}

// A(p) s without forming A.
inline Vec3 rotate(const Vec4& p, const Vec3& s) {
  const double e0 = p[0];
  const Vec3 e = p.tail<3>();
  return (e0 * e0 - e.dot(e)) * s + 2.0 * e * e.dot(s) + 2.0 * e0 * e.cross(s);
}

// L(p): omega_body = 2 L(p) pdot.
inline Mat34 L_matrix(const Vec4& p) {
  Mat34 l;
  l.col(0) = -p.tail<3>();
  l.rightCols<3>() = -skew(p.tail<3>()) + p[0] * Mat3::Identity();
  return l;
}

// B(p, s) = d(A(p) s)/dp = 2 [ e0 s + e x s,  (e.s) I + e s^T - s e^T - e0 [s]x ], entry by
// entry (a hot kernel: every point constraint and force), with Eigen's operations and order.
inline Mat34 B_matrix(const Vec4& p, const Vec3& s) {
  const double e0 = p[0], e1 = p[1], e2 = p[2], e3 = p[3];
  const double es = p.tail<3>().dot(s);
  Mat34 b;
  b(0, 0) = 2.0 * (e0 * s[0] + (e2 * s[2] - e3 * s[1]));
  b(1, 0) = 2.0 * (e0 * s[1] + (e3 * s[0] - e1 * s[2]));
  b(2, 0) = 2.0 * (e0 * s[2] + (e1 * s[1] - e2 * s[0]));
  // (e.s) I + e s^T - s e^T - e0 [s]x, [s]x = [0 -s2 s1; s2 0 -s0; -s1 s0 0].
  b(0, 1) = 2.0 * ((es + e1 * s[0]) - s[0] * e1);
  b(1, 2) = 2.0 * ((es + e2 * s[1]) - s[1] * e2);
  b(2, 3) = 2.0 * ((es + e3 * s[2]) - s[2] * e3);
  b(0, 2) = 2.0 * ((e1 * s[1] - s[0] * e2) - e0 * -s[2]);
  b(0, 3) = 2.0 * ((e1 * s[2] - s[0] * e3) - e0 * s[1]);
  b(1, 1) = 2.0 * ((e2 * s[0] - s[1] * e1) - e0 * s[2]);
  b(1, 3) = 2.0 * ((e2 * s[2] - s[1] * e3) - e0 * -s[0]);
  b(2, 1) = 2.0 * ((e3 * s[0] - s[2] * e1) - e0 * -s[1]);
  b(2, 2) = 2.0 * ((e3 * s[1] - s[2] * e2) - e0 * s[0]);
  return b;
}

// K(s, w) = d(B(p, s)^T w)/dp, independent of p.
inline Mat4 K_matrix(const Vec3& s, const Vec3& w) {
  Mat4 out;
  out.col(0) = 2.0 * Vec4(s.dot(w), -w.dot(skew(s).col(0)), -w.dot(skew(s).col(1)),
                          -w.dot(skew(s).col(2)));
  // Columns 1..3: B(u_k, s) = 2 [ u x s, s_k I + u s^T - s u^T ] with u = unit vector k.
  for (int k = 0; k < 3; ++k) {
    const Vec3 u = Vec3::Unit(k);
    Mat34 b;
    b.col(0) = 2.0 * u.cross(s);
    b.rightCols<3>() = 2.0 * (s[k] * Mat3::Identity() + u * s.transpose() - s * u.transpose());
    out.col(k + 1) = b.transpose() * w;
  }
  return out;
}

// P(w) = d(L(p)^T w)/dp (L is linear in p): column k is L(u_k)^T w.
inline Mat4 P_matrix(const Vec3& w) {
  Mat4 m;
  for (int k = 0; k < 4; ++k) m.col(k) = L_matrix(Vec4::Unit(k)).transpose() * w;
  return m;
}

// Euler parameters of a rotation matrix (Shepperd's method), e0 >= 0.
Vec4 euler_parameters_from_rotation(const Mat3& a);

// Elementary rotation about body axis 0 (x), 1 (y) or 2 (z).
Mat3 axis_rotation(int axis, double angle);

}  // namespace mbdae
