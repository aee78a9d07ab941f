// The constant crank torque of the fast mechanism (slider_crank_fast.yaml), emulated by user
// force laws until an applied-torque force type exists: law "planar_torque_couple" applies, at a
// body point P1 with d = P2 - P1 (P2 the pivot on the axis z), the force
//   f = -(torque / |d_xy|^2) (e_z x d),
// normal to the radius in the xy plane, whose moment about the pivot is `torque` e_z. Two such
// elements at opposite crank points, each with half the torque, form a couple (no net force).
// Exact Jacobian with respect to d (d_dot does not enter).
#pragma once

#include "formulation/forces.h"

namespace mbdae {

inline void register_torque_couple_law() {
  UserForceLaw law;
  law.name = "planar_torque_couple";
  law.parameter_names = {"torque"};
  law.force = [](const Vec3& d, const Vec3&, double, const double* p) -> Vec3 {
    const double s = p[0] / (d.x() * d.x() + d.y() * d.y());
    return Vec3(s * d.y(), -s * d.x(), 0.0);
  };
  law.jacobian = [](const Vec3& d, const Vec3&, double, const double* p, Mat3& df_dd, Mat3& df_dv) {
    const double rho2 = d.x() * d.x() + d.y() * d.y();
    const double s = p[0] / rho2, c = 2.0 * p[0] / (rho2 * rho2);
    df_dd.setZero();
    df_dd(0, 0) = -c * d.x() * d.y();
    df_dd(0, 1) = s - c * d.y() * d.y();
    df_dd(1, 0) = -s + c * d.x() * d.x();
    df_dd(1, 1) = c * d.x() * d.y();
    df_dv.setZero();
  };
  register_force_law(law);
}

}  // namespace mbdae
