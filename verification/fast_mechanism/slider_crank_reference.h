// Independent reference for the fast mechanism (slider_crank_fast.yaml): the slider-crank's
// one-degree-of-freedom Lagrange equation in the crank angle theta,
//   M(theta) theta'' + 1/2 M'(theta) theta'^2 = tau,
// with M(theta) = J_c + m_c a^2 + m_r |R'|^2 + J_r psi'^2 + m_p x'^2 (primes: d/dtheta; R the
// rod's centre of mass, psi the rod's angle, x the piston), written in closed form from the
// planar geometry, and integrated by an adaptive Dormand-Prince 5(4) (hand-written: a 1-DOF ODE
// to 1e-12 needs nothing more; no ODE library is packaged for C++ here). Nothing of mbdae's
// formulation (absolute coordinates, Euler parameters, constraints) is used.
#pragma once

#include <string>
#include <vector>

namespace mbdae {

struct SliderCrankParameters {
  double r = 0.01, l = 0.03;           // crank radius, rod length [m]
  double a = 0.002, b = 0.01;          // crank and rod centres of mass from pivot and pin [m]
  double m_crank = 0.005, j_crank = 2e-7;  // mass [kg], inertia about its centre of mass [kg m^2]
  double m_rod = 0.004, j_rod = 4e-7;
  double m_piston = 0.006;
  double torque = 0.04;                // [N m]
  double theta0 = 0.3;                 // crank angle at rest at t = 0 [rad]
};

// Sensors of slider_crank_fast.yaml at one time, from (theta, theta').
struct SliderCrankSample {
  double t, theta, rate;
  double piston_x, piston_vx, pin_x, pin_y, pin_vx, pin_vy;
  double value(const std::string& sensor) const;  // by the scene's sensor name; throws if unknown
};

// Samples at `times` (increasing, from 0), integrated with relative and absolute tolerance tol.
std::vector<SliderCrankSample> slider_crank_reference(const SliderCrankParameters& p,
                                                      const std::vector<double>& times,
                                                      double tol = 1e-13);

}  // namespace mbdae
