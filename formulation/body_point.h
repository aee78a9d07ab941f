// The kinematics of bodies and of points fixed on them, in absolute coordinates: what
// constraints, forces, sensors and the animation read from the state vectors.
//
// Body b's coordinates in q are q[7b .. 7b+7] = (r_b, p_b): r_b its centre of mass in the world,
// p_b its Euler parameters (A(p) its rotation, B(p, s) = d(A(p) s)/dp). A point s fixed on the
// body (in its centre-of-mass frame) has
//   position      x = r + A(p) s
//   velocity      x' = r' + B(p, s) p'
//   acceleration  x'' = r'' + B(p, s) p'' + B(p', s) p'
// and dx/d(r, p) = [I, B(p, s)], dx'/d(r', p') = [I, B(p, s)], dx'/dp = B(p', s).
// Ground (index -1) has r = 0, p = (1, 0, 0, 0): its points are world points.
#pragma once

#include "formulation/euler_parameters.h"

namespace mbdae {

using Vec14 = Eigen::Matrix<double, 14, 1>;
using Row14 = Eigen::Matrix<double, 1, 14>;
using Mat14 = Eigen::Matrix<double, 14, 14>;

// One body's pose (or its rates: the same slice of v or a).
struct BodyPose {
  Vec3 r = Vec3::Zero();
  Vec4 p = Vec4(1, 0, 0, 0);
};
// Body b's slice of a state vector x (q, v or a); ground's pose (or zero rates) for b < 0.
BodyPose body_pose(const double* x, int b, bool rates = false);

// Position, velocity and acceleration of the point s fixed on a body (formulas above).
Vec3 point_position(const BodyPose& q, const Vec3& s);
Vec3 point_velocity(const BodyPose& q, const BodyPose& v, const Vec3& s);
Vec3 point_acceleration(const BodyPose& q, const BodyPose& v, const BodyPose& a, const Vec3& s);

// Local coordinates of two bodies (a constraint's or a force's), gathered from the global vector q.
struct LocalState {
  Vec3 ri = Vec3::Zero(), rj = Vec3::Zero();
  Vec4 pi = Vec4(1, 0, 0, 0), pj = Vec4(1, 0, 0, 0);
};
// The two bodies' coordinates from the global q (ground: the origin, unrotated). Inline: every
// constraint, force and sensor evaluation starts with it.
inline LocalState gather(const double* q, int bi, int bj) {
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
// The local 14-vector [x_bi; x_bj] of a global vector (zeros for ground). Inline: every Jacobian
// product gathers its vectors per constraint and force.
inline Vec14 gather_local(const double* x, int bi, int bj) {
  Vec14 v = Vec14::Zero();
  if (bi >= 0) v.head<7>() = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(x + 7 * bi);
  if (bj >= 0) v.tail<7>() = Eigen::Map<const Eigen::Matrix<double, 7, 1>>(x + 7 * bj);
  return v;
}
// A LocalState as the local 14-vector [ri, pi, rj, pj], and back.
Vec14 local_vector(const LocalState& s);
LocalState local_state(const Vec14& y);

}  // namespace mbdae
