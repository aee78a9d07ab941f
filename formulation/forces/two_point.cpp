// Elements between two body points (spring-damper, user laws): forces.h, formulation/forces/element.h.
#include "formulation/forces/element.h"

namespace mbdae::force_element {

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

void two_point_eval(TwoPointLaw law, const Force& f, const LocalState& x, const LocalState& v, double t, Vec14& q,
                    Mat14* dqx, Mat14* dqv) {
  const TwoPoint tp = two_point(f, x, v);
  Vec3 force;
  Mat3 fd, fdd;
  law(f, tp, t, force, dqx ? &fd : nullptr, dqx ? &fdd : nullptr);
  // Q = G1^T f - G2^T f = -dq^T f.
  q.noalias() -= tp.dq.transpose() * force;
  if (!dqx) return;
  const Eigen::Matrix<double, 3, 14> dfx = fd * tp.dq + fdd * tp.dv;
  const Eigen::Matrix<double, 3, 14> dfv = fdd * tp.dq;
  dqx->noalias() -= tp.dq.transpose() * dfx;
  dqv->noalias() -= tp.dq.transpose() * dfv;
  if (f.bi >= 0) dqx->block<4, 4>(kPi4, kPi4) += K_matrix(f.si, force);
  if (f.bj >= 0) dqx->block<4, 4>(kPj, kPj) -= K_matrix(f.sj, force);
}

double two_point_length(const Force& f, const LocalState& x, double) {
  return (point(f.bj, x.rj, x.pj, f.sj) - point(f.bi, x.ri, x.pi, f.si)).norm();
}

double two_point_tension(TwoPointLaw law, const Force& f, const LocalState& x, const LocalState& v, double t) {
  const TwoPoint tp = two_point(f, x, v);
  Vec3 force;
  law(f, tp, t, force, nullptr, nullptr);
  return force.dot(tp.d.normalized());
}

}  // namespace mbdae::force_element
