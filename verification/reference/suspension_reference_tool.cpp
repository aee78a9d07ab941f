// Prints the reference solution of the five-point suspension (independent carrier-pose
// formulation, see suspension_reference.h): the design configuration, the spring free length
// Z0, the chassis-free equilibrium and a kinematic sweep over q4.
#include <cmath>
#include <cstdio>
#include <vector>

#include "verification/reference/suspension_reference.h"

namespace ref = mbdae::reference;

namespace {

constexpr double kRadiansToDegrees = 180.0 / 3.14159265358979323846;

void print_newton_history(const ref::SuspensionData& data) {
  std::printf("Newton from the spec's guess (q4 = q4_0, q1 = %.3f):\n", data.chassis_z_design);
  const ref::CarrierPose guess = ref::spec_guess_pose(data, data.chassis_z_design);
  for (int iterations = 0; iterations <= 8; ++iterations) {
    ref::NewtonReport report;
    ref::solve_pose(data, data.q4_design, data.chassis_z_design, guess, &report, 1e-14,
                    iterations);
    std::printf("  after %d iteration(s): |F|_inf = %.3e\n", report.iterations,
                report.residual_norm);
    if (report.converged) break;
  }
}

void print_design_pose(const ref::SuspensionData& data, const ref::CarrierPose& pose) {
  ref::NewtonReport report;
  ref::solve_pose(data, data.q4_design, data.chassis_z_design, pose, &report);
  const ref::WheelOutputs wheel = ref::wheel_outputs(data, pose);
  const auto q = ref::joint_coordinates(data, pose);
  std::printf("\nDesign configuration (q4 = %.12f rad, q1 = %.3f m):\n", data.q4_design,
              data.chassis_z_design);
  std::printf("  residual |F|_inf = %.3e, sigma_min(J) = %.6f, cond(J) = %.3f\n",
              ref::pose_residual(data, pose, data.q4_design).lpNorm<Eigen::Infinity>(),
              report.min_singular_value, report.condition_number);
  std::printf("  carrier origin (chassis frame) = (%.15f, %.15f, %.15f)\n", pose.origin.x(),
              pose.origin.y(), pose.origin.z());
  std::printf("  wheel centre = (%.15f, %.15f, %.15f) m\n", wheel.centre.x(), wheel.centre.y(),
              wheel.centre.z());
  std::printf("  spin axis y_w = (%.15f, %.15f, %.15f)\n", wheel.spin_axis.x(),
              wheel.spin_axis.y(), wheel.spin_axis.z());
  std::printf("  camber = %.15e rad = %.12f deg\n", wheel.camber,
              wheel.camber * kRadiansToDegrees);
  std::printf("  toe    = %.15e rad = %.12f deg\n", wheel.toe, wheel.toe * kRadiansToDegrees);
  std::printf("  d(wheel centre)/dq4 = (%.12f, %.12f, %.12f) m/rad\n", wheel.dcentre.x(),
              wheel.dcentre.y(), wheel.dcentre.z());
  std::printf("  dcamber/dq4 = %.12f, dtoe/dq4 = %.12f\n", wheel.dcamber, wheel.dtoe);
  std::printf("  joint coordinates (spec guess in degrees for comparison):\n");
  std::printf("    q1  = %.15f m\n", q[0]);
  for (int i = 2; i <= 14; ++i) {
    std::printf("    q%-2d = %+.15f rad = %+.12f deg   (guess %+.12f deg)\n", i, q[i - 1],
                q[i - 1] * kRadiansToDegrees, data.initial_guess_deg[i - 2]);
  }
  const double force = ref::tyre_force(data, wheel, 0.0);
  const double weight = ref::total_mass(data) * data.gravity;
  std::printf("  tyre compression e = %.15f m, tyre force = %.9f N, total weight %.3f kg * g = "
              "%.9f N (difference %.6f N)\n",
              ref::tyre_compression(data, wheel, 0.0), force, ref::total_mass(data), weight,
              force - weight);
}

void print_equilibria(const ref::SuspensionData& data, const ref::CarrierPose& pose) {
  const double z0 = ref::spring_free_length(data, pose);
  const ref::PoseSensitivity sensitivity = ref::pose_sensitivity(data, pose);
  const ref::SpringGeometry spring = ref::spring_geometry(data, pose, sensitivity);
  const ref::GeneralizedForce force = ref::generalized_force_q4(data, pose, z0);
  std::printf("\nEquilibrium with the chassis held (q1 = %.3f, q4 = q4_0, ground at 0):\n",
              data.chassis_z_design);
  std::printf("  spring length Z = %.15f m, dZ/dq4 = %.15f m/rad\n", spring.length,
              spring.first);
  std::printf("  Z0 = %.15f m  (spring tension %.9f N)\n", z0,
              data.spring_stiffness * (spring.length - z0));
  std::printf("  generalized forces along q4: gravity %.9f, tyre %.9f, spring %.9f, "
              "total %.3e N m\n",
              force.gravity, force.tyre, force.spring, force.total);
  std::printf("  tyre camber work term K_t e r sin(phi) phi' = %.9f N m "
              "(not in the spec's force)\n",
              ref::tyre_camber_work_q4(data, pose));

  ref::VehicleEquilibriumReport report;
  const ref::VehicleEquilibrium equilibrium = ref::solve_vehicle_equilibrium(data, z0, &report);
  const ref::WheelOutputs wheel = ref::wheel_outputs(data, report.pose);
  std::printf("\nChassis-free equilibrium (Dynamics II initial state, Z0 above):\n");
  std::printf("  converged = %s in %d Newton iterations, |G1| = %.3e N, |G2| = %.3e N m\n",
              report.converged ? "yes" : "NO", report.iterations, report.vertical_residual,
              report.q4_residual);
  std::printf("  q1 = %.15f m, q4 = %.15f rad\n", equilibrium.q1, equilibrium.q4);
  std::printf("  q1 - 0.278 = %.3e m, q4 - q4_0 = %.3e rad\n",
              equilibrium.q1 - data.chassis_z_design, equilibrium.q4 - data.q4_design);
  std::printf("  wheel centre = (%.15f, %.15f, %.15f), tyre force = %.9f N\n", wheel.centre.x(),
              wheel.centre.y(), wheel.centre.z(), report.tyre_force);
}

struct SweepRow {
  double q4 = 0.0;
  bool reached = false;
  ref::CarrierPose pose;
  ref::NewtonReport report;
};

// Continuation from the design pose outwards in both directions; a direction stops at its first
// failure.
std::vector<SweepRow> sweep(const ref::SuspensionData& data, const ref::CarrierPose& design,
                            const std::vector<double>& values) {
  std::vector<SweepRow> rows(values.size());
  for (size_t i = 0; i < values.size(); ++i) rows[i].q4 = values[i];
  for (int direction : {-1, +1}) {
    ref::CarrierPose pose = design;
    double q4 = data.q4_design;
    bool blocked = false;
    for (size_t n = 0; n < values.size(); ++n) {
      const size_t i = direction < 0 ? values.size() - 1 - n : n;
      if ((values[i] - data.q4_design) * direction < 0) continue;
      if (direction > 0 && values[i] == data.q4_design) continue;
      if (blocked) continue;
      ref::NewtonReport report;
      const ref::CarrierPose next = ref::continue_pose(data, pose, q4, values[i], &report);
      rows[i].report = report;
      if (!report.converged) {
        blocked = true;
        const double stuck_at = ref::joint_coordinates(data, next)[3];
        std::printf("  continuation towards q4 = %+.4f stopped at q4 = %+.9f "
                    "(sigma_min(J) = %.3e, cond = %.3e)\n",
                    values[i], stuck_at, report.min_singular_value, report.condition_number);
        continue;
      }
      rows[i].reached = true;
      rows[i].pose = next;
      pose = next;
      q4 = values[i];
    }
  }
  return rows;
}

void print_sweep(const ref::SuspensionData& data, const ref::CarrierPose& design) {
  std::printf("\nKinematic sweep (q1 = %.3f), 25 values of q4 from -1.1 to 1.2:\n",
              data.chassis_z_design);
  std::vector<double> values;
  for (int i = 0; i < 25; ++i) values.push_back(-1.1 + 2.3 * i / 24.0);
  const std::vector<SweepRow> rows = sweep(data, design, values);
  std::printf("  %9s %12s %12s %13s %13s %13s %11s %11s\n", "q4 [rad]", "camber[deg]",
              "toe [deg]", "x_w [m]", "y_w [m]", "z_w [m]", "sigma_min", "cond(J)");
  for (const SweepRow& row : rows) {
    if (!row.reached) {
      std::printf("  %+9.5f   (not reached: Newton/continuation failed before this value)\n",
                  row.q4);
      continue;
    }
    const ref::WheelOutputs wheel = ref::wheel_outputs(data, row.pose);
    std::printf("  %+9.5f %+12.6f %+12.6f %+13.9f %+13.9f %+13.9f %11.3e %11.3e\n", row.q4,
                wheel.camber * kRadiansToDegrees, wheel.toe * kRadiansToDegrees,
                wheel.centre.x(), wheel.centre.y(), wheel.centre.z(),
                row.report.min_singular_value, row.report.condition_number);
  }
}

}  // namespace

int main() {
  const ref::SuspensionData data = ref::spec_data();
  print_newton_history(data);
  const ref::CarrierPose design = ref::design_pose(data);
  print_design_pose(data, design);
  print_equilibria(data, design);
  print_sweep(data, design);
  return 0;
}
