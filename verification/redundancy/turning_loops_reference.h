// Independent references for the planar loops in a turning plane (verification/redundancy,
// issue 23): one-degree-of-freedom Lagrange equations in the frame of a body spun at a constant
// rate Omega about the world z axis, the loop moving in that frame's x-z plane.
//
// In that frame a body with centre of mass p = (x, z) and angle phi about y (body x along
// (cos phi, -sin phi)) has T = 1/2 m (x'^2 + z'^2 + Omega^2 x^2) + 1/2 Iyy phi'^2
// + 1/2 Omega^2 (Ixx sin^2 phi + Izz cos^2 phi) (principal body axes; the Coriolis terms are normal
// to the plane and are carried by the constraints). With p(theta), phi(theta) along the loop:
//   M theta'' + C theta'^2 = Q,  M = sum m |p_t|^2 + Iyy phi_t^2,  C = sum m p_t.p_tt + Iyy phi_t phi_tt,
//   Q = sum [-m g z_t + m Omega^2 x x_t + Omega^2 (Ixx - Izz) sin phi cos phi phi_t] + spring.
// Integrated by classical Runge-Kutta 4 with a fixed step (converged in the test by halving it).
#pragma once

#include <vector>

namespace mbdae {

// A state along the reference: the loop's coordinate and a tracked point (world coordinates).
struct LoopSample {
  double t = 0, theta = 0, rate = 0;
  double point[3] = {0, 0, 0}, velocity[3] = {0, 0, 0};
};

// verification/redundancy/turntable_four_bar.yaml: theta = crank angle (relative to the table),
// point = the coupler's end (the rocker's end).
std::vector<LoopSample> turntable_four_bar_reference(double theta0, double rate0, const std::vector<double>& times,
                                                     double step);
// verification/redundancy/governor_pinned_links.yaml: theta = arm A's angle below the horizontal,
// point = arm A's ball.
std::vector<LoopSample> governor_reference(double theta0, double rate0, const std::vector<double>& times,
                                           double step);

}  // namespace mbdae
