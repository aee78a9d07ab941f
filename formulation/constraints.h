// Scalar constraint equations between (at most) two bodies, in absolute coordinates.
//
// Each body b has q_b = (r_b, p_b): r_b the centre of mass in the world, p_b its Euler
// parameters. A constraint touches the 14 local coordinates [q_i, q_j]; ground (index -1)
// contributes none. Every equation provides its value, its gradient (a row of the constraint
// Jacobian) and its Hessian (needed for the exact Newton matrix, sum_k lambda_k d2Phi_k/dq2,
// and for the acceleration-level right side gamma = -qdot^T d2Phi/dq2 qdot - Phi_tt).
//
// Primitive equations (Haug, Computer-Aided Kinematics and Dynamics, ch. 9 and 11):
//   kNorm   p_i.p_i - 1 = 0
//   kPoint  r_i + A_i s_i - r_j - A_j s_j = 0                       (3 rows)
//   kDot1   (A_i a_i).(A_j a_j) = 0                                 (perpendicular axes)
//   kDot2   (A_i a_i).(r_j + A_j s_j - r_i - A_i s_i) = 0           (point on a plane)
//   kDistance |r_j + A_j s_j - r_i - A_i s_i|^2 - d^2 = 0
//   kCoordinate  g(q) - f(t) = 0: a joint coordinate of a chain held (locked) or driven.
#pragma once

#include <string>

#include "core/time_function.h"
#include "formulation/euler_parameters.h"

namespace mbdae {

using Vec14 = Eigen::Matrix<double, 14, 1>;
using Row14 = Eigen::Matrix<double, 1, 14>;
using Mat14 = Eigen::Matrix<double, 14, 14>;

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
  enum class Type { kNorm, kPoint, kDot1, kDot2, kDistance, kCoordinate };
  Type type = Type::kPoint;
  int bi = -1, bj = -1;  // body indices, -1 = ground (its points are world points)
  Vec3 si = Vec3::Zero(), sj = Vec3::Zero();
  Vec3 ai = Vec3::Zero(), aj = Vec3::Zero();
  double distance = 0;
  CoordinateFunction coord;  // kCoordinate
  TimeFunction target;       // kCoordinate: f(t)
  std::string label;         // e.g. "joint rod2: axis x _|_ z"
  int mask = 7;              // kPoint: active components (bit k = world axis k); rows compacted

  int rows() const { return type == Type::kPoint ? __builtin_popcount(mask) : 1; }
};

// Local coordinates of a constraint's two bodies, gathered from the global vector q.
struct LocalState {
  Vec3 ri = Vec3::Zero(), rj = Vec3::Zero();
  Vec4 pi = Vec4(1, 0, 0, 0), pj = Vec4(1, 0, 0, 0);
};
LocalState gather(const double* q, int bi, int bj);
Vec14 gather_local(const double* x, int bi, int bj);  // local 14-vector (zeros for ground)

// Values of the constraint rows (1 or 3).
void constraint_value(const Constraint& c, const LocalState& s, double t, double* value);
// Rows of the Jacobian with respect to the 14 local coordinates.
void constraint_jacobian(const Constraint& c, const LocalState& s, Row14* rows);
// Adds sum_k w_k d2(Phi_k)/dq2 (local 14 x 14) to h.
void constraint_hessian(const Constraint& c, const LocalState& s, const double* w, Mat14& h);
// Explicit time derivatives dPhi/dt and d2Phi/dt2 of each row (non-zero for driven rows).
void constraint_time_derivatives(const Constraint& c, double t, double* phi_t, double* phi_tt);

// Value, gradient and Hessian of a joint coordinate function (for sensors and drivers).
struct ScalarJet {
  double value = 0;
  Row14 grad = Row14::Zero();
  Mat14 hess = Mat14::Zero();
};
ScalarJet coordinate_jet(const CoordinateFunction& f, const LocalState& s);

// Wraps an angle difference into (-pi, pi].
double wrap_angle(double a);

}  // namespace mbdae
