// Independent reference computation of the five-point suspension's geometry and statics.
//
// Model: /work/shared/spec/five-point-suspension.md (the authoritative page; read it first).
//
// This file deliberately does NOT use the engine's formulation (absolute Cartesian coordinates
// plus Euler parameters for every body). It is a minimal-coordinate "carrier pose" formulation:
//
//   * The chassis only translates vertically (joint T3, q1 = chassis_z). Its axes stay parallel
//     to the base axes, so "chassis frame" and "world" differ by the offset (0, 0, chassis_z).
//   * The carrier is described by x = (p, R): p the position of its origin in the chassis frame
//     (= rod 5's end point, where the R1 R2 R3 joint sits) and R its rotation matrix (carrier
//     axes in chassis/world axes). Newton updates R by a world-frame incremental rotation:
//     R <- exp([dtheta]x) R.
//   * Every rod is a two-force member between a chassis point bp_k and a carrier point. Its
//     R1(a) R3(b) joint makes its y axis point along d_k = (end point) - bp_k:
//         d_k / L_k = Rx(a) Rz(b) e_y = (-sin b, cos a cos b, sin a cos b),
//     so the rods do not need coordinates of their own: they are recovered from (p, R).
//   * Six scalar equations fix the six pose unknowns for a given rod-2 angle q4:
//         |p - bp5|             - L5 = 0                 (rod 5 holds the carrier origin)
//         |R cp_k + p - bp_k|   - L_k = 0,  k = 1..4     (ball cuts 1..4)
//         atan2(d2_z, d2_y)     - q4  = 0                (rod 2's R1 angle is q4)
//
// Derivatives with respect to q4 come from the implicit function theorem (first and second
// order), so point velocities/accelerations along q4 are exact, and the statics is a virtual
// work balance along the single degree of freedom.
//
// All functions are free functions on plain structs; indices in arrays are 0-based
// (chassis_points[k - 1] holds bp_k, and so on); angles are in radians unless named *_deg.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Dense>

namespace mbdae::reference {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// ---------------------------------------------------------------------------------------------
// Data
// ---------------------------------------------------------------------------------------------

// Every number of the spec page, in SI units, vectors in their own body's frame.
struct SuspensionData {
  double gravity = 9.81;                      // |g|, g = (0, 0, -gravity)
  double chassis_mass = 409.91;
  std::array<Vector3, 6> chassis_points;      // bp1..bp6 (bp5 x = +0.2115, see the Errata)
  std::array<double, 5> rod_masses{};         // m_1..m_5 (point masses)
  std::array<double, 5> rod_lengths{};        // L_1..L_5: end point (0, L_k, 0) on rod k
  std::array<double, 5> rod_com_offsets{};    // c_1..c_5: centre of mass (0, c_k, 0) on rod k
  std::array<Vector3, 5> carrier_points;      // cp1..cp5 (cp5 = wheel centre)
  double carrier_mass = 15.0;
  Vector3 carrier_com;                        // (-0.1055, -0.2713, 0.2243)
  Matrix3 carrier_inertia;                    // about the COM, carrier axes (tensor elements)
  double wheel_mass = 12.0;
  Matrix3 wheel_inertia;                      // diag(0.74, 1.46, 0.74)
  double spring_stiffness = 1.4e5;            // K  [N/m]
  double spring_damping = 1400.0;             // D  [N s/m] (unused by the statics here)
  double tyre_stiffness = 2.0e5;              // K_t [N/m]
  double tyre_radius = 0.30;                  // r  [m]
  double q4_design = 0.207743260032;          // q4_0 [rad]
  double chassis_z_design = 0.278;            // q1 of the kinematic / equilibrium analyses [m]
  // The spec's initial guess for q2..q14 in degrees (entry i - 2 holds q_i; the q4 entry is
  // q4_design in degrees).
  std::array<double, 13> initial_guess_deg{};
};

// The spec's data (bp5 x = +0.2115).
SuspensionData spec_data();

// Sum of all masses: chassis + rods + carrier + wheel (448.91 kg).
double total_mass(const SuspensionData& data);

// ---------------------------------------------------------------------------------------------
// Small rotation helpers
// ---------------------------------------------------------------------------------------------

Matrix3 rotation_x(double angle);
Matrix3 rotation_y(double angle);
Matrix3 rotation_z(double angle);
// exp([w]x): rotation by |w| about w/|w| (Rodrigues).
Matrix3 rotation_from_vector(const Vector3& w);

// ---------------------------------------------------------------------------------------------
// Carrier pose and its solution
// ---------------------------------------------------------------------------------------------

// Configuration of the closed-loop suspension for a given chassis height.
struct CarrierPose {
  Vector3 origin = Vector3::Zero();           // p: carrier origin in the chassis frame
  Matrix3 rotation = Matrix3::Identity();     // R: carrier axes in chassis (= world) axes
  double chassis_z = 0.0;                     // q1: chassis frame origin is (0, 0, chassis_z)
};

// Diagnostics of a Newton solve.
struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  double residual_norm = 0.0;                 // infinity norm of the final residual
  double min_singular_value = 0.0;            // of the 6x6 pose Jacobian at the end
  double condition_number = 0.0;              // sigma_max / sigma_min at the end
};

// F(x; q4): the six pose equations listed at the top (units: m for 0..4, rad for 5).
// Order: 0 = rod 5, 1..4 = ball cuts 1..4, 5 = rod-2 angle.
Vector6 pose_residual(const SuspensionData& data, const CarrierPose& pose, double q4);

// dF/dx for x perturbed as p <- p + dp, R <- exp([dtheta]x) R, columns (dp, dtheta).
Matrix6 pose_jacobian(const SuspensionData& data, const CarrierPose& pose);

// Carrier pose from the spec's guessed joint angles: rod 5 = R1(q10) R3(q11) from bp5, carrier
// = R1(q12) R2(q13) R3(q14) at rod 5's end point.
CarrierPose spec_guess_pose(const SuspensionData& data, double chassis_z);

// Newton on F(x; q4) = 0 from `guess` (its chassis_z is replaced by `chassis_z`). Converged when
// |F|_inf <= tolerance. If `report` is null a failure throws std::runtime_error; otherwise the
// report is filled and the last iterate is returned.
CarrierPose solve_pose(const SuspensionData& data, double q4, double chassis_z,
                       const CarrierPose& guess, NewtonReport* report = nullptr,
                       double tolerance = 1e-14, int max_iterations = 30);

// The converged design configuration: q4 = q4_design, chassis_z = chassis_z_design, from the
// spec's guess.
CarrierPose design_pose(const SuspensionData& data);

// Continuation in q4: walks from (start, start_q4) to target_q4 in steps of at most max_step
// with a second-order predictor (from the implicit derivatives) and a Newton corrector, halving
// the step on failure. Same error convention as solve_pose.
CarrierPose continue_pose(const SuspensionData& data, const CarrierPose& start, double start_q4,
                          double target_q4, NewtonReport* report = nullptr,
                          double max_step = 0.02);

// ---------------------------------------------------------------------------------------------
// Implicit derivatives along q4 (chassis fixed)
// ---------------------------------------------------------------------------------------------

// First and second derivatives of the pose with respect to q4:
//   p' = dp/dq4, omega with dR/dq4 = [omega]x R, and their derivatives p'', omega'.
// From F(x(q4), q4) = 0:  J (p', omega) = -dF/dq4 = (0, 0, 0, 0, 0, 1), and, differentiating the
// scalar equations once more, J (p'', omega') = gamma (the "acceleration" right-hand side).
struct PoseSensitivity {
  Vector3 dorigin = Vector3::Zero();
  Vector3 omega = Vector3::Zero();
  Vector3 ddorigin = Vector3::Zero();
  Vector3 domega = Vector3::Zero();
};

PoseSensitivity pose_sensitivity(const SuspensionData& data, const CarrierPose& pose);

// A world point with its first and second derivatives along q4.
struct PointMotion {
  Vector3 position = Vector3::Zero();
  Vector3 first = Vector3::Zero();
  Vector3 second = Vector3::Zero();
};

// A point fixed on the carrier, given in carrier coordinates.
PointMotion carrier_point_motion(const CarrierPose& pose, const PoseSensitivity& sensitivity,
                                 const Vector3& point_in_carrier);

// The point (0, s, 0) of rod k (k = 1..5), i.e. bp_k + s d_k / L_k.
PointMotion rod_point_motion(const SuspensionData& data, const CarrierPose& pose,
                             const PoseSensitivity& sensitivity, int k, double s);

// ---------------------------------------------------------------------------------------------
// Outputs
// ---------------------------------------------------------------------------------------------

struct WheelOutputs {
  Vector3 centre = Vector3::Zero();           // cp5 in the world
  Vector3 spin_axis = Vector3::Zero();        // y_w = R e_y (the wheel's R2 does not change it)
  double camber = 0.0;                        // asin(y_w . e_z)
  double toe = 0.0;                           // atan2(y_w . e_x, y_w . e_y)
  // Derivatives along q4 (chassis fixed).
  Vector3 dcentre = Vector3::Zero();
  Vector3 ddcentre = Vector3::Zero();
  double dcamber = 0.0;
  double dtoe = 0.0;
};

WheelOutputs wheel_outputs(const SuspensionData& data, const CarrierPose& pose,
                           const PoseSensitivity& sensitivity);
WheelOutputs wheel_outputs(const SuspensionData& data, const CarrierPose& pose);

// Robotran joint coordinates q1..q14 of the pose; q[i - 1] holds q_i. q1 = chassis_z, rod k has
// (q(2k), q(2k+1)) = (a, b) from its direction, and (q12, q13, q14) are the R1 R2 R3 angles of
// the carrier relative to rod 5's frame Rx(q10) Rz(q11). q15 (wheel spin) is ignorable.
std::array<double, 14> joint_coordinates(const SuspensionData& data, const CarrierPose& pose);

// Direction of rod k (unit, chassis axes) and the rod's (R1, R3) angles from a unit direction u:
//   a = atan2(u_z, u_y),  b = atan2(-u_x, sqrt(u_y^2 + u_z^2))   (cos b > 0 branch).
Vector3 rod_direction(const SuspensionData& data, const CarrierPose& pose, int k);
std::array<double, 2> rod_angles_from_direction(const Vector3& unit_direction);

// ---------------------------------------------------------------------------------------------
// Statics (all at rest)
// ---------------------------------------------------------------------------------------------

// Spring length Z = |P - bp6|, P = rod 5's COM point (0, c5, 0), and its q4 derivatives.
struct SpringGeometry {
  double length = 0.0;
  double first = 0.0;
  double second = 0.0;
};
SpringGeometry spring_geometry(const SuspensionData& data, const CarrierPose& pose,
                               const PoseSensitivity& sensitivity);

// Tyre compression e = r cos(camber) - (z_w - ground_z) and the vertical force max(0, K_t e).
double tyre_compression(const SuspensionData& data, const WheelOutputs& wheel, double ground_z);
double tyre_force(const SuspensionData& data, const WheelOutputs& wheel, double ground_z);

// Generalized force along q4 with the chassis held: Q = sum F_i . dr_i/dq4 (virtual work),
// split by origin. Q = 0 is the static equilibrium along the suspension's degree of freedom.
struct GeneralizedForce {
  double gravity = 0.0;   // rods (point masses at (0, c_k, 0)), carrier COM, wheel at cp5
  double spring = 0.0;    // -K (Z - Z0) dZ/dq4
  double tyre = 0.0;      // max(0, K_t e) dz_w/dq4 (vertical force at the wheel centre)
  double total = 0.0;
};
GeneralizedForce generalized_force_q4(const SuspensionData& data, const CarrierPose& pose,
                                      double spring_free_length, double ground_z = 0.0);

// Z0 making Q(q4) = 0 with the chassis at chassis_z_design and the ground at 0:
//   Z0 = Z - (Q_gravity + Q_tyre) / (K dZ/dq4).
double spring_free_length(const SuspensionData& data, const CarrierPose& pose);
double spring_free_length(const SuspensionData& data, double q4);

// Potential energies of the pose (world heights; ground at ground_z).
//   gravity = sum m_i g z_i (all bodies including the chassis),
//   spring  = K (Z - Z0)^2 / 2,
//   tyre    = K_t e^2 / 2 for e > 0, else 0.
// gravity and spring are exact potentials: dV/dq4 = -Q. The spec's tyre force acts vertically
// with magnitude K_t e, e = r cos(camber) - z_w: it is not conservative when the camber varies,
// and  -dV_tyre/dq4 = Q_tyre + K_t e r sin(camber) dcamber/dq4  (see tyre_camber_work_q4).
struct PotentialEnergy {
  double gravity = 0.0;
  double spring = 0.0;
  double tyre = 0.0;
  double total = 0.0;
};
PotentialEnergy potential_energy(const SuspensionData& data, const CarrierPose& pose,
                                 double spring_free_length, double ground_z = 0.0);

// K_t e r sin(camber) dcamber/dq4 (0 without contact): the part of -dV_tyre/dq4 that the
// spec's tyre force does not produce.
double tyre_camber_work_q4(const SuspensionData& data, const CarrierPose& pose,
                           double ground_z = 0.0);

// Chassis-free static equilibrium (Dynamics II initial state), ground at 0, Z0 given.
// Unknowns (q1, q4); equations
//   G1 = F_tyre(q1, q4) - M g = 0                 (generalized force along q1: vertical balance)
//   G2 = Q_gravity + F_tyre dz_w/dq4 - K (Z - Z0) dZ/dq4 = 0     (along q4, chassis held)
// Newton with the exact 2x2 Jacobian (second-order implicit derivatives, no finite differences).
struct VehicleEquilibrium {
  double q1 = 0.0;
  double q4 = 0.0;
};

struct VehicleEquilibriumReport {
  bool converged = false;
  int iterations = 0;
  double vertical_residual = 0.0;   // |G1| [N]
  double q4_residual = 0.0;         // |G2| [N m]
  double tyre_force = 0.0;          // at the solution [N]
  CarrierPose pose;                 // at the solution
};

// Starts from `guess` (default: the design point q1 = 0.278, q4 = q4_0).
VehicleEquilibrium solve_vehicle_equilibrium(const SuspensionData& data,
                                             double spring_free_length,
                                             VehicleEquilibriumReport* report = nullptr);
VehicleEquilibrium solve_vehicle_equilibrium(const SuspensionData& data,
                                             double spring_free_length,
                                             const VehicleEquilibrium& guess,
                                             VehicleEquilibriumReport* report = nullptr);

}  // namespace mbdae::reference
