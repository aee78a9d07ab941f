// Scalar constraint equations between (at most) two bodies, in absolute coordinates.
//
// Each body b has q_b = (r_b, p_b): r_b the centre of mass in the world, p_b its Euler
// parameters. A constraint touches the 14 local coordinates [q_i, q_j]; ground (index -1)
// contributes none. Every equation provides its value, its gradient (a row of the constraint
// Jacobian) and its Hessian (needed for the exact Newton matrix, sum_k lambda_k d2Phi_k/dq2,
// and for the acceleration-level right side gamma = -qdot^T d2Phi/dq2 qdot - Phi_tt).
//
// Primitive equations (Haug, Computer-Aided Kinematics and Dynamics, ch. 9 and 11), each with its
// value, Jacobian, Hessian and acceleration right side in one table in constraints.cpp:
//   kNorm   p_i.p_i - 1 = 0
//   kPoint  r_i + A_i s_i - r_j - A_j s_j = 0                       (3 rows)
//   kDot1   (A_i a_i).(A_j a_j) = 0                                 (perpendicular axes)
//   kDot2   (A_i a_i).(r_j + A_j s_j - r_i - A_i s_i) = 0           (point on a plane)
//   kDistance |r_j + A_j s_j - r_i - A_i s_i|^2 - d^2 = 0
//   kCoordinate  g(q) - f(t) = 0: a joint coordinate of a chain held (locked) or driven.
//   kOrientation (p_i (x) w).p_j = 0: component k of the vector part of the Euler parameters
//                conj(d) (x) conj(p_i) (x) p_j, with (x) the quaternion product and w the
//                constant k-th row of the left-product matrix of conj(d). The three components
//                vanish only where the relative rotation conj(p_i) (x) p_j equals the constant d
//                (not at its 180-degree flips, unlike three dot-1 equations).
#pragma once

#include <string>

#include "core/time_function.h"
#include "formulation/body_point.h"
#include "formulation/euler_parameters.h"

namespace mbdae {


// A joint coordinate measured from the two bodies' poses.
//  Rotation of a chain whose rotations (completed to three distinct axes ax[0..2]) give the
//  relative rotation R = Rparent^T Rchild = R_ax0(a0) R_ax1(a1) R_ax2(a2); `index` picks a_k.
//  Translation: the offset from the anchor to the child origin along `axis` of the parent
//  frame (or of the child frame when `child_frame`).
struct CoordinateFunction {
  bool rotation = true;
  int ax[3] = {0, 1, 2};
  int index = 0;
  int axis = 0;
  bool child_frame = false;
  // Frame data in each body's local (centre-of-mass) coordinates.
  int body_parent = -1, body_child = -1;
  Mat3 frame_parent = Mat3::Identity();  // joint frame axes in the parent body's coordinates
  Mat3 frame_child = Mat3::Identity();   // child frame axes in the child body's coordinates
  Vec3 anchor = Vec3::Zero();            // anchor point on the parent (local)
  Vec3 origin = Vec3::Zero();            // child frame origin on the child (local)
};

struct Constraint {
  enum class Type { kNorm, kPoint, kDot1, kDot2, kDistance, kCoordinate, kOrientation };
  // What the equation belongs to: a body's Euler-parameter norm, a tree joint, a loop cut, a
  // driven, locked or held (assembly, equilibrium) joint coordinate.
  enum class Owner { kNorm, kJoint, kCut, kDrive, kLock, kHold };
  Type type = Type::kPoint;
  Owner owner = Owner::kJoint;
  std::string owner_name;  // the body, joint, cut or coordinate
  int bi = -1, bj = -1;  // body indices, -1 = ground (its points are world points)
  Vec3 si = Vec3::Zero(), sj = Vec3::Zero();
  Vec3 ai = Vec3::Zero(), aj = Vec3::Zero();
  double distance = 0;
  Vec4 w = Vec4::Zero();     // kOrientation: the row w (orientation_rows())
  CoordinateFunction coord;  // kCoordinate
  TimeFunction target;       // kCoordinate: f(t)
  std::string label;         // for messages, e.g. "joint rod2 (R1): parent y _|_ child x"
  int mask = 7;              // kPoint: active components (bit k = world axis k); rows compacted

  int rows() const { return type == Type::kPoint ? (mask & 1) + (mask >> 1 & 1) + (mask >> 2 & 1) : 1; }
};

// Values of the constraint rows (1 or 3).
void constraint_value(const Constraint& c, const LocalState& s, double t, double* value);
// Rows of the Jacobian with respect to the 14 local coordinates.
void constraint_jacobian(const Constraint& c, const LocalState& s, Row14* rows);
// Adds sum_k w_k d2(Phi_k)/dq2 (local 14 x 14) to h.
void constraint_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h);
// Explicit time derivatives dPhi/dt and d2Phi/dt2 of each row (non-zero for driven rows).
void constraint_time_derivatives(const Constraint& c, double t, double* phi_t, double* phi_tt);
// The acceleration right side of each row, gamma = -v^T d2Phi/dq2 v - Phi_tt, for the
// velocities v gathered like the coordinates s (gather(v, bi, bj)) and the rows' Phi_tt.
void constraint_gamma(const Constraint& c, const LocalState& s, const LocalState& v,
                      const double* phi_tt, double* gamma);
// Whether the Hessian has entries in the position (r) rows and columns (dot-2, distance,
// translation coordinates); the others depend on r linearly or not at all.
bool constraint_hessian_touches_r(const Constraint& c);
// The Hessian terms of the constraint's rows along one direction x (local, like v), without the
// Hessians, where its type has them in closed form (point, dot-1, norm): f1 += sum_r mu_r H_r x,
// f2 += sum_r lambda_r H_r x, g[r] = v^T H_r x. False, nothing added, for the other types.
bool constraint_hessian_products(const Constraint& c, const LocalState& s, const Vec14& x, const Vec14& v,
                                 const double* mu, const double* lambda, Vec14& f1, Vec14& f2, double* g);
// Global index of local coordinate l (0..13) of a constraint between bodies bi, bj; -1 for ground.
inline int global_index(int bi, int bj, int l) {
  const int b = l < 7 ? bi : bj;
  return b < 0 ? -1 : 7 * b + (l % 7);
}

// "joint rod2 (R1): origin at anchor [y]": a constraint's label, with the world component of a
// point constraint's row `row` (rows counted among the active components).
std::string row_label(const Constraint& c, int row);
// "joint rod2", "cut ball2", "drive q4", "lock q1", "hold q1", "body rod3": what the constraint
// belongs to.
std::string constraint_group(const Constraint& c);

// Value, gradient and Hessian of a joint coordinate function (for sensors and drivers).
struct ScalarJet {
  double value = 0;
  Row14 grad = Row14::Zero();
  Mat14 hess = Mat14::Zero();
};
ScalarJet coordinate_jet(const CoordinateFunction& f, const LocalState& s);
// Its value and gradient alone, bit for bit coordinate_jet's, without the Hessian's cost (the
// turns at every step, the coordinate sensors).
struct ScalarSlope {
  double value = 0;
  Row14 grad = Row14::Zero();
};
ScalarSlope coordinate_slope(const CoordinateFunction& f, const LocalState& s);

// The three kOrientation rows w_k (k = x, y, z) that hold conj(p_i) (x) p_j = d, i.e. the
// frames with Euler parameters c_i on body i and c_j on body j aligned, d = c_i (x) conj(c_j).
void orientation_rows(const Vec4& c_i, const Vec4& c_j, Vec4 w[3]);

// Wraps an angle difference into (-pi, pi].
double wrap_angle(double a);

}  // namespace mbdae
