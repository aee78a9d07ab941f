// What the force laws of formulation/forces/ share: points of the (up to two) bodies of an
// element and their Jacobians in the local 14-vector [ri, pi, rj, pj], a world force applied at a
// point, the relative position of two points, and the given components of a load.
#pragma once

#include <cmath>

#include "formulation/force_types.h"

namespace mbdae::force_element {

constexpr int kRi = 0, kPi4 = 3, kRj = 7, kPj = 10;

inline Vec3 point(int b, const Vec3& r, const Vec4& p, const Vec3& s) {
  return b < 0 ? s : Vec3(r + rotate(p, s));
}
inline Vec3 point_velocity(int b, const Vec4& p, const Vec3& rd, const Vec4& pd, const Vec3& s) {
  return b < 0 ? Vec3::Zero() : Vec3(rd + B_matrix(p, s) * pd);
}

// d(point)/d(local q) as 3 x 14 for body slot (i or j).
inline Eigen::Matrix<double, 3, 14> point_jacobian(int b, const Vec4& p, const Vec3& s, bool slot_j) {
  Eigen::Matrix<double, 3, 14> g = Eigen::Matrix<double, 3, 14>::Zero();
  if (b < 0) return g;
  g.block<3, 3>(0, slot_j ? kRj : kRi) = Mat3::Identity();
  g.block<3, 4>(0, slot_j ? kPj : kPi4) = B_matrix(p, s);
  return g;
}

// Generalized force of world force f at point s of body slot, plus dQ/dp for fixed f.
inline void apply_point_force(int b, const Vec4& p, const Vec3& s, const Vec3& f, bool slot_j, Vec14& q, Mat14* dq) {
  if (b < 0) return;
  const int ro = slot_j ? kRj : kRi, po = slot_j ? kPj : kPi4;
  q.segment<3>(ro) += f;
  q.segment<4>(po) += B_matrix(p, s).transpose() * f;
  if (dq) dq->block<4, 4>(po, po) += K_matrix(s, f);
}

// Component k of a point force or torque: its expression's value if it has one, else fx/fy/fz(t).
inline double component(const Force& f, int k, double t, const LoadInput* in) {
  if (!f.expression[k].empty()) return in ? in->value[k] : 0.0;
  return (k == 0 ? f.fx : k == 1 ? f.fy : f.fz).value(t);
}

// Two-point elements (spring-damper, user law): relative position d = P2 - P1, velocity, and
// their Jacobians (two_point.cpp).
struct TwoPoint {
  Vec3 d, dd;
  Eigen::Matrix<double, 3, 14> dq;  // d(d)/dq = d(dd)/dqdot
  Eigen::Matrix<double, 3, 14> dv;  // d(dd)/dq
};
TwoPoint two_point(const Force& f, const LocalState& x, const LocalState& v);

// A two-point law: the force on point 1 and, if df_dd is given, its derivatives with respect to
// d and d_dot.
using TwoPointLaw = void (*)(const Force& f, const TwoPoint& tp, double t, Vec3& force, Mat3* df_dd, Mat3* df_ddd);
// Generalized force of a two-point law (force f on point 1, -f on point 2) and its Jacobians.
void two_point_eval(TwoPointLaw law, const Force& f, const LocalState& x, const LocalState& v, double t, Vec14& q,
                    Mat14* dqx, Mat14* dqv);
// Distance of the two points; tension (force along d) of a two-point law.
double two_point_length(const Force& f, const LocalState& x, double t);
double two_point_tension(TwoPointLaw law, const Force& f, const LocalState& x, const LocalState& v, double t);

}  // namespace mbdae::force_element
