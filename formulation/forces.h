// Applied forces as generalized forces on absolute coordinates, with exact Jacobians.
//
// A world force f applied at body point s (local) contributes Q_r = f, Q_p = B(p, s)^T f.
// Element laws:
//   spring-damper: tension T = k (Z - Z0) + c dZ/dt between two points, Z their distance;
//   point force:   f(t) given in world components;
//   wheel contact: vertical f_z = K_t e when in contact, e = r cos(camber) - (z - z_g(t)), camber
//                  from the wheel's spin axis u: cos(camber) = sqrt(1 - u_z^2). Whether the wheel
//                  is in contact is a mode switched by events (root of e), not a max() inside the
//                  Newton iteration;
//   user law:      a registered function f(d, d_dot, t, parameters) of the relative position and
//                  velocity of two points (force on point 1, reaction on point 2).
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

// Generalized force of element f on its (up to two) bodies, local 14-vector; optional exact
// Jacobians with respect to the local positions and velocities. `in_contact` is the mode of a
// wheel-contact element.
void force_eval(const Force& f, const LocalState& pos, const LocalState& vel, double t,
                bool in_contact, Vec14& q_local, Mat14* dq_dpos, Mat14* dq_dvel);

// Derivative of the element's generalized force with respect to one of its parameters
// ("free_length", "stiffness", "damping"), local 14-vector.
Vec14 force_parameter_derivative(const Force& f, const LocalState& pos, const LocalState& vel,
                                 double t, bool in_contact, const std::string& parameter);
double* force_parameter(Force& f, const std::string& parameter);  // nullptr if unknown

// Switching function of a wheel contact (its penetration e); elements without one return 0.
bool force_has_switch(const Force& f);
double force_switch_value(const Force& f, const LocalState& pos, double t);

// Length and tension (or normal force) of an element, for sensors.
double force_length(const Force& f, const LocalState& pos);
double force_magnitude(const Force& f, const LocalState& pos, const LocalState& vel, double t,
                       bool in_contact);

}  // namespace mbdae
