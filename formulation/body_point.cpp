// Body and body-point kinematics (formulation/body_point.h).
#include "formulation/body_point.h"

namespace mbdae {

BodyPose body_pose(const double* x, int b, bool rates) {
  BodyPose s;
  if (rates) s.p = Vec4::Zero();
  if (b < 0) return s;
  s.r = Eigen::Map<const Vec3>(x + 7 * b);
  s.p = Eigen::Map<const Vec4>(x + 7 * b + 3);
  return s;
}

Vec3 point_position(const BodyPose& q, const Vec3& s) { return q.r + rotate(q.p, s); }

Vec3 point_velocity(const BodyPose& q, const BodyPose& v, const Vec3& s) {
  return v.r + B_matrix(q.p, s) * v.p;
}

Vec3 point_acceleration(const BodyPose& q, const BodyPose& v, const BodyPose& a, const Vec3& s) {
  return a.r + B_matrix(q.p, s) * a.p + B_matrix(v.p, s) * v.p;
}

Vec14 local_vector(const LocalState& s) {
  Vec14 y;
  y << s.ri, s.pi, s.rj, s.pj;
  return y;
}

LocalState local_state(const Vec14& y) {
  LocalState s;
  s.ri = y.segment<3>(0);
  s.pi = y.segment<4>(3);
  s.rj = y.segment<3>(7);
  s.pj = y.segment<4>(10);
  return s;
}

}  // namespace mbdae
