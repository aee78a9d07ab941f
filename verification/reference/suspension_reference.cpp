// Independent reference computation of the five-point suspension: see suspension_reference.h
// for the formulation. Notation used in the comments:
//   p, R      carrier origin (chassis frame) and rotation,
//   r_k       = R cp_k (carrier point k relative to the carrier origin, chassis axes),
//   d_k       = r_k + p - bp_k (rod k's vector from its chassis anchor to its end), d_5 = p - bp5,
//   u_k       = d_k / |d_k|,
//   ' and ''  first and second derivatives along q4 with the chassis held,
//   omega     dR/dq4 = [omega]x R  (so r_k' = omega x r_k).
#include "verification/reference/suspension_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mbdae::reference {

namespace {

constexpr double kPi = 3.14159265358979323846;

double degrees_to_radians(double degrees) { return degrees * kPi / 180.0; }

// Wraps an angle to (-pi, pi].
double wrap_angle(double angle) {
  return std::atan2(std::sin(angle), std::cos(angle));
}

const Vector3& chassis_point(const SuspensionData& data, int k) {
  return data.chassis_points.at(k - 1);
}

// Restores orthonormality of R (quaternion round trip) after many incremental updates.
Matrix3 orthonormalized(const Matrix3& rotation) {
  Eigen::Quaterniond quaternion(rotation);
  quaternion.normalize();
  return quaternion.toRotationMatrix();
}

// Everything about one rod's vector d_k that the equations need.
struct RodVector {
  Vector3 lever = Vector3::Zero();   // r_k = R cp_k (zero for rod 5: it ends at the origin)
  Vector3 vector = Vector3::Zero();  // d_k
};

RodVector rod_vector(const SuspensionData& data, const CarrierPose& pose, int k) {
  RodVector rod;
  if (k != 5) rod.lever = pose.rotation * data.carrier_points.at(k - 1);
  rod.vector = rod.lever + pose.origin - chassis_point(data, k);
  return rod;
}

// Jacobian row of a scalar g(d) with gradient `gradient` = dg/dd, d = r + p - bp:
//   delta d = delta p + delta theta x r
//   =>  delta g = gradient . delta p + (r x gradient) . delta theta.
Eigen::Matrix<double, 1, 6> row_for_vector(const Vector3& gradient, const Vector3& lever) {
  Eigen::Matrix<double, 1, 6> row;
  row.head<3>() = gradient.transpose();
  row.tail<3>() = lever.cross(gradient).transpose();
  return row;
}

// Gradient of atan2(d_z, d_y) with respect to d: (0, -d_z, d_y) / (d_y^2 + d_z^2).
Vector3 angle_gradient(const Vector3& d) {
  const double rho_squared = d.y() * d.y() + d.z() * d.z();
  return Vector3(0.0, -d.z(), d.y()) / rho_squared;
}

void apply_increment(const Vector6& increment, CarrierPose* pose) {
  pose->origin += increment.head<3>();
  pose->rotation = orthonormalized(rotation_from_vector(increment.tail<3>()) * pose->rotation);
}

void fill_singular_values(const Matrix6& jacobian, NewtonReport* report) {
  Eigen::JacobiSVD<Matrix6> svd(jacobian);
  const auto& sigma = svd.singularValues();
  report->min_singular_value = sigma(5);
  report->condition_number =
      sigma(5) > 0 ? sigma(0) / sigma(5) : std::numeric_limits<double>::infinity();
}

// Sums over the moving masses (rods, carrier, wheel; the chassis is held) of m_i z_i' and
// m_i z_i''. Gravity's generalized force along q4 is -g times the first sum.
std::array<double, 2> weighted_height_derivatives(const SuspensionData& data,
                                                  const CarrierPose& pose,
                                                  const PoseSensitivity& sensitivity) {
  double first = 0.0;
  double second = 0.0;
  for (int k = 1; k <= 5; ++k) {
    const PointMotion com =
        rod_point_motion(data, pose, sensitivity, k, data.rod_com_offsets[k - 1]);
    first += data.rod_masses[k - 1] * com.first.z();
    second += data.rod_masses[k - 1] * com.second.z();
  }
  const PointMotion carrier = carrier_point_motion(pose, sensitivity, data.carrier_com);
  first += data.carrier_mass * carrier.first.z();
  second += data.carrier_mass * carrier.second.z();
  const PointMotion wheel = carrier_point_motion(pose, sensitivity, data.carrier_points[4]);
  first += data.wheel_mass * wheel.first.z();
  second += data.wheel_mass * wheel.second.z();
  return {first, second};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Data
// ---------------------------------------------------------------------------------------------

SuspensionData spec_data() {
  SuspensionData data;
  data.gravity = 9.81;
  data.chassis_mass = 409.91;
  data.chassis_points = {Vector3(-0.064, 0.413, 0.327), Vector3(-0.303, 0.432, 0.295),
                         Vector3(-0.093, 0.366, 0.004), Vector3(-0.236, 0.388, -0.109),
                         Vector3(+0.2115, 0.3845, -0.100),  // Errata: +0.2115, not -0.2115
                         Vector3(0.090, 0.525, 0.170)};
  data.rod_masses = {2.0, 2.0, 4.0, 1.0, 3.0};
  data.rod_lengths = {0.2237, 0.2794, 0.2979, 0.4191, 0.4116};
  data.rod_com_offsets = {0.1118626389819228, 0.1396969935252724, 0.1489253168537841,
                          0.2095250581672751, 0.2056047482428361};
  data.carrier_points = {Vector3(-0.0665, -0.0962051898607574, 0.4799860012998876),
                         Vector3(-0.1195, -0.0962751863610199, 0.4729863512736397),
                         Vector3(-0.1905, -0.0888855558333097, 0.11189440541959),
                         Vector3(-0.0075, 3.999800015e-5, 3.9998000149988e-3),
                         Vector3(-0.0025, 0.0323383831212649, 0.1336833160012957)};
  data.carrier_mass = 15.0;
  data.carrier_com = Vector3(-0.1055, -0.2713, 0.2243);
  const double ixx = 0.3, iyy = 0.20122, izz = 0.198780669;
  const double ixy = 0.0101821697, iyz = 0.0499851301, ixz = 0.0148769426;
  data.carrier_inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  data.wheel_mass = 12.0;
  data.wheel_inertia = Vector3(0.74, 1.46, 0.74).asDiagonal();
  data.spring_stiffness = 1.4e5;
  data.spring_damping = 1400.0;
  data.tyre_stiffness = 2.0e5;
  data.tyre_radius = 0.30;
  data.q4_design = 0.207743260032;
  data.chassis_z_design = 0.278;
  data.initial_guess_deg = {4.613882548811577,
                            4.02889045738623e-05,
                            data.q4_design * 180.0 / kPi,
                            -41.73804367345049,
                            -5.489179473987941,
                            18.599571106148783,
                            3.444025498268294,  // q8: wrong sign in the source (see spec)
                            -33.452591013228314,
                            -5.509358437021373,
                            30.547781981310944,
                            5.347518201452412,
                            -3.143760886564701,
                            -30.365880376422055};
  return data;
}

double total_mass(const SuspensionData& data) {
  double mass = data.chassis_mass + data.carrier_mass + data.wheel_mass;
  for (double rod_mass : data.rod_masses) mass += rod_mass;
  return mass;
}

// ---------------------------------------------------------------------------------------------
// Rotations
// ---------------------------------------------------------------------------------------------

Matrix3 rotation_x(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Matrix3 m;
  m << 1, 0, 0, 0, c, -s, 0, s, c;
  return m;
}

Matrix3 rotation_y(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Matrix3 m;
  m << c, 0, s, 0, 1, 0, -s, 0, c;
  return m;
}

Matrix3 rotation_z(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Matrix3 m;
  m << c, -s, 0, s, c, 0, 0, 0, 1;
  return m;
}

Matrix3 rotation_from_vector(const Vector3& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Matrix3::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// ---------------------------------------------------------------------------------------------
// Pose equations
// ---------------------------------------------------------------------------------------------

Vector6 pose_residual(const SuspensionData& data, const CarrierPose& pose, double q4) {
  Vector6 residual;
  // Row 0: rod 5 reaches the carrier origin, |p - bp5| = L5.
  residual(0) = rod_vector(data, pose, 5).vector.norm() - data.rod_lengths[4];
  // Rows 1..4: ball cuts, |R cp_k + p - bp_k| = L_k.
  for (int k = 1; k <= 4; ++k) {
    residual(k) = rod_vector(data, pose, k).vector.norm() - data.rod_lengths[k - 1];
  }
  // Row 5: rod 2's R1 angle. With d_2 / L_2 = (-sin q5, cos q4 cos q5, sin q4 cos q5) and
  // cos q5 > 0, q4 = atan2(d_2z, d_2y).
  const Vector3 d2 = rod_vector(data, pose, 2).vector;
  residual(5) = wrap_angle(std::atan2(d2.z(), d2.y()) - q4);
  return residual;
}

Matrix6 pose_jacobian(const SuspensionData& data, const CarrierPose& pose) {
  Matrix6 jacobian;
  // d|d|/dd = u = d/|d|; rod 5 has no lever (its end is the carrier origin itself).
  for (int k = 1; k <= 5; ++k) {
    const RodVector rod = rod_vector(data, pose, k);
    const int row = (k == 5) ? 0 : k;
    jacobian.row(row) = row_for_vector(rod.vector.normalized(), rod.lever);
  }
  const RodVector rod2 = rod_vector(data, pose, 2);
  jacobian.row(5) = row_for_vector(angle_gradient(rod2.vector), rod2.lever);
  return jacobian;
}

CarrierPose spec_guess_pose(const SuspensionData& data, double chassis_z) {
  // Entry i - 2 of the guess holds q_i.
  auto guess = [&data](int i) { return degrees_to_radians(data.initial_guess_deg.at(i - 2)); };
  const Matrix3 rod5_rotation = rotation_x(guess(10)) * rotation_z(guess(11));
  CarrierPose pose;
  pose.origin = chassis_point(data, 5) + rod5_rotation * Vector3(0.0, data.rod_lengths[4], 0.0);
  pose.rotation = rod5_rotation * rotation_x(guess(12)) * rotation_y(guess(13)) *
                  rotation_z(guess(14));
  pose.chassis_z = chassis_z;
  return pose;
}

CarrierPose solve_pose(const SuspensionData& data, double q4, double chassis_z,
                       const CarrierPose& guess, NewtonReport* report, double tolerance,
                       int max_iterations) {
  CarrierPose pose = guess;
  pose.chassis_z = chassis_z;
  NewtonReport local;
  Vector6 residual = pose_residual(data, pose, q4);
  for (;;) {
    local.residual_norm = residual.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(local.residual_norm)) break;
    if (local.residual_norm <= tolerance) {
      local.converged = true;
      break;
    }
    if (local.iterations >= max_iterations) break;
    // Newton: J dx = -F, then p += dp, R = exp([dtheta]x) R.
    const Vector6 increment = pose_jacobian(data, pose).fullPivLu().solve(-residual);
    if (!increment.allFinite()) break;
    apply_increment(increment, &pose);
    ++local.iterations;
    residual = pose_residual(data, pose, q4);
  }
  fill_singular_values(pose_jacobian(data, pose), &local);
  if (report != nullptr) {
    *report = local;
  } else if (!local.converged) {
    std::ostringstream message;
    message << "mbdae::reference::solve_pose: no convergence at q4 = " << q4 << " after "
            << local.iterations << " iterations, |F| = " << local.residual_norm
            << ", sigma_min(J) = " << local.min_singular_value;
    throw std::runtime_error(message.str());
  }
  return pose;
}

CarrierPose design_pose(const SuspensionData& data) {
  return solve_pose(data, data.q4_design, data.chassis_z_design,
                    spec_guess_pose(data, data.chassis_z_design));
}

CarrierPose continue_pose(const SuspensionData& data, const CarrierPose& start, double start_q4,
                          double target_q4, NewtonReport* report, double max_step) {
  CarrierPose pose = start;
  double q4 = start_q4;
  double step_limit = max_step;
  const double min_step = 1e-9;
  NewtonReport total;
  total.converged = true;
  NewtonReport last;
  last.converged = true;
  last.residual_norm = pose_residual(data, pose, q4).lpNorm<Eigen::Infinity>();
  while (q4 != target_q4) {
    const double remaining = target_q4 - q4;
    const bool last_step = std::abs(remaining) <= step_limit;
    const double step = last_step ? remaining : std::copysign(step_limit, remaining);
    // Second-order predictor: p(q4 + h) ~ p + h p' + h^2/2 p'',
    // R(q4 + h) ~ exp([h omega + h^2/2 omega']x) R (agrees with R + h R' + h^2/2 R'' to O(h^3)).
    const PoseSensitivity sensitivity = pose_sensitivity(data, pose);
    CarrierPose predicted = pose;
    predicted.origin += step * sensitivity.dorigin + 0.5 * step * step * sensitivity.ddorigin;
    predicted.rotation = orthonormalized(
        rotation_from_vector(step * sensitivity.omega + 0.5 * step * step * sensitivity.domega) *
        pose.rotation);
    const double next_q4 = last_step ? target_q4 : q4 + step;
    NewtonReport step_report;
    const CarrierPose corrected =
        solve_pose(data, next_q4, pose.chassis_z, predicted, &step_report, 1e-14, 12);
    total.iterations += step_report.iterations;
    if (step_report.converged) {
      pose = corrected;
      q4 = next_q4;
      last = step_report;
      step_limit = std::min(max_step, 2.0 * step_limit);
    } else {
      step_limit *= 0.5;
      last = step_report;
      if (step_limit < min_step) {
        total.converged = false;
        break;
      }
    }
  }
  total.residual_norm = last.residual_norm;
  fill_singular_values(pose_jacobian(data, pose), &total);
  if (report != nullptr) {
    *report = total;
  } else if (!total.converged) {
    std::ostringstream message;
    message << "mbdae::reference::continue_pose: stuck at q4 = " << q4 << " on the way to "
            << target_q4 << ", sigma_min(J) = " << total.min_singular_value;
    throw std::runtime_error(message.str());
  }
  return pose;
}

// ---------------------------------------------------------------------------------------------
// Implicit derivatives
// ---------------------------------------------------------------------------------------------

PoseSensitivity pose_sensitivity(const SuspensionData& data, const CarrierPose& pose) {
  const auto lu = pose_jacobian(data, pose).fullPivLu();

  // First order. Only the angle equation depends on q4 explicitly (dF_5/dq4 = -1), so
  //   J (p', omega) = (0, 0, 0, 0, 0, 1).
  Vector6 first_rhs = Vector6::Zero();
  first_rhs(5) = 1.0;
  const Vector6 first = lu.solve(first_rhs);
  PoseSensitivity sensitivity;
  sensitivity.dorigin = first.head<3>();
  sensitivity.omega = first.tail<3>();
  const Vector3& omega = sensitivity.omega;

  // Second order. With r' = omega x r and
  //   d'' = p'' + omega' x r + omega x (omega x r)     (the last term is the "centripetal" part),
  // the equations differentiated twice along the solution curve are linear in (p'', omega')
  // with the same matrix J:
  //   |d| = L  =>  d.d' = 0  =>  d'.d' + d.d'' = 0
  //            =>  u.(p'' + omega' x r) = -(|d'|^2 + d.(omega x (omega x r))) / |d|;
  //   atan2(d_z, d_y) = q4  =>  N = d_y d_z' - d_z d_y' = rho^2 (rho^2 = d_y^2 + d_z^2), and
  //            N' = d_y d_z'' - d_z d_y'' = (rho^2)' = 2 (d_y d_y' + d_z d_z')
  //            =>  a.(p'' + omega' x r) = 2 (d_y d_y' + d_z d_z') / rho^2
  //                                       - a.(omega x (omega x r)),
  //               a = (0, -d_z, d_y) / rho^2.
  Vector6 gamma;
  for (int k = 1; k <= 5; ++k) {
    const RodVector rod = rod_vector(data, pose, k);
    const Vector3 d_first = sensitivity.dorigin + omega.cross(rod.lever);
    const Vector3 centripetal = omega.cross(omega.cross(rod.lever));
    const int row = (k == 5) ? 0 : k;
    gamma(row) = -(d_first.squaredNorm() + rod.vector.dot(centripetal)) / rod.vector.norm();
  }
  {
    const RodVector rod2 = rod_vector(data, pose, 2);
    const Vector3& d = rod2.vector;
    const Vector3 d_first = sensitivity.dorigin + omega.cross(rod2.lever);
    const Vector3 centripetal = omega.cross(omega.cross(rod2.lever));
    const double rho_squared = d.y() * d.y() + d.z() * d.z();
    gamma(5) = 2.0 * (d.y() * d_first.y() + d.z() * d_first.z()) / rho_squared -
               angle_gradient(d).dot(centripetal);
  }
  const Vector6 second = lu.solve(gamma);
  sensitivity.ddorigin = second.head<3>();
  sensitivity.domega = second.tail<3>();
  return sensitivity;
}

PointMotion carrier_point_motion(const CarrierPose& pose, const PoseSensitivity& sensitivity,
                                 const Vector3& point_in_carrier) {
  // x = p + R c (+ chassis offset), r = R c:
  //   x' = p' + omega x r,   x'' = p'' + omega' x r + omega x (omega x r).
  const Vector3 lever = pose.rotation * point_in_carrier;
  const Vector3& omega = sensitivity.omega;
  PointMotion motion;
  motion.position = pose.origin + lever + Vector3(0.0, 0.0, pose.chassis_z);
  motion.first = sensitivity.dorigin + omega.cross(lever);
  motion.second =
      sensitivity.ddorigin + sensitivity.domega.cross(lever) + omega.cross(omega.cross(lever));
  return motion;
}

PointMotion rod_point_motion(const SuspensionData& data, const CarrierPose& pose,
                             const PoseSensitivity& sensitivity, int k, double s) {
  // x = bp_k + (s / L_k) d_k; the rod's length is constant, so the derivatives scale d_k's.
  const double fraction = s / data.rod_lengths.at(k - 1);
  PointMotion end;  // rod k's end point: carrier point cp_k, or the carrier origin for rod 5
  if (k == 5) {
    end.position = pose.origin + Vector3(0.0, 0.0, pose.chassis_z);
    end.first = sensitivity.dorigin;
    end.second = sensitivity.ddorigin;
  } else {
    end = carrier_point_motion(pose, sensitivity, data.carrier_points.at(k - 1));
  }
  const Vector3 anchor = chassis_point(data, k) + Vector3(0.0, 0.0, pose.chassis_z);
  PointMotion motion;
  motion.position = anchor + fraction * (end.position - anchor);
  motion.first = fraction * end.first;
  motion.second = fraction * end.second;
  return motion;
}

// ---------------------------------------------------------------------------------------------
// Outputs
// ---------------------------------------------------------------------------------------------

WheelOutputs wheel_outputs(const SuspensionData& data, const CarrierPose& pose,
                           const PoseSensitivity& sensitivity) {
  WheelOutputs wheel;
  const PointMotion centre = carrier_point_motion(pose, sensitivity, data.carrier_points[4]);
  wheel.centre = centre.position;
  wheel.dcentre = centre.first;
  wheel.ddcentre = centre.second;
  // Spin axis y_w = R e_y; y_w' = omega x y_w.
  const Vector3 y = pose.rotation.col(1);
  const Vector3 y_first = sensitivity.omega.cross(y);
  wheel.spin_axis = y;
  // camber = asin(y_z):  camber' = y_z' / sqrt(1 - y_z^2).
  wheel.camber = std::asin(std::clamp(y.z(), -1.0, 1.0));
  wheel.dcamber = y_first.z() / std::sqrt(1.0 - y.z() * y.z());
  // toe = atan2(y_x, y_y):  toe' = (y_y y_x' - y_x y_y') / (y_x^2 + y_y^2).
  wheel.toe = std::atan2(y.x(), y.y());
  wheel.dtoe = (y.y() * y_first.x() - y.x() * y_first.y()) / (y.x() * y.x() + y.y() * y.y());
  return wheel;
}

WheelOutputs wheel_outputs(const SuspensionData& data, const CarrierPose& pose) {
  return wheel_outputs(data, pose, pose_sensitivity(data, pose));
}

Vector3 rod_direction(const SuspensionData& data, const CarrierPose& pose, int k) {
  return rod_vector(data, pose, k).vector.normalized();
}

std::array<double, 2> rod_angles_from_direction(const Vector3& u) {
  // u = Rx(a) Rz(b) e_y = (-sin b, cos a cos b, sin a cos b), cos b > 0.
  const double a = std::atan2(u.z(), u.y());
  const double b = std::atan2(-u.x(), std::hypot(u.y(), u.z()));
  return {a, b};
}

std::array<double, 14> joint_coordinates(const SuspensionData& data, const CarrierPose& pose) {
  std::array<double, 14> q{};
  q[0] = pose.chassis_z;  // q1
  for (int k = 1; k <= 5; ++k) {
    const auto angles = rod_angles_from_direction(rod_direction(data, pose, k));
    q[2 * k - 1] = angles[0];  // q(2k)
    q[2 * k] = angles[1];      // q(2k+1)
  }
  // Carrier relative to rod 5: M = (Rx(q10) Rz(q11))^T R = Rx(q12) Ry(q13) Rz(q14), where
  //   M = [ c13 c14, -c13 s14, s13 ; ... ; ..., -s12 c13, c12 c13 ]  (first row, last column).
  const Matrix3 rod5_rotation = rotation_x(q[9]) * rotation_z(q[10]);
  const Matrix3 m = rod5_rotation.transpose() * pose.rotation;
  q[11] = std::atan2(-m(1, 2), m(2, 2));                          // q12
  q[12] = std::atan2(m(0, 2), std::hypot(m(0, 0), m(0, 1)));      // q13
  q[13] = std::atan2(-m(0, 1), m(0, 0));                          // q14
  return q;
}

// ---------------------------------------------------------------------------------------------
// Statics
// ---------------------------------------------------------------------------------------------

SpringGeometry spring_geometry(const SuspensionData& data, const CarrierPose& pose,
                               const PoseSensitivity& sensitivity) {
  // s = P - bp6 with P = rod 5's COM (both on/relative to the chassis, so chassis_z cancels).
  const PointMotion com = rod_point_motion(data, pose, sensitivity, 5, data.rod_com_offsets[4]);
  const Vector3 s = com.position - (chassis_point(data, 6) + Vector3(0.0, 0.0, pose.chassis_z));
  // Z = |s|, Z' = s.s'/Z, Z'' = (s'.s' + s.s'' - Z'^2) / Z.
  SpringGeometry spring;
  spring.length = s.norm();
  spring.first = s.dot(com.first) / spring.length;
  spring.second =
      (com.first.squaredNorm() + s.dot(com.second) - spring.first * spring.first) / spring.length;
  return spring;
}

double tyre_compression(const SuspensionData& data, const WheelOutputs& wheel, double ground_z) {
  return data.tyre_radius * std::cos(wheel.camber) - (wheel.centre.z() - ground_z);
}

double tyre_force(const SuspensionData& data, const WheelOutputs& wheel, double ground_z) {
  return std::max(0.0, data.tyre_stiffness * tyre_compression(data, wheel, ground_z));
}

GeneralizedForce generalized_force_q4(const SuspensionData& data, const CarrierPose& pose,
                                      double spring_free_length, double ground_z) {
  const PoseSensitivity sensitivity = pose_sensitivity(data, pose);
  const WheelOutputs wheel = wheel_outputs(data, pose, sensitivity);
  const SpringGeometry spring = spring_geometry(data, pose, sensitivity);
  GeneralizedForce force;
  // Weight (0, 0, -m g) at every moving mass: delta W = -g sum m_i delta z_i.
  force.gravity = -data.gravity * weighted_height_derivatives(data, pose, sensitivity)[0];
  // Tension F = K (Z - Z0) pulls the two ends together: delta W = -F delta Z.
  force.spring = -data.spring_stiffness * (spring.length - spring_free_length) * spring.first;
  // Vertical tyre force at the wheel centre: delta W = F_t delta z_w.
  force.tyre = tyre_force(data, wheel, ground_z) * wheel.dcentre.z();
  force.total = force.gravity + force.spring + force.tyre;
  return force;
}

double spring_free_length(const SuspensionData& data, const CarrierPose& pose) {
  // Q = Q_g + Q_t - K (Z - Z0) Z' = 0  =>  Z0 = Z - (Q_g + Q_t) / (K Z').
  const GeneralizedForce force = generalized_force_q4(data, pose, 0.0, 0.0);
  const SpringGeometry spring = spring_geometry(data, pose, pose_sensitivity(data, pose));
  return spring.length - (force.gravity + force.tyre) / (data.spring_stiffness * spring.first);
}

double spring_free_length(const SuspensionData& data, double q4) {
  const CarrierPose pose = continue_pose(data, design_pose(data), data.q4_design, q4);
  return spring_free_length(data, pose);
}

PotentialEnergy potential_energy(const SuspensionData& data, const CarrierPose& pose,
                                 double spring_free_length, double ground_z) {
  const PoseSensitivity no_motion;  // positions only
  PotentialEnergy energy;
  double weighted_height = data.chassis_mass * pose.chassis_z;
  for (int k = 1; k <= 5; ++k) {
    weighted_height +=
        data.rod_masses[k - 1] *
        rod_point_motion(data, pose, no_motion, k, data.rod_com_offsets[k - 1]).position.z();
  }
  weighted_height +=
      data.carrier_mass * carrier_point_motion(pose, no_motion, data.carrier_com).position.z();
  weighted_height += data.wheel_mass *
                     carrier_point_motion(pose, no_motion, data.carrier_points[4]).position.z();
  energy.gravity = data.gravity * weighted_height;
  const double stretch = spring_geometry(data, pose, no_motion).length - spring_free_length;
  energy.spring = 0.5 * data.spring_stiffness * stretch * stretch;
  WheelOutputs wheel;
  wheel.centre = carrier_point_motion(pose, no_motion, data.carrier_points[4]).position;
  wheel.camber = std::asin(std::clamp(pose.rotation(2, 1), -1.0, 1.0));
  const double e = tyre_compression(data, wheel, ground_z);
  energy.tyre = e > 0.0 ? 0.5 * data.tyre_stiffness * e * e : 0.0;
  energy.total = energy.gravity + energy.spring + energy.tyre;
  return energy;
}

double tyre_camber_work_q4(const SuspensionData& data, const CarrierPose& pose, double ground_z) {
  // V_t = K_t e^2 / 2, e = r cos(phi) - z_w:  -dV_t/dq4 = K_t e (z_w' + r sin(phi) phi').
  const WheelOutputs wheel = wheel_outputs(data, pose);
  const double e = tyre_compression(data, wheel, ground_z);
  if (e <= 0.0) return 0.0;
  return data.tyre_stiffness * e * data.tyre_radius * std::sin(wheel.camber) * wheel.dcamber;
}

VehicleEquilibrium solve_vehicle_equilibrium(const SuspensionData& data,
                                             double spring_free_length,
                                             VehicleEquilibriumReport* report) {
  return solve_vehicle_equilibrium(data, spring_free_length,
                                   VehicleEquilibrium{data.chassis_z_design, data.q4_design},
                                   report);
}

namespace {

// The two equilibrium equations of the chassis-free vehicle and their exact Jacobian at (q1, q4).
struct VehicleEquations {
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();   // (G1, G2)
  Eigen::Matrix2d jacobian = Eigen::Matrix2d::Zero();   // d(G1, G2)/d(q1, q4)
  double tyre_force = 0.0;
};

VehicleEquations vehicle_equations(const SuspensionData& data, double spring_free_length,
                                   const CarrierPose& pose) {
  const PoseSensitivity sensitivity = pose_sensitivity(data, pose);
  const WheelOutputs wheel = wheel_outputs(data, pose, sensitivity);
  const SpringGeometry spring = spring_geometry(data, pose, sensitivity);
  const auto heights = weighted_height_derivatives(data, pose, sensitivity);
  const double k_tyre = data.tyre_stiffness;
  const double k_spring = data.spring_stiffness;
  const bool contact = tyre_compression(data, wheel, 0.0) > 0.0;
  const double f_tyre = tyre_force(data, wheel, 0.0);
  const double zw1 = wheel.dcentre.z();   // z_w'  (z_w = q1 + z~(q4))
  const double zw2 = wheel.ddcentre.z();  // z_w''
  const double stretch = spring.length - spring_free_length;

  VehicleEquations equations;
  equations.tyre_force = f_tyre;
  // G1: generalized force along q1 (every body rides on the chassis): F_t - M g.
  equations.residual(0) = f_tyre - total_mass(data) * data.gravity;
  // G2: generalized force along q4 with q1 held.
  equations.residual(1) =
      -data.gravity * heights[0] + f_tyre * zw1 - k_spring * stretch * spring.first;
  // In contact: dF_t/dq1 = -K_t, dF_t/dq4 = -K_t (z_w' + r sin(phi) phi');
  //   dG2/dq1 = dF_t/dq1 z_w',
  //   dG2/dq4 = -g sum m z'' + dF_t/dq4 z_w' + F_t z_w'' - K (Z'^2 + (Z - Z0) Z'').
  const double df_dq1 = contact ? -k_tyre : 0.0;
  const double df_dq4 =
      contact ? -k_tyre * (zw1 + data.tyre_radius * std::sin(wheel.camber) * wheel.dcamber)
              : 0.0;
  equations.jacobian << df_dq1, df_dq4, df_dq1 * zw1,
      -data.gravity * heights[1] + df_dq4 * zw1 + f_tyre * zw2 -
          k_spring * (spring.first * spring.first + stretch * spring.second);
  return equations;
}

}  // namespace

VehicleEquilibrium solve_vehicle_equilibrium(const SuspensionData& data,
                                             double spring_free_length,
                                             const VehicleEquilibrium& guess,
                                             VehicleEquilibriumReport* report) {
  VehicleEquilibrium solution = guess;
  CarrierPose pose = continue_pose(data, design_pose(data), data.q4_design, solution.q4);
  double pose_q4 = solution.q4;
  VehicleEquilibriumReport local;
  const int max_iterations = 40;
  bool last_step_negligible = false;
  for (;;) {
    // The loop geometry does not depend on q1 (the chassis only translates): follow q4 by
    // continuation and set the chassis height.
    pose = continue_pose(data, pose, pose_q4, solution.q4);
    pose_q4 = solution.q4;
    // Globalization: without tyre contact G1 = -M g does not depend on q1 and the Jacobian is
    // singular. G1 is linear in q1 in contact, so put the chassis where G1 = 0 exactly:
    //   q1 = r cos(camber) - z~(q4) - M g / K_t,   z~ = wheel-centre height relative to chassis.
    pose.chassis_z = 0.0;
    const WheelOutputs relative = wheel_outputs(data, pose);
    if (tyre_compression(data, relative, -solution.q1) <= 0.0) {  // ground at -q1 from chassis
      solution.q1 = data.tyre_radius * std::cos(relative.camber) - relative.centre.z() -
                    total_mass(data) * data.gravity / data.tyre_stiffness;
    }
    pose.chassis_z = solution.q1;
    const VehicleEquations equations = vehicle_equations(data, spring_free_length, pose);
    local.vertical_residual = std::abs(equations.residual(0));
    local.q4_residual = std::abs(equations.residual(1));
    local.tyre_force = equations.tyre_force;
    local.pose = pose;
    // Stop after a step below 1e-12: with quadratic convergence the error left after it is
    // O(1e-24), i.e. the iterate is exact to rounding.
    if (last_step_negligible) {
      local.converged = true;
      break;
    }
    if (local.iterations >= max_iterations) break;
    Eigen::Vector2d step = equations.jacobian.fullPivLu().solve(-equations.residual);
    if (!step.allFinite()) break;
    // Step limit (inactive near the solution): at most 0.2 rad of q4 per iteration.
    const double max_q4_step = 0.2;
    if (std::abs(step(1)) > max_q4_step) step *= max_q4_step / std::abs(step(1));
    solution.q1 += step(0);
    solution.q4 += step(1);
    ++local.iterations;
    last_step_negligible = step.lpNorm<Eigen::Infinity>() < 1e-12;
  }
  if (report != nullptr) {
    *report = local;
  } else if (!local.converged) {
    std::ostringstream message;
    message << "mbdae::reference::solve_vehicle_equilibrium: no convergence, |G1| = "
            << local.vertical_residual << " N, |G2| = " << local.q4_residual << " N m";
    throw std::runtime_error(message.str());
  }
  return solution;
}

}  // namespace mbdae::reference
