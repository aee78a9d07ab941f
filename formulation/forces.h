// Applied forces as generalized forces on absolute coordinates, with exact Jacobians.
//
// A world force f applied at body point s (local) contributes Q_r = f, Q_p = B(p, s)^T f.
// A torque n (world axes) on a body contributes Q_p = 2 E(p)^T n, E(p) = [-e, [e]x + e0 I]; a
// torque n' in body axes Q_p = 2 L(p)^T n' (the virtual rotation is 2 E dp in world axes, 2 L dp
// in body axes). Both are linear in p: Q_p = 2 T M(a) p with the constant 4 x 4 matrices
//   M_world(a) = [0 -a^T; a [a]x],   M_body(a) = [0 -a^T; a -[a]x]   (a the unit axis).
// Each force type is a row of the force-type table (formulation/force_types.h) and its law is
// one file in formulation/forces/ (spring_damper, point_force, torque, joint_spring_damper,
// bushing, wheel_contact, user_law, ...), whose header comment states the law and its Jacobians.
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
// The law named `name` from the immutable table in formulation/forces/user_law.cpp (safe from any
// thread), or null.
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

// Derivative of the element's generalized force with respect to one of its solvable parameters
// (ForceParameter::solvable: "free_length", "stiffness", "damping", "radius"), local 14-vector.
Vec14 force_parameter_derivative(const Force& f, const LocalState& pos, const LocalState& vel,
                                 double t, bool in_contact, const std::string& parameter);
// A parameter of the load's expressions, or of its type's row (ForceParameter); nullptr if unknown.
double* force_parameter(Force& f, const std::string& parameter);

// Switching function (a wheel contact's penetration e); elements without one return 0.
bool force_has_switch(const Force& f);
double force_switch_value(const Force& f, const LocalState& pos, double t);

// Length and tension (or normal force) of an element at time t, for sensors (a wheel contact's
// length is its penetration, which depends on the ground height at t).
double force_length(const Force& f, const LocalState& pos, double t);
double force_magnitude(const Force& f, const LocalState& pos, const LocalState& vel, double t,
                       bool in_contact, const LoadInput* input = nullptr);
// Potential energy stored in a conservative element (spring-damper, joint spring-damper,
// bushing, wheel contact in contact); 0 for the others (their rows have no potential).
double force_potential(const Force& f, const LocalState& pos, double t, bool in_contact,
                       const LoadInput* input = nullptr);

}  // namespace mbdae
