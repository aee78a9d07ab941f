// Self-consistency tests of the independent suspension reference (suspension_reference.h):
// solved poses, the spec's statements about the design configuration, implicit derivatives
// against finite differences, and virtual work against the potential energy.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "verification/reference/suspension_reference.h"

namespace mbdae::reference {
namespace {

constexpr double kDegreesToRadians = 3.14159265358979323846 / 180.0;

class SuspensionReferenceTest : public ::testing::Test {
 protected:
  SuspensionData data_ = spec_data();
  CarrierPose design_ = design_pose(data_);

  CarrierPose pose_at(double q4) const {
    return continue_pose(data_, design_, data_.q4_design, q4);
  }
};

// Rotation vector w with exp([w]x) = rotation.
Vector3 rotation_vector(const Matrix3& rotation) {
  const Eigen::AngleAxisd angle_axis(rotation);
  return angle_axis.angle() * angle_axis.axis();
}

TEST_F(SuspensionReferenceTest, SpecData) {
  EXPECT_DOUBLE_EQ(data_.chassis_points[4].x(), 0.2115);  // Errata: bp5 x = +0.2115
  EXPECT_NEAR(total_mass(data_), 448.91, 1e-12);
  EXPECT_NEAR(data_.initial_guess_deg[2] * kDegreesToRadians, data_.q4_design, 1e-15);
}

TEST_F(SuspensionReferenceTest, NewtonFromSpecGuessConvergesQuadratically) {
  NewtonReport report;
  const CarrierPose pose = solve_pose(data_, data_.q4_design, data_.chassis_z_design,
                                      spec_guess_pose(data_, data_.chassis_z_design), &report);
  EXPECT_TRUE(report.converged);
  EXPECT_LE(report.iterations, 5);
  EXPECT_LT(pose_residual(data_, pose, data_.q4_design).lpNorm<Eigen::Infinity>(), 1e-13);
  // The guess is off by "a few mm": the first residual is of that order.
  const double guess_residual =
      pose_residual(data_, spec_guess_pose(data_, data_.chassis_z_design), data_.q4_design)
          .lpNorm<Eigen::Infinity>();
  EXPECT_GT(guess_residual, 1e-4);
  EXPECT_LT(guess_residual, 1e-2);
  EXPECT_GT(report.min_singular_value, 0.1);
}

TEST_F(SuspensionReferenceTest, DesignPoseResidualAndOrthonormality) {
  EXPECT_LT(pose_residual(data_, design_, data_.q4_design).lpNorm<Eigen::Infinity>(), 1e-13);
  EXPECT_LT((design_.rotation.transpose() * design_.rotation - Matrix3::Identity()).norm(),
            1e-14);
  EXPECT_NEAR(design_.rotation.determinant(), 1.0, 1e-14);
  // Every rod has its length, measured directly.
  for (int k = 1; k <= 4; ++k) {
    const Vector3 end = design_.rotation * data_.carrier_points[k - 1] + design_.origin;
    EXPECT_NEAR((end - data_.chassis_points[k - 1]).norm(), data_.rod_lengths[k - 1], 1e-14);
  }
  EXPECT_NEAR((design_.origin - data_.chassis_points[4]).norm(), data_.rod_lengths[4], 1e-14);
}

TEST_F(SuspensionReferenceTest, SpecStatementsAtDesign) {
  const WheelOutputs wheel = wheel_outputs(data_, design_);
  // "The converged design configuration has the wheel centre close to (0, 0.768, 0.278) with toe
  // close to 0."
  EXPECT_NEAR(wheel.centre.x(), 0.0, 1e-3);
  EXPECT_NEAR(wheel.centre.y(), 0.768, 1e-3);
  EXPECT_NEAR(wheel.centre.z(), 0.278, 1e-3);
  EXPECT_NEAR(wheel.toe, 0.0, 0.2 * kDegreesToRadians);
  // "The tyre force there (about 4403 N) equals the total weight (448.91 kg * 9.81 = 4403.8 N)."
  const double force = tyre_force(data_, wheel, 0.0);
  EXPECT_NEAR(force, 4403.0, 2.0);
  EXPECT_NEAR(force, total_mass(data_) * data_.gravity, 2.0);
  // Regression values (cross-checked by an independent joint-coordinate computation in Python).
  EXPECT_NEAR(wheel.centre.x(), -0.000258388578671, 1e-12);
  EXPECT_NEAR(wheel.centre.y(), 0.768205558171672, 1e-12);
  EXPECT_NEAR(wheel.centre.z(), 0.277971383717455, 1e-12);
  EXPECT_NEAR(wheel.camber, 1.045373159588503e-02, 1e-12);
  EXPECT_NEAR(wheel.toe, -1.097697576518972e-03, 1e-12);
}

TEST_F(SuspensionReferenceTest, JointCoordinatesMatchGuessAndReproducePose) {
  const auto q = joint_coordinates(data_, design_);
  EXPECT_DOUBLE_EQ(q[0], data_.chassis_z_design);
  EXPECT_NEAR(q[3], data_.q4_design, 1e-14);
  for (int i = 2; i <= 14; ++i) {
    const double guess = data_.initial_guess_deg[i - 2] * kDegreesToRadians;
    // q8's guess has the wrong sign (spec); all the others are within 0.1 deg.
    const double expected = (i == 8) ? -guess : guess;
    EXPECT_NEAR(q[i - 1], expected, 0.1 * kDegreesToRadians) << "q" << i;
  }
  // Forward kinematics of the recovered joint coordinates gives back the pose.
  for (int k = 1; k <= 5; ++k) {
    const Matrix3 rod_rotation = rotation_x(q[2 * k - 1]) * rotation_z(q[2 * k]);
    const Vector3 end =
        data_.chassis_points[k - 1] + rod_rotation * Vector3(0, data_.rod_lengths[k - 1], 0);
    const Vector3 target = (k == 5) ? design_.origin
                                    : Vector3(design_.rotation * data_.carrier_points[k - 1] +
                                              design_.origin);
    EXPECT_LT((end - target).norm(), 1e-14) << "rod " << k;
  }
  const Matrix3 carrier_rotation = rotation_x(q[9]) * rotation_z(q[10]) * rotation_x(q[11]) *
                                   rotation_y(q[12]) * rotation_z(q[13]);
  EXPECT_LT((carrier_rotation - design_.rotation).norm(), 1e-14);
}

TEST_F(SuspensionReferenceTest, RodAnglesFromDirectionInvertsRodKinematics) {
  for (double a : {-1.2, -0.3, 0.0, 0.4, 1.1}) {
    for (double b : {-0.9, -0.1, 0.0, 0.5, 1.3}) {
      const Vector3 u = rotation_x(a) * rotation_z(b) * Vector3::UnitY();
      EXPECT_NEAR(u.x(), -std::sin(b), 1e-15);
      EXPECT_NEAR(u.y(), std::cos(a) * std::cos(b), 1e-15);
      EXPECT_NEAR(u.z(), std::sin(a) * std::cos(b), 1e-15);
      const auto angles = rod_angles_from_direction(u);
      EXPECT_NEAR(angles[0], a, 1e-14);
      EXPECT_NEAR(angles[1], b, 1e-14);
    }
  }
}

TEST_F(SuspensionReferenceTest, PoseJacobianMatchesFiniteDifferences) {
  const CarrierPose pose = pose_at(0.6);
  const Matrix6 jacobian = pose_jacobian(data_, pose);
  const double h = 1e-6;
  for (int j = 0; j < 6; ++j) {
    Vector6 step = Vector6::Zero();
    step(j) = h;
    auto perturbed = [&](double sign) {
      CarrierPose p = pose;
      p.origin += sign * step.head<3>();
      p.rotation = rotation_from_vector(sign * step.tail<3>()) * pose.rotation;
      return pose_residual(data_, p, 0.6);
    };
    const Vector6 column = (perturbed(+1) - perturbed(-1)) / (2 * h);
    EXPECT_LT((column - jacobian.col(j)).norm(), 1e-8) << "column " << j;
  }
}

TEST_F(SuspensionReferenceTest, ContinuationRoundTripAndSweep) {
  // Out to both ends of the spec's travel and back: the design pose is recovered.
  const CarrierPose low = continue_pose(data_, design_, data_.q4_design, -1.1);
  const CarrierPose high = continue_pose(data_, low, -1.1, 1.2);
  const CarrierPose back = continue_pose(data_, high, 1.2, data_.q4_design);
  EXPECT_LT((back.origin - design_.origin).norm(), 1e-13);
  EXPECT_LT((back.rotation - design_.rotation).norm(), 1e-13);
  // Every sweep point is a solved, well-conditioned configuration with rod 2 at q4.
  CarrierPose pose = low;
  double q4 = -1.1;
  for (int i = 0; i < 25; ++i) {
    const double target = -1.1 + 2.3 * i / 24.0;
    NewtonReport report;
    pose = continue_pose(data_, pose, q4, target, &report);
    q4 = target;
    ASSERT_TRUE(report.converged) << "q4 = " << target;
    EXPECT_LT(pose_residual(data_, pose, q4).lpNorm<Eigen::Infinity>(), 1e-13);
    EXPECT_GT(report.min_singular_value, 0.05);
    EXPECT_NEAR(joint_coordinates(data_, pose)[3], q4, 1e-13);
  }
  // The travel covers the spec's +-0.20 m of wheel-centre height around the design.
  const double z_design = wheel_outputs(data_, design_).centre.z();
  EXPECT_LT(wheel_outputs(data_, low).centre.z(), z_design - 0.20);
  EXPECT_GT(wheel_outputs(data_, high).centre.z(), z_design + 0.20);
}

TEST_F(SuspensionReferenceTest, ImplicitDerivativesMatchFiniteDifferences) {
  const double h = 1e-5;
  for (double q4 : {-1.0, data_.q4_design, 1.1}) {
    const CarrierPose pose = pose_at(q4);
    const CarrierPose plus = continue_pose(data_, pose, q4, q4 + h);
    const CarrierPose minus = continue_pose(data_, pose, q4, q4 - h);
    const PoseSensitivity s = pose_sensitivity(data_, pose);
    const PoseSensitivity s_plus = pose_sensitivity(data_, plus);
    const PoseSensitivity s_minus = pose_sensitivity(data_, minus);

    // First order: p' and omega (dR/dq4 = [omega]x R).
    EXPECT_LT(((plus.origin - minus.origin) / (2 * h) - s.dorigin).norm(), 1e-9) << q4;
    const Vector3 omega_fd =
        rotation_vector(plus.rotation * minus.rotation.transpose()) / (2 * h);
    EXPECT_LT((omega_fd - s.omega).norm(), 1e-9) << q4;
    // Second order: p'' and omega'.
    EXPECT_LT(((s_plus.dorigin - s_minus.dorigin) / (2 * h) - s.ddorigin).norm(), 1e-8) << q4;
    EXPECT_LT(((s_plus.omega - s_minus.omega) / (2 * h) - s.domega).norm(), 1e-8) << q4;

    // Wheel outputs.
    const WheelOutputs w = wheel_outputs(data_, pose, s);
    const WheelOutputs w_plus = wheel_outputs(data_, plus, s_plus);
    const WheelOutputs w_minus = wheel_outputs(data_, minus, s_minus);
    EXPECT_LT(((w_plus.centre - w_minus.centre) / (2 * h) - w.dcentre).norm(), 1e-9) << q4;
    EXPECT_LT(((w_plus.dcentre - w_minus.dcentre) / (2 * h) - w.ddcentre).norm(), 1e-8) << q4;
    EXPECT_NEAR((w_plus.camber - w_minus.camber) / (2 * h), w.dcamber, 1e-9) << q4;
    EXPECT_NEAR((w_plus.toe - w_minus.toe) / (2 * h), w.dtoe, 1e-9) << q4;

    // Rod points (COMs) and the spring length.
    for (int k = 1; k <= 5; ++k) {
      const double c = data_.rod_com_offsets[k - 1];
      const PointMotion m = rod_point_motion(data_, pose, s, k, c);
      const PointMotion m_plus = rod_point_motion(data_, plus, s_plus, k, c);
      const PointMotion m_minus = rod_point_motion(data_, minus, s_minus, k, c);
      EXPECT_LT(((m_plus.position - m_minus.position) / (2 * h) - m.first).norm(), 1e-9);
      EXPECT_LT(((m_plus.first - m_minus.first) / (2 * h) - m.second).norm(), 1e-8);
    }
    const SpringGeometry z = spring_geometry(data_, pose, s);
    const SpringGeometry z_plus = spring_geometry(data_, plus, s_plus);
    const SpringGeometry z_minus = spring_geometry(data_, minus, s_minus);
    EXPECT_NEAR((z_plus.length - z_minus.length) / (2 * h), z.first, 1e-9) << q4;
    EXPECT_NEAR((z_plus.first - z_minus.first) / (2 * h), z.second, 1e-8) << q4;
  }
}

TEST_F(SuspensionReferenceTest, VirtualWorkMatchesPotentialEnergy) {
  const double z0 = spring_free_length(data_, design_);
  const double h = 1e-4;
  for (double q4 : {-0.8, data_.q4_design, 0.9}) {
    const CarrierPose pose = pose_at(q4);
    const CarrierPose plus = continue_pose(data_, pose, q4, q4 + h);
    const CarrierPose minus = continue_pose(data_, pose, q4, q4 - h);
    const CarrierPose plus2 = continue_pose(data_, pose, q4, q4 + 2 * h);
    const CarrierPose minus2 = continue_pose(data_, pose, q4, q4 - 2 * h);
    // Fourth-order central difference of V.
    auto derivative = [&](auto energy_term) {
      return (-energy_term(potential_energy(data_, plus2, z0)) +
              8 * energy_term(potential_energy(data_, plus, z0)) -
              8 * energy_term(potential_energy(data_, minus, z0)) +
              energy_term(potential_energy(data_, minus2, z0))) /
             (12 * h);
    };
    const GeneralizedForce q = generalized_force_q4(data_, pose, z0);
    EXPECT_NEAR(-derivative([](const PotentialEnergy& v) { return v.gravity; }), q.gravity,
                1e-8)
        << q4;
    EXPECT_NEAR(-derivative([](const PotentialEnergy& v) { return v.spring; }), q.spring, 1e-7)
        << q4;
    // The spec's tyre force is vertical with magnitude K_t e; K_t e^2 / 2 is its potential only
    // up to the camber term.
    EXPECT_NEAR(-derivative([](const PotentialEnergy& v) { return v.tyre; }),
                q.tyre + tyre_camber_work_q4(data_, pose), 1e-7)
        << q4;
    // Tyre virtual work directly: F_t dz_w/dq4 with a finite-difference dz_w/dq4.
    const double dzw = (wheel_outputs(data_, plus).centre.z() -
                        wheel_outputs(data_, minus).centre.z()) / (2 * h);
    EXPECT_NEAR(q.tyre, tyre_force(data_, wheel_outputs(data_, pose), 0.0) * dzw, 1e-4) << q4;
  }
}

TEST_F(SuspensionReferenceTest, SpringFreeLengthMakesDesignAnEquilibrium) {
  const double z0 = spring_free_length(data_, design_);
  EXPECT_NEAR(spring_free_length(data_, data_.q4_design), z0, 1e-14);
  const GeneralizedForce q = generalized_force_q4(data_, design_, z0);
  EXPECT_NEAR(q.total, 0.0, 1e-10);
  // Regression value (the Python joint-coordinate cross-check gives 0.349998971628678 with
  // finite-difference derivatives).
  EXPECT_NEAR(z0, 0.349998971628795, 1e-11);
  // The spring is compressed at the design point (Z < Z0): it pushes the arm down.
  EXPECT_LT(spring_geometry(data_, design_, pose_sensitivity(data_, design_)).length, z0);
  // At another q4, the free length from that configuration again cancels Q there.
  const CarrierPose other = pose_at(0.5);
  EXPECT_NEAR(generalized_force_q4(data_, other, spring_free_length(data_, 0.5)).total, 0.0,
              1e-10);
}

TEST_F(SuspensionReferenceTest, ChassisFreeEquilibrium) {
  const double z0 = spring_free_length(data_, design_);
  VehicleEquilibriumReport report;
  const VehicleEquilibrium equilibrium = solve_vehicle_equilibrium(data_, z0, &report);
  ASSERT_TRUE(report.converged);
  EXPECT_LE(report.iterations, 6);
  const double weight = total_mass(data_) * data_.gravity;
  EXPECT_LT(report.vertical_residual, 1e-9);
  EXPECT_LT(report.q4_residual, 1e-9);
  // Independent evaluation of both equations at the solution.
  NewtonReport pose_report;
  const CarrierPose pose =
      solve_pose(data_, equilibrium.q4, equilibrium.q1, report.pose, &pose_report);
  ASSERT_TRUE(pose_report.converged);
  const WheelOutputs wheel = wheel_outputs(data_, pose);
  EXPECT_NEAR(tyre_force(data_, wheel, 0.0), weight, 1e-9);
  EXPECT_NEAR(generalized_force_q4(data_, pose, z0).total, 0.0, 1e-9);
  // Eliminating q1 by G1 = 0: q1 = r cos(camber) - z~(q4) - M g / K_t.
  const double z_relative = wheel.centre.z() - equilibrium.q1;
  EXPECT_NEAR(equilibrium.q1,
              data_.tyre_radius * std::cos(wheel.camber) - z_relative -
                  weight / data_.tyre_stiffness,
              1e-14);
  // Close to the design point: the tyre force there is 1.36 N short of the weight.
  EXPECT_NEAR(equilibrium.q1, data_.chassis_z_design, 1e-4);
  EXPECT_NEAR(equilibrium.q4, data_.q4_design, 1e-3);
  // Regression values.
  EXPECT_NEAR(equilibrium.q1, 0.277952850902763, 1e-11);
  EXPECT_NEAR(equilibrium.q4, 0.207921840103701, 1e-10);
  // From a distant guess as well.
  const VehicleEquilibrium again =
      solve_vehicle_equilibrium(data_, z0, VehicleEquilibrium{0.25, 0.6});
  EXPECT_NEAR(again.q1, equilibrium.q1, 1e-13);
  EXPECT_NEAR(again.q4, equilibrium.q4, 1e-12);
}

}  // namespace
}  // namespace mbdae::reference
