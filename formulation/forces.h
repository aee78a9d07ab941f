// Applied forces as generalized forces on absolute coordinates, with exact Jacobians.
//
// A world force f applied at body point s (local) contributes Q_r = f, Q_p = B(p, s)^T f.
// A torque n (world axes) on a body contributes Q_p = 2 E(p)^T n, E(p) = [-e, [e]x + e0 I]; a
// torque n' in body axes Q_p = 2 L(p)^T n' (the virtual rotation is 2 E dp in world axes, 2 L dp
// in body axes). Both are linear in p: Q_p = 2 T M(a) p with the constant 4 x 4 matrices
//   M_world(a) = [0 -a^T; a [a]x],   M_body(a) = [0 -a^T; a -[a]x]   (a the unit axis).
// Element laws:
//   spring-damper: tension T = k (Z - Z0) + c dZ/dt between two points, Z their distance;
//   point force:   f(t) given in world components, or in body axes (a follower force:
//                  f = A(p) F, so dQ_r/dp = B(p, F), dQ_p/dp = K(s, f) + B(p, s)^T B(p, F));
//   torque:        magnitude T(t) about a world or body-fixed axis (above);
//   joint spring-damper: tau = k (q - q0) + c q' on a joint coordinate q(x) with gradient G and
//                  Hessian H (coordinate_jet): Q = -tau G^T, dQ/dx = -G^T (k G + c (H v)^T) - tau H,
//                  dQ/dv = -c G^T G; a rotation q counts whole turns (LoadInput::turns, from
//                  CoordinateTurns: a spring wound 10 rad gives -10 k), or with `wrap` q - q0 is
//                  wrapped to (-pi, pi] (a spring acting within half a turn of its rest angle);
//   bushing:       six coordinates y = (d, theta) of frame 2 relative to frame 1, d = C1^T A1^T
//                  (P2 - P1) and theta = 2 sign(w0) w_vec, w = conj(p1 c1) (p2 c2) the relative
//                  Euler parameters (c_k the frame's axes in its body): theta is the rotation
//                  vector to first order (2 sin(phi/2) u exactly). Q = -J^T (K y + C J v), J =
//                  dy/dx; dQ/dv = -J^T C J exactly, dQ/dx by central differences of Q (step
//                  1e-6 max(1, |x_k|), truncation and rounding both below 1e-9 relative);
//   wheel contact: vertical f_z = K_t e when in contact, e = r cos(camber) - (z - z_g(t)), camber
//                  from the wheel's spin axis u: cos(camber) = sqrt(1 - u_z^2). Whether the wheel
//                  is in contact is a mode switched by events (root of e), not a max() inside the
//                  Newton iteration;
//   user law:      a registered function f(d, d_dot, t, parameters) of the relative position and
//                  velocity of two points (force on point 1, reaction on point 2).
// Components given by expressions of sensors (point force, torque) come in a LoadInput computed
// from the whole state (load_input, formulation/sensors.h) with their gradients; force_eval then
// returns dQ/d(component) and the caller applies the chain rule (mechanics.cpp).
// Gravity is applied to every body by the DAE itself.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "formulation/constraints.h"
#include "formulation/system.h"

namespace mbdae {

// Extension point for force laws. `force` must return the world force on point 1 (the reaction
// -f acts on point 2). The Jacobians with respect to d and d_dot may be supplied; if not, they
// are computed by central differences.
struct UserForceLaw {
  std::string name;
  std::vector<std::string> parameter_names;
  std::function<Vec3(const Vec3& d, const Vec3& d_dot, double t, const double* params)> force;
  std::function<void(const Vec3& d, const Vec3& d_dot, double t, const double* params,
                     Mat3& df_dd, Mat3& df_dddot)>
      jacobian;  // optional
};
// The law named `name` from the immutable table in forces.cpp (safe from any thread), or null.
const UserForceLaw* find_force_law(const std::string& name);


// Values of a load's expression components (index 0..2) and their derivatives with respect to
// the positions and velocities of the bodies in Force::reads (7 columns per body, in order).
struct LoadInput {
  double value[3] = {0, 0, 0};
  double turns = 0;  // joint spring-damper: 2 pi times the whole turns added to its measured coordinate
  double dq[3][7 * kMaxLoadReads], dv[3][7 * kMaxLoadReads];
};
using Mat14x3 = Eigen::Matrix<double, 14, 3>;

// Generalized force of element f on its (up to two) bodies, local 14-vector; optional exact
// Jacobians with respect to the local positions and velocities. `in_contact` is the mode of a
// wheel-contact element. For a load with expression components, `input` carries their values
// and dq_dinput (if given) receives dQ/d(component) (zero columns for other components).
void force_eval(const Force& f, const LocalState& pos, const LocalState& vel, double t,
                bool in_contact, Vec14& q_local, Mat14* dq_dpos, Mat14* dq_dvel,
                const LoadInput* input = nullptr, Mat14x3* dq_dinput = nullptr);

// Derivative of the element's generalized force with respect to one of its parameters
// ("free_length", "stiffness", "damping"), local 14-vector.
Vec14 force_parameter_derivative(const Force& f, const LocalState& pos, const LocalState& vel,
                                 double t, bool in_contact, const std::string& parameter);
double* force_parameter(Force& f, const std::string& parameter);  // nullptr if unknown

// Switching function of a wheel contact (its penetration e); elements without one return 0.
bool force_has_switch(const Force& f);
double force_switch_value(const Force& f, const LocalState& pos, double t);

// Length and tension (or normal force) of an element at time t, for sensors (a wheel contact's
// length is its penetration, which depends on the ground height at t).
double force_length(const Force& f, const LocalState& pos, double t);
double force_magnitude(const Force& f, const LocalState& pos, const LocalState& vel, double t,
                       bool in_contact, const LoadInput* input = nullptr);
// Potential energy stored in a conservative element (spring-damper, joint spring-damper,
// bushing, wheel contact in contact); 0 for the others.
double force_potential(const Force& f, const LocalState& pos, double t, bool in_contact,
                       const LoadInput* input = nullptr);

}  // namespace mbdae
