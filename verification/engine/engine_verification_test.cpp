// End-to-end verification of the engine: scenes in verification/engine/scenes/ are loaded and run
// as a user runs them (load_scene + run, or the mbdae executable), and their output is
// compared with references computed here from the scenes' data alone: closed-form solutions, the
// complete elliptic integral by the arithmetic-geometric mean, energies from the initial joint
// angles with Eigen's own rotations. No expected value is a recorded output of the engine.
//
// The scene constants that the references need are repeated below; each test first checks that
// the engine's initial output agrees with them (so a scene edited alone fails loudly).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cases/mbdae.h"
#include "cases/scene/scene.h"
#include "formulation/tests/pendulum_reference.h"

namespace {

using mbdae::testing::downward_crossings;
using mbdae::testing::elliptic_k;

using Eigen::AngleAxisd;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Tolerances of every integration below (they override the scenes' own, which are the same, so
// that `mbdae run` on a scene reproduces the test). The scenes also set IDA's Newton convergence
// coefficient to 0.001 (default 0.33): with the default, each step's Newton iteration stops at
// an error of about a third of the local tolerance, and for the energy of a conservative system
// those errors add up over the 2e4 steps (double pendulum at rtol 1e-13: 1.4e-8 of the kinetic
// energy with 0.33 and 3e-14 atol, 4.7e-9 with 0.001 and 1e-14 atol; spring body 1.6e-8 and
// sensitive to rounding-level changes, hence rtol 3e-14: 1.8e-9 and 4.0e-9).
// Requirement d: at the integrator's accepted steps, max |Phi| < 1e-10 and max | |p| - 1 | <
// 1e-12; the Euler-norm drift is about half the residual of p.p - 1, about rtol.
constexpr double kTightRtol = 3e-14, kTightAtol = 1e-14;

// Requirement d thresholds.
constexpr double kMaxViolation = 1e-10, kMaxNormDrift = 1e-12;

std::string scene_path(const std::string& name) {
  return std::string(MBDAE_SOURCE_DIR) + "/verification/engine/scenes/" + name;
}

// Rows kept, nothing printed; `tight`: kTightRtol and kTightAtol instead of the scene's.
mbdae::RunOptions test_options(bool tight) {
  mbdae::RunOptions o;
  o.verbose = false;
  o.progress = false;
  if (tight) {
    o.rtol = kTightRtol;
    o.atol = kTightAtol;
  }
  return o;
}

mbdae::Result run(const std::string& name) {
  return mbdae::run(mbdae::load_scene(scene_path(name)), test_options(true));
}

// The text of a scene of verification/engine/scenes, to run modified with run_text().
std::string scene_text(const std::string& name) {
  std::ifstream in(scene_path(name));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A modified scene `text`, read as if it were the file `name` (for its relative paths).
mbdae::Result run_text(const std::string& text, const std::string& name, bool tight) {
  return mbdae::run(mbdae::load_scene_text(text, scene_path(name)), test_options(tight));
}

// One output column (Result::column throws, and the test fails, naming a missing column).
const std::vector<double>& series(const mbdae::Result& r, const std::string& name) { return r.column(name); }

// The summary entry of the run's kinematics or dynamics step.
nlohmann::ordered_json integration_step(const mbdae::Result& r) {
  for (const auto& s : r.summary["steps"])
    if (s["type"] == "dynamics" || s["type"] == "kinematics") return s;
  ADD_FAILURE() << "no integration step in the summary";
  return {};
}

// Requirement d, with the measured values printed for the record.
void expect_clean_integration(const mbdae::Result& r, const char* what) {
  const auto step = integration_step(r);
  ASSERT_TRUE(step.contains("statistics"));
  const auto& st = step["statistics"];
  const double violation = st["max_position_violation_steps"].get<double>();
  const double drift = st["max_euler_norm_drift"].get<double>();
  std::printf("  [%s] %ld steps, max position violation %.3e, max Euler norm drift %.3e\n", what,
              st["steps"].get<long>(), violation, drift);
  EXPECT_LT(violation, kMaxViolation) << what;
  EXPECT_LT(drift, kMaxNormDrift) << what;
}

void expect_ran_to(const mbdae::Result& r, double t_end) {
  ASSERT_EQ(r.exit_code, 0) << r.summary.dump(2);
  ASSERT_EQ(r.summary["status"], "ok");
  ASSERT_FALSE((r.rows() == 0));
  EXPECT_DOUBLE_EQ(r.data[0].back(), t_end);
}

// --- References ---------------------------------------------------------------------------------

Matrix3d rx(double a) { return AngleAxisd(a, Vector3d::UnitX()).toRotationMatrix(); }
Matrix3d ry(double a) { return AngleAxisd(a, Vector3d::UnitY()).toRotationMatrix(); }
Matrix3d rz(double a) { return AngleAxisd(a, Vector3d::UnitZ()).toRotationMatrix(); }

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::fabs(a[i] - b[i]));
  return m;
}

// Largest |E(t) - E(0)| of kinetic + potential, relative to the largest kinetic energy reached
// (the energy the motion exchanges; |E| itself depends on the choice of the potential's zero).
double relative_energy_drift(const std::vector<double>& kinetic, const std::vector<double>& potential) {
  const double e0 = kinetic[0] + potential[0];
  double drift = 0, ke_max = 0;
  for (size_t i = 0; i < kinetic.size(); ++i) {
    drift = std::max(drift, std::fabs(kinetic[i] + potential[i] - e0));
    ke_max = std::max(ke_max, kinetic[i]);
  }
  return drift / ke_max;
}

TEST(Reference, EllipticIntegralByAgm) {
  EXPECT_NEAR(elliptic_k(0.0), kPi / 2, 1e-16);
  // K(1/sqrt 2) = Gamma(1/4)^2 / (4 sqrt(pi)).
  EXPECT_NEAR(elliptic_k(std::sqrt(0.5)), std::pow(std::tgamma(0.25), 2) / (4 * std::sqrt(kPi)), 2e-15);
}

// --- a. Compound pendulum ------------------------------------------------------------------------

// compound_pendulum.yaml's pendulum, computed here from its constants: a rotation about a fixed
// axis, I theta'' = -m g_perp d sin(theta - theta_eq).
struct CompoundPendulumReference {
  double i_hinge, stiffness, theta_eq, amplitude, period;
};
CompoundPendulumReference compound_pendulum_reference() {
  // Hinge = y axis of a base frame turned by Rz(30 deg) Rx(25 deg).
  const double m = 2.5, g = 9.81, amplitude = 60 * kDeg;
  const Vector3d com(0.15, 0.08, -0.4);  // from the hinge, pendulum axes
  Matrix3d inertia;                      // about the centre of mass, pendulum axes
  inertia << 0.05, 0.004, 0.006, 0.004, 0.04, -0.003, 0.006, -0.003, 0.03;
  const Matrix3d base = rz(30 * kDeg) * rx(25 * kDeg);
  const Vector3d axis = Vector3d::UnitY();  // in base (and pendulum) axes

  // Only the gravity and centre-of-mass components across the axis count. I = a.J a + m d^2
  // about the hinge; the equilibrium turns c_perp onto g_perp.
  const Vector3d g_base = base.transpose() * Vector3d(0, 0, -g);
  const Vector3d g_perp = g_base - g_base.dot(axis) * axis;
  const Vector3d c_perp = com - com.dot(axis) * axis;
  const double d = c_perp.norm();
  CompoundPendulumReference ref;
  ref.i_hinge = axis.dot(inertia * axis) + m * d * d;
  ref.theta_eq = std::atan2(axis.dot(c_perp.cross(g_perp)), c_perp.dot(g_perp));
  ref.stiffness = m * g_perp.norm() * d;
  ref.amplitude = amplitude;
  ref.period = 4.0 * std::sqrt(ref.i_hinge / ref.stiffness) * elliptic_k(std::sin(amplitude / 2));
  return ref;
}

// Period from the downward crossings of theta - theta_eq.
double measured_period(const mbdae::Result& r, double theta_eq) {
  const auto t = series(r, "t"), theta = series(r, "theta"), rate = series(r, "theta_rate");
  std::vector<double> u(theta.size());
  for (size_t i = 0; i < u.size(); ++i) u[i] = theta[i] - theta_eq;
  const std::vector<double> crossings = downward_crossings(t, u, rate);
  if (crossings.size() < 6) {
    ADD_FAILURE() << "only " << crossings.size() << " crossings";
    return 0;
  }
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

TEST(CompoundPendulum, PeriodMatchesEllipticIntegral) {
  const CompoundPendulumReference ref = compound_pendulum_reference();
  const double i_hinge = ref.i_hinge, stiffness = ref.stiffness, theta_eq = ref.theta_eq;
  const double amplitude = ref.amplitude, period = ref.period;

  const mbdae::Result r = run("compound_pendulum.yaml");
  expect_ran_to(r, 10.5);
  const auto t = series(r, "t"), theta = series(r, "theta"), rate = series(r, "theta_rate");
  const auto kinetic = series(r, "kinetic"), potential = series(r, "potential");
  ASSERT_NEAR(theta[0], theta_eq + amplitude, 1e-12) << "scene and test disagree on the start";
  ASSERT_EQ(rate[0], 0.0);

  std::vector<double> u(theta.size());
  for (size_t i = 0; i < u.size(); ++i) u[i] = theta[i] - theta_eq;
  const double measured = measured_period(r, theta_eq);
  const double rel = (measured - period) / period;
  std::printf("  period: exact %.15f s, measured %.15f s, relative error %.3e\n", period, measured, rel);
  EXPECT_LT(std::fabs(rel), 1e-8);

  // The energy sensors against the same reference: T = 1/2 I theta'^2 and
  // V - V(0) = m g_perp d (cos(amplitude) - cos(theta - theta_eq)).
  const double scale = stiffness * (1 - std::cos(amplitude));  // largest kinetic energy
  double ke_err = 0, pe_err = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    ke_err = std::max(ke_err, std::fabs(kinetic[i] - 0.5 * i_hinge * rate[i] * rate[i]));
    pe_err = std::max(pe_err, std::fabs(potential[i] - potential[0] -
                                        stiffness * (std::cos(amplitude) - std::cos(u[i]))));
  }
  std::printf("  energy sensors vs 1/2 I w^2 and m g d (cos A - cos u): %.3e, %.3e (relative to %.4f J)\n",
              ke_err / scale, pe_err / scale, scale);
  EXPECT_LT(ke_err / scale, 1e-10);
  EXPECT_LT(pe_err / scale, 1e-10);
  expect_clean_integration(r, "compound pendulum");
}

// The same pendulum started at its equilibrium angle with the rate that carries it to the same
// 60 deg amplitude, from the scene field `initial_velocities`: theta'(0)^2 = 2 m g_perp d
// (1 - cos A) / I. Same period, and the rate at t = 0 is the one asked for.
TEST(CompoundPendulum, InitialVelocityGivesTheSameSwing) {
  const CompoundPendulumReference ref = compound_pendulum_reference();
  const double rate0 = std::sqrt(2 * ref.stiffness * (1 - std::cos(ref.amplitude)) / ref.i_hinge);
  std::string scene = scene_text("compound_pendulum.yaml");
  const std::string start = "theta: {initial_deg: 80.556045219583467}";
  const size_t at = scene.find(start);
  ASSERT_NE(at, std::string::npos);
  char buf[160];
  std::snprintf(buf, sizeof buf, "theta: {initial: %.17g}", ref.theta_eq);
  scene.replace(at, start.size(), buf);
  const std::string step = "{type: dynamics, ";
  const size_t st = scene.rfind(step);
  ASSERT_NE(st, std::string::npos);
  std::snprintf(buf, sizeof buf, "{type: dynamics, initial_velocities: {theta: %.17g}, ", rate0);
  scene.replace(st, step.size(), buf);
  const mbdae::Result r = run_text(scene, "compound_pendulum.yaml", true);
  expect_ran_to(r, 10.5);
  const auto theta = series(r, "theta"), rate = series(r, "theta_rate");
  EXPECT_NEAR(theta[0], ref.theta_eq, 1e-12);
  EXPECT_NEAR(rate[0], rate0, 1e-12 * rate0);
  EXPECT_NEAR(integration_step(r)["initial_velocities"]["theta"].get<double>(), rate0, 1e-12 * rate0);
  double largest = 0;
  for (double x : theta) largest = std::max(largest, x - ref.theta_eq);
  const double measured = measured_period(r, ref.theta_eq);
  std::printf("  from theta'(0) = %.12f rad/s: amplitude %.12f deg (60), period %.15f s (exact %.15f)\n",
              rate0, largest / kDeg, measured, ref.period);
  EXPECT_NEAR(largest, ref.amplitude, 1e-6);  // the samples are 2 ms apart: the top is between them
  EXPECT_LT(std::fabs(measured - ref.period) / ref.period, 1e-8);
  expect_clean_integration(r, "compound pendulum from an initial velocity");
}

// slider_crank.yaml with the crank free at phi = 0.6 rad: the crank's rate alone sets every
// velocity (one degree of freedom), x' = -r w sin(phi) - r^2 w sin(phi) cos(phi) / sqrt(l^2 -
// r^2 sin^2(phi)); a rate of x as well over-determines the motion and is refused.
std::string free_slider_crank(const std::string& rates) {
  std::string scene = scene_text("slider_crank.yaml");
  const std::string driven = "phi: {initial: 0, mode: driven, drive: {type: polynomial, coefficients: [0, 6.283185307179586]}}";
  const size_t at = scene.find(driven);
  if (at == std::string::npos) return "";
  scene.replace(at, driven.size(), "phi: {initial: 0.6}");
  const size_t an = scene.find("analysis:");
  scene = scene.substr(0, an) + "analysis:\n  - {type: assembly, hold: [phi]}\n"
          "  - {type: dynamics, t_end: 0.01, output_step: 0.001, rtol: 1.0e-12, atol: 1.0e-14, initial_velocities: {" +
          rates + "}}\n";
  return scene;
}

TEST(SliderCrank, InitialCrankRateSetsThePistonRate) {
  const std::string scene = free_slider_crank("phi: 6.283185307179586");
  ASSERT_FALSE(scene.empty());
  const mbdae::Result r = run_text(scene, "slider_crank.yaml", false);
  ASSERT_EQ(r.exit_code, 0) << r.summary.dump(2);
  const double rr = 0.1, l = 0.35, w = 2 * kPi, phi = 0.6;
  const double sn = std::sin(phi), cs = std::cos(phi);
  const double x_rate = -rr * w * sn - rr * rr * w * sn * cs / std::sqrt(l * l - rr * rr * sn * sn);
  const auto x = series(r, "x"), rate = series(r, "x_rate");
  std::printf("  piston rate at phi = 0.6 rad, phi' = 2 pi: %.15f m/s (exact %.15f)\n", rate[0], x_rate);
  EXPECT_NEAR(x[0], rr * cs + std::sqrt(l * l - rr * rr * sn * sn), 1e-12);
  EXPECT_NEAR(rate[0], x_rate, 1e-12);
  EXPECT_NEAR(integration_step(r)["initial_velocities"]["phi"].get<double>(), w, 1e-12);
}

TEST(SliderCrank, InitialRatesBeyondTheDegreesOfFreedomAreRefused) {
  const std::string scene = free_slider_crank("phi: 6.283185307179586, x: 1.0");
  ASSERT_FALSE(scene.empty());
  const mbdae::Result r = run_text(scene, "slider_crank.yaml", false);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.summary["status"], "inconsistent_initial_velocities") << r.summary.dump(2);
  const std::string message = r.summary.value("message", "");
  EXPECT_NE(message.find("initial rate of"), std::string::npos) << message;
}

// --- b. Spatial double pendulum ---------------------------------------------------------------

TEST(SpatialDoublePendulum, EnergyIsConserved) {
  const mbdae::Result r = run("double_pendulum.yaml");
  expect_ran_to(r, 10.0);
  const auto kinetic = series(r, "kinetic"), potential = series(r, "potential");

  // double_pendulum.yaml: potential energy at the start from the joint angles (R1 R2 at the
  // shoulder, R1 R2 R3 at the elbow: rotations about the current x, y, z axes).
  const double g = 9.81, m1 = 1.5, m2 = 1.0;
  const Vector3d pivot(0, 0, 1), c1(0.02, 0.03, -0.25), elbow(0.01, -0.02, -0.5), c2(0.03, -0.02, -0.2);
  const Matrix3d a1 = rx(50 * kDeg) * ry(-30 * kDeg);
  const Matrix3d a2 = a1 * rx(20 * kDeg) * ry(40 * kDeg) * rz(10 * kDeg);
  const double v0 = g * (m1 * (pivot + a1 * c1).z() + m2 * (pivot + a1 * elbow + a2 * c2).z());
  EXPECT_NEAR(potential[0], v0, 1e-12 * std::fabs(v0));
  EXPECT_EQ(kinetic[0], 0.0);

  // The motion is spatial: the lower link's centre of mass moves in all three directions.
  for (const char* c : {"lower_x", "lower_y", "lower_z"}) {
    const auto s = series(r, c);
    const auto [lo, hi] = std::minmax_element(s.begin(), s.end());
    EXPECT_GT(*hi - *lo, 0.1) << c;
  }

  const double drift = relative_energy_drift(kinetic, potential);
  std::printf("  energy: max |E - E0| / max kinetic energy = %.3e (E0 = %.6f J, max kinetic %.6f J)\n",
              drift, kinetic[0] + potential[0], *std::max_element(kinetic.begin(), kinetic.end()));
  EXPECT_LT(drift, 1e-8);
  expect_clean_integration(r, "double pendulum");
}

// --- c. Slider-crank ----------------------------------------------------------------------------

TEST(SliderCrank, PistonFollowsClosedForm) {
  const mbdae::Result r = run("slider_crank.yaml");
  const double w = 2 * kPi, crank = 0.1, rod = 0.35;
  expect_ran_to(r, 2.0);  // two revolutions
  const auto t = series(r, "t");
  std::vector<double> x_ref, v_ref;
  for (double ti : t) {
    const double s = std::sin(w * ti), c = std::cos(w * ti), root = std::sqrt(rod * rod - crank * crank * s * s);
    x_ref.push_back(crank * c + root);
    v_ref.push_back(-crank * w * s - crank * crank * w * s * c / root);
  }
  const double ex = max_abs_diff(series(r, "x"), x_ref);
  const double ep = max_abs_diff(series(r, "piston_x"), x_ref);
  const double ev = max_abs_diff(series(r, "x_rate"), v_ref);
  std::printf("  piston: max |x - x_exact| = %.3e m (coordinate), %.3e m (point), max |x' - x'_exact| = %.3e m/s\n",
              ex, ep, ev);
  EXPECT_LT(ex, 1e-10);
  EXPECT_LT(ep, 1e-10);
  EXPECT_LT(ev, 1e-9);  // r w = 0.63 m/s
  expect_clean_integration(r, "slider-crank");
}

// --- e. Invalid scenes through the executable ------------------------------------------------------

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

CommandResult run_command(const std::string& command) {
  CommandResult r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// 1-based number of the first line of a file containing `needle` (0 if none).
int line_containing(const std::string& path, const std::string& needle) {
  std::ifstream in(path);
  std::string line;
  for (int k = 1; std::getline(in, line); ++k)
    if (line.find(needle) != std::string::npos) return k;
  return 0;
}

CommandResult run_mbdae(const std::string& scene, const std::string& out_name) {
  const std::string out = std::string(MBDAE_TEST_OUTPUT_DIR) + "/" + out_name;
  return run_command("'" + std::string(MBDAE_EXECUTABLE) + "' run '" + scene_path(scene) + "' --out '" + out +
                     "' --quiet");
}

TEST(InvalidScene, JointNamingAMissingBody) {
  const std::string path = scene_path("error_missing_body.yaml");
  const int line = line_containing(path, "parent: ulpper");
  ASSERT_GT(line, 0);
  const CommandResult r = run_mbdae("error_missing_body.yaml", "error_missing_body");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":" + std::to_string(line) + ":"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("field 'parent'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'ulpper'"), std::string::npos) << r.output;
}

TEST(InvalidScene, UnknownField) {
  const std::string path = scene_path("error_unknown_field.yaml");
  const int line = line_containing(path, "colour: red");
  ASSERT_GT(line, 0);
  const CommandResult r = run_mbdae("error_unknown_field.yaml", "error_unknown_field");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":" + std::to_string(line) + ":"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("field 'colour'"), std::string::npos) << r.output;
}

// --- f. Spring energy and a user force law ------------------------------------------------------

TEST(SpringBody, EnergyIsConserved) {
  const mbdae::Result r = run("spring_body.yaml");
  expect_ran_to(r, 3.0);
  const auto kinetic = series(r, "kinetic"), potential = series(r, "potential");

  // spring_body.yaml at the start: frame origin (x, y, z), orientation Rx Ry Rz (free joint
  // T1 T2 T3 R1 R2 R3); hook on a support welded to ground at (0, 0, 1).
  const double g = 9.81, m = 1.2, k = 400, free_length = 0.3;
  const Vector3d origin(0.25, 0.1, 0.55), com(0.01, 0.02, -0.03), eye(0.03, -0.02, 0.08);
  const Vector3d hook = Vector3d(0, 0, 1) + Vector3d(0.1, -0.05, 0.3);
  const Matrix3d a = rx(20 * kDeg) * ry(-15 * kDeg) * rz(30 * kDeg);
  const double length = (origin + a * eye - hook).norm();
  const double v0 = m * g * (origin + a * com).z() + 0.5 * k * (length - free_length) * (length - free_length);
  EXPECT_NEAR(series(r, "spring_length")[0], length, 1e-14);
  EXPECT_NEAR(potential[0], v0, 1e-12 * std::fabs(v0));
  EXPECT_EQ(kinetic[0], 0.0);

  const double drift = relative_energy_drift(kinetic, potential);
  std::printf("  energy: max |E - E0| / max kinetic energy = %.3e (E0 = %.6f J, max kinetic %.6f J)\n",
              drift, kinetic[0] + potential[0], *std::max_element(kinetic.begin(), kinetic.end()));
  EXPECT_LT(drift, 1e-8);
  expect_clean_integration(r, "spring body");
}

TEST(UserForceLaw, LinearBushingMatchesDampedOscillator) {
  const mbdae::Result r = run("bushing.yaml");
  expect_ran_to(r, 2.0);
  // bushing.yaml: m x'' + c x' + k x = m g per direction, from rest at x0.
  const double m = 2.0, k = 800, c = 4, g = 9.81;
  const double w = std::sqrt(k / m), zeta = c / (2 * std::sqrt(k * m)), wd = w * std::sqrt(1 - zeta * zeta);
  const Vector3d x0(0.1, -0.05, 0.2), eq(0, 0, -m * g / k);
  const auto t = series(r, "t");
  const std::vector<double> pos[3] = {series(r, "x"), series(r, "y"), series(r, "z")};
  const auto vz = series(r, "vz"), potential = series(r, "potential");
  double e_pos = 0, e_vel = 0, e_pot = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double decay = std::exp(-zeta * w * t[i]), cw = std::cos(wd * t[i]), sw = std::sin(wd * t[i]);
    for (int j = 0; j < 3; ++j) {
      const double ref = eq[j] + (x0[j] - eq[j]) * decay * (cw + zeta * w / wd * sw);
      e_pos = std::max(e_pos, std::fabs(pos[j][i] - ref));
    }
    const double vref = -(x0[2] - eq[2]) * decay * (w * w / wd) * sw;
    e_vel = std::max(e_vel, std::fabs(vz[i] - vref));
    // User laws add nothing to the potential energy: gravity only.
    e_pot = std::max(e_pot, std::fabs(potential[i] - m * g * pos[2][i]));
  }
  std::printf("  bushing: max position error %.3e m, max velocity error %.3e m/s, potential - m g z %.3e J\n",
              e_pos, e_vel, e_pot);
  EXPECT_LT(e_pos, 1e-9);   // amplitude 0.22 m
  EXPECT_LT(e_vel, 1e-8);   // amplitude 4.3 m/s
  EXPECT_LT(e_pot, 1e-12);
  expect_clean_integration(r, "linear bushing");
}

}  // namespace
