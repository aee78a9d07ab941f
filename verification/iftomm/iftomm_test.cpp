// IFToMM / MBSBenchmark problems A01, A02, A04, A05 (verification/iftomm/scenes/) run as a user
// runs them (load_scene + run) and compared with references that do not come from mbdae:
//   A01  the exact solution of the pendulum (Jacobi sn by the arithmetic-geometric mean);
//   A02  M theta'' = -C cos(theta), the parallelogram's one-degree-of-freedom equation,
//        integrated here by RK4 with tiny steps;
//   A04  the closed-form relation between the joint angles, and the libration period and point
//        table of docs/iftomm-benchmarks-sources.md section 3.2 (computed there independently);
//   A05  conservation of the angular momentum about the shaft, the initial energy, and the s(t)
//        table of docs/iftomm-benchmarks-sources.md section 4.2 (RK4 on a 4-DOF Lagrangian).
// The benchmark's error measure where it is published (A01, A02): the largest error of the
// reported coordinates over the output samples, against 1e-3 ("high precision"). Each test also
// asserts a tighter bound near what mbdae achieves, so that a loss of accuracy is seen.
// Where a run is shortened (A01: the IFToMM version's 10 s instead of 2000 s; A02: 5 s, five
// singular configurations, instead of 20 s; A02 at index 3: up to the first singular
// configuration), the full runs are in verification/iftomm/make_table.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cases/mbdae.h"
#include "cases/scene/scene.h"
#include "verification/iftomm/pendulum_exact.h"

namespace {

using mbdae::PendulumExact;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;

std::string scene_path(const std::string& name) {
  return std::string(MBDAE_SOURCE_DIR) + "/verification/iftomm/scenes/" + name;
}

mbdae::AnalysisStep& integration_step(mbdae::Scene& scene) {
  for (auto& s : scene.steps)
    if (s.type == mbdae::AnalysisStep::Type::kDynamics) return s;
  throw std::runtime_error("no dynamics step");
}

// Runs a scene, optionally with another end time and output step (0: as in the scene).
mbdae::Result run(const std::string& name, double t_end = 0, double output_step = 0) {
  mbdae::Scene scene = mbdae::load_scene(scene_path(name));
  mbdae::AnalysisStep& step = integration_step(scene);
  if (t_end > 0) step.t_end = t_end;
  if (output_step > 0) step.output_step = output_step;
  mbdae::RunOptions o;
  o.verbose = false;
  o.progress = false;
  return mbdae::run(scene, o);
}

// One output column (Result::column throws, and the test fails, naming a missing column).
const std::vector<double>& series(const mbdae::Result& r, const std::string& name) { return r.column(name); }

// Index of the sample at time t (the output grid contains it), or -1.
int sample_at(const std::vector<double>& t, double time) {
  for (size_t i = 0; i < t.size(); ++i)
    if (std::fabs(t[i] - time) < 1e-9) return static_cast<int>(i);
  return -1;
}

const nlohmann::ordered_json& statistics(const mbdae::Result& r) {
  for (const auto& s : r.summary["steps"])
    if (s["type"] == "dynamics") return s["statistics"];
  static const nlohmann::ordered_json none;
  return none;
}

void expect_ran_to(const mbdae::Result& r, double t_end) {
  ASSERT_EQ(r.exit_code, 0) << r.summary.dump(2);
  ASSERT_EQ(r.summary["status"], "ok");
  ASSERT_FALSE((r.rows() == 0));
  EXPECT_NEAR(r.data[0].back(), t_end, 1e-12);
  const auto& st = statistics(r);
  std::printf("  %ld steps, %ld residual evaluations, %ld KLU factorizations, cpu %.3f s\n",
              st["steps"].get<long>(), st["residual_evaluations"].get<long>(),
              st["klu_factorizations"].get<long>(), st["cpu_seconds"].get<double>());
}

// --- References ---------------------------------------------------------------------------------

// A02 on the parallelogram branch: M theta'' = -C cos(theta), theta(0) = pi/2, theta'(0) = -1,
// M = (N+1) m L^2 / 3 + N m L^2, C = m g L ((N+1)/2 + N) (m = 1 kg, L = 1 m). Classical RK4 with
// step h; returns (theta, theta') at each requested time (increasing, multiples of h).
std::vector<std::pair<double, double>> four_bar_reference(int n, const std::vector<double>& times, double h = 1e-4) {
  const double big_m = (n + 1) / 3.0 + n, c = kG * ((n + 1) / 2.0 + n);
  auto acc = [&](double th) { return -c * std::cos(th) / big_m; };
  std::vector<std::pair<double, double>> out;
  double th = kPi / 2, w = -1, t = 0;
  for (double target : times) {
    while (t < target - 1e-12) {
      const double hh = std::min(h, target - t);
      const double k1x = w, k1v = acc(th);
      const double k2x = w + 0.5 * hh * k1v, k2v = acc(th + 0.5 * hh * k1x);
      const double k3x = w + 0.5 * hh * k2v, k3v = acc(th + 0.5 * hh * k2x);
      const double k4x = w + hh * k3v, k4v = acc(th + hh * k3x);
      th += hh / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      w += hh / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      t += hh;
    }
    out.push_back({th, w});
  }
  return out;
}

// Times where u crosses zero in the direction `sign` (+1 up, -1 down), from samples t_i, u_i,
// u'_i: the cubic Hermite interpolant on each bracketing interval, solved by bisection.
std::vector<double> crossings(const std::vector<double>& t, const std::vector<double>& u,
                              const std::vector<double>& du, int sign) {
  std::vector<double> out;
  for (size_t i = 0; i + 1 < t.size(); ++i) {
    if (!(sign * u[i] < 0 && sign * u[i + 1] >= 0)) continue;
    const double h = t[i + 1] - t[i];
    auto p = [&](double s) {
      const double s2 = s * s, s3 = s2 * s;
      return (2 * s3 - 3 * s2 + 1) * u[i] + (s3 - 2 * s2 + s) * h * du[i] + (-2 * s3 + 3 * s2) * u[i + 1] +
             (s3 - s2) * h * du[i + 1];
    };
    double lo = 0, hi = 1;
    for (int k = 0; k < 80; ++k) {
      const double mid = 0.5 * (lo + hi);
      (sign * p(mid) < 0 ? lo : hi) = mid;
    }
    out.push_back(t[i] + 0.5 * (lo + hi) * h);
  }
  return out;
}

// Number of redundant equations reported, and how many of them name each kind of equation.
int redundant_count(const mbdae::Result& r) {
  return static_cast<int>(r.summary["redundant_constraints"]["redundant"].size());
}

TEST(Reference, JacobiSnMatchesTheResearchNotes) {
  const PendulumExact p;
  // K(1/sqrt 2) = Gamma(1/4)^2 / (4 sqrt(pi)); the notes' period and table (section 1.2).
  EXPECT_NEAR(p.agm.complete_k(), std::pow(std::tgamma(0.25), 2) / (4 * std::sqrt(kPi)), 1e-15);
  EXPECT_NEAR(p.period(), 2.367841947576237, 1e-14);
  const double table[][3] = {{0.5, 0.391048791551, -0.920369948785},  {1, -0.986291751132, -0.165010853126},
                             {5, 0.942305435044, -0.334754338414},    {9.99, 0.316436469913, -0.948613704576},
                             {10, 0.275087462576, -0.961419205099},   {20, -0.996907173991, -0.078588080809}};
  for (const auto& row : table) {
    EXPECT_NEAR(p.x(row[0]), row[1], 2e-12) << "t = " << row[0];
    EXPECT_NEAR(p.y(row[0]), row[2], 2e-12) << "t = " << row[0];
  }
  // 2000 s (given to 10 digits): the sn argument is large, phase accuracy matters.
  EXPECT_NEAR(p.x(2000), -0.8146030686, 2e-9);
  EXPECT_NEAR(p.y(2000), -0.5800188278, 2e-9);
}

TEST(Reference, FourBarEquationMatchesTheResearchNotes) {
  // Section 2.2, N = 40: B0 = (cos theta, sin theta), given to 10 digits.
  const std::vector<double> times = {0.5, 1.0, 5.0, 15.0, 20.0};
  const double x_ref[] = {0.6879259708, -0.1153568806, -0.5401900507, -0.9998781771, 0.4109011537};
  const double vy_ref[] = {-1.8285420937, 0.7746000987, 3.4896283652, 4.8433168598, -0.7061622355};
  const auto ref = four_bar_reference(40, times);
  for (size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(std::cos(ref[i].first), x_ref[i], 1e-9) << "t = " << times[i];
    EXPECT_NEAR(std::cos(ref[i].first) * ref[i].second, vy_ref[i], 1e-8) << "t = " << times[i];
  }
}

// --- A01 simple pendulum --------------------------------------------------------------------------

TEST(A01SimplePendulum, MatchesExactSolution) {
  // The IFToMM version's 10 s, with the specification's 4000 output steps.
  const mbdae::Result r = run("A01_simple_pendulum.yaml", 10.0, 10.0 / 4000);
  expect_ran_to(r, 10.0);
  EXPECT_EQ(redundant_count(r), 0);
  const auto t = series(r, "t"), x = series(r, "x_P1"), y = series(r, "y_P1"), e = series(r, "energy");
  ASSERT_EQ(t.size(), 4001u);
  EXPECT_EQ(x[0], 1.0);
  EXPECT_EQ(y[0], 0.0);
  const PendulumExact p;
  double err = 0, t_worst = 0, e_err = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double ei = std::max(std::fabs(x[i] - p.x(t[i])), std::fabs(y[i] - p.y(t[i])));
    if (ei > err) err = ei, t_worst = t[i];
    e_err = std::max(e_err, std::fabs(e[i]));  // E = 0 exactly (potential zero at the pivot)
  }
  std::printf("  A01 (10 s, 4000 samples): max |P1 - P1_exact| = %.3e m at t = %.4f s; max |E| = %.3e J\n", err,
              t_worst, e_err);
  EXPECT_LT(err, 1e-3);  // benchmark, high precision
  EXPECT_LT(err, 1e-6);  // what rtol 1e-13 gives (about 1e-7)
  EXPECT_LT(e_err, 1e-5);
}

// The tolerance's promise (issue 13) on A01's 10 s at the default tolerances (rtol 1e-6, atol from
// the model's scales): index3 keeps P1's position and velocity within 10 rtol of their scales
// (L = 1 m and sqrt(2 g L) = 4.43 m/s). Exact velocity: central differences of the exact
// position (h = 1e-6 s: about 1e-10 m/s). Measured 1.9e-6 of both scales (docs/work-precision.md).
TEST(A01SimplePendulum, DefaultTolerancesKeepThePromise) {
  mbdae::Scene scene = mbdae::load_scene(scene_path("A01_simple_pendulum.yaml"));
  mbdae::AnalysisStep& step = integration_step(scene);
  step.t_end = 10.0;
  step.output_step = 0.01;
  step.rtol = 1e-6;
  step.atol = 0;  // the model's default
  const mbdae::Result r = mbdae::run(scene, mbdae::RunOptions{});
  expect_ran_to(r, 10.0);
  const auto t = series(r, "t"), x = series(r, "x_P1"), y = series(r, "y_P1");
  const auto vx = series(r, "vx_P1"), vy = series(r, "vy_P1");
  const PendulumExact p;
  const double d = 1e-6, v_scale = std::sqrt(2 * kG * p.length);
  double ep = 0, ev = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    ep = std::max({ep, std::fabs(x[i] - p.x(t[i])), std::fabs(y[i] - p.y(t[i]))});
    const double vx_exact = (p.x(t[i] + d) - p.x(t[i] - d)) / (2 * d);
    const double vy_exact = (p.y(t[i] + d) - p.y(t[i] - d)) / (2 * d);
    ev = std::max({ev, std::fabs(vx[i] - vx_exact), std::fabs(vy[i] - vy_exact)});
  }
  std::printf("  A01 (10 s, rtol 1e-6, default atol): position error %.3g of 1 m, velocity error %.3g of %.3g m/s\n",
              ep, ev / v_scale, v_scale);
  EXPECT_LT(ep / p.length, 10 * step.rtol);
  EXPECT_LT(ev / v_scale, 10 * step.rtol);
}

// --- A02 N four-bar -------------------------------------------------------------------------------

// The first horizontal (singular) configuration of the N = 40 mechanism is at t = 0.7216 s
// (docs/iftomm-benchmarks-sources.md, section 2.2).
constexpr double kA02FirstSingular = 0.721581024826;

// The benchmark's initial state (docs/iftomm-benchmarks-sources.md section 2.1): cranks vertical,
// theta0 = pi/2, B0 = (0, 1) m with velocity (1, 0) m/s. On the parallelogram branch every crank
// turns at the same rate w and B0 = L (cos theta, sin theta), so B0' = L w (-sin theta, cos theta):
// the scene's one given rate, of crank 0, must be w = -vx_B0 / (L sin theta0) = -1 rad/s.
constexpr double kA02Theta0 = kPi / 2, kA02VxB0 = 1.0, kA02VyB0 = 0.0;

// The state at t = 0 (the scene's initial_velocities): B0's position and the specified
// velocity, every crank at the same rate, and the rate mbdae reports as given.
void check_four_bar_start(const mbdae::Result& r) {
  const auto t = series(r, "t"), x = series(r, "x_B0"), y = series(r, "y_B0");
  const auto vx = series(r, "vx_B0"), vy = series(r, "vy_B0");
  const auto w0 = series(r, "rate0"), w_mid = series(r, "rate_mid"), w_last = series(r, "rate_last");
  ASSERT_FALSE(t.empty());
  ASSERT_EQ(t[0], 0.0);
  const double w = -kA02VxB0 / std::sin(kA02Theta0);  // L = 1 m
  std::printf("  t = 0: B0 = (%.3e, 1 %+.3e), v_B0 = (1 %+.3e, %.3e); crank rates %.15f, %.15f, %.15f\n", x[0],
              y[0] - 1, vx[0] - 1, vy[0], w0[0], w_mid[0], w_last[0]);
  EXPECT_NEAR(x[0], std::cos(kA02Theta0), 1e-12);
  EXPECT_NEAR(y[0], std::sin(kA02Theta0), 1e-12);
  EXPECT_NEAR(vx[0], kA02VxB0, 1e-12);
  EXPECT_NEAR(vy[0], kA02VyB0, 1e-12);
  EXPECT_NEAR(w * -std::sin(kA02Theta0), kA02VxB0, 1e-15);  // B0' = L w (-sin, cos) from w
  EXPECT_NEAR(w * std::cos(kA02Theta0), kA02VyB0, 1e-15);
  EXPECT_NEAR(w0[0], w, 1e-12);
  EXPECT_NEAR(w_mid[0], w, 1e-12);
  EXPECT_NEAR(w_last[0], w, 1e-12);
  for (const auto& s : r.summary["steps"]) {
    if (s["type"] == "dynamics") {
      EXPECT_NEAR(s["initial_velocities"]["th0"].get<double>(), w, 1e-12);
    }
  }
}

// `bias`: the constraint violation the formulation allows by construction (0 for the exact
// index-3 constraints; the penalty formulation's |lambda| / (p beta^2), formulation/index1_dae.h),
// added to the bound that compares with exact kinematics (crank angle spread).
void check_four_bar(const mbdae::Result& r, int n, double t_end, double tight, double bias = 0) {
  EXPECT_EQ(redundant_count(r), 3 * n) << r.summary["redundant_constraints"].dump(1);
  EXPECT_EQ(r.summary["redundant_constraints"]["equations"].get<int>(), 5 * (3 * n + 1) + 2 * n + 1);
  EXPECT_EQ(r.summary["redundant_constraints"]["rank"].get<int>(), 5 * (3 * n + 1) + 2 * n + 1 - 3 * n);
  const auto t = series(r, "t"), x = series(r, "x_B0"), y = series(r, "y_B0");
  const auto vx = series(r, "vx_B0"), vy = series(r, "vy_B0"), e = series(r, "energy");
  const auto th0 = series(r, "theta0"), th_last = series(r, "theta_last"), th_mid = series(r, "theta_mid");
  check_four_bar_start(r);
  const std::vector<double>& times = t;
  const auto ref = four_bar_reference(n, times);
  const double e0 = 0.5 * ((n + 1) / 3.0 + n) + kG * ((n + 1) / 2.0 + n);  // 1/2 M + C
  double ep = 0, ev = 0, ee = 0, spread = 0;
  for (size_t i = 0; i < times.size(); ++i) {
    const double th = ref[i].first, w = ref[i].second;
    ep = std::max({ep, std::fabs(x[i] - std::cos(th)), std::fabs(y[i] - std::sin(th))});
    ev = std::max({ev, std::fabs(vx[i] + std::sin(th) * w), std::fabs(vy[i] - std::cos(th) * w)});
    ee = std::max(ee, std::fabs(e[i] - e0));
    spread = std::max({spread, std::fabs(th_last[i] - th0[i]), std::fabs(th_mid[i] - th0[i])});
  }
  std::printf("  A02 N = %d to %.2f s (%zu samples): max |B0 - ref| = %.3e m, max |v_B0 - ref| = %.3e m/s, "
              "max |E - E0| = %.3e J (E0 = %.6f), crank angle spread %.3e rad\n",
              n, t_end, times.size(), ep, ev, ee, e0, spread);
  EXPECT_LT(ep, 1e-3);  // benchmark, high precision
  EXPECT_LT(ep, tight);
  EXPECT_LT(ee, 1e3 * tight);
  EXPECT_LT(spread, 1e-8 + 10 * bias);  // on the parallelogram branch (the other is O(1) away)
}

// Up to the first singular configuration (0.72 s). The run goes to 0.70 s, but only the samples
// up to 0.65 s are compared and required: close to the singular configuration, and on the last
// step before the end time (see docs/iftomm-benchmarks.md, engine findings), IDA may fail with
// IDA_CONV_FAIL, which is reported but not asserted here.
mbdae::Result run_before_singular(const std::string& name) {
  // The index-3 integration (exact constraints), with the scenes' tolerances and the Newton
  // convergence coefficient it was tuned with; the scenes themselves use the penalty formulation.
  mbdae::Scene scene = mbdae::load_scene(scene_path(name));
  mbdae::AnalysisStep& step = integration_step(scene);
  step.t_end = 0.70;
  step.formulation = "index3";
  step.newton_convergence = 0.001;
  // rtol 1e-11 (the scenes' 1e-10 / 10, atol = 1e-3 rtol as theirs): at 1e-10 the N = 2 error
  // at 0.65 s depends on IDA's step sequence at the 1e-6 m level (1.7e-7 to 1.1e-6 m for start
  // angles pi/2 + 1e-12 ... 1e-8 rad; velocities are out of the index-3 error test), at 1e-11 it
  // is 8.5e-10 m (N = 40: 9.6e-8 m).
  step.rtol = 1e-11;
  step.atol = 1e-14;
  mbdae::RunOptions o;
  o.verbose = false;
  o.progress = false;
  const mbdae::Result r = mbdae::run(scene, o);
  if (r.exit_code != 0)
    std::printf("  note: the run to 0.70 s stopped: %s\n", r.summary.value("message", std::string()).c_str());
  EXPECT_TRUE(r.exit_code == 0 || r.summary["status"] == "integration_failed");
  EXPECT_FALSE((r.rows() == 0));
  return r;
}

// The samples of r up to t_max.
mbdae::Result up_to(mbdae::Result r, double t_max) {
  while (!(r.rows() == 0) && r.data[0].back() > t_max + 1e-9) for (auto& col : r.data) col.pop_back();
  return r;
}

TEST(A02NFourBar, N40UpToTheFirstSingularConfiguration) {
  const double t_end = 0.65;
  ASSERT_LT(t_end, kA02FirstSingular);
  const mbdae::Result r = up_to(run_before_singular("A02_n_four_bar_N40.yaml"), t_end);
  ASSERT_NEAR(r.data[0].back(), t_end, 1e-9);
  check_four_bar(r, 40, t_end, 1e-6);
}

TEST(A02NFourBar, N2UpToTheFirstSingularConfiguration) {
  const double t_end = 0.65;  // N = 2: first singular configuration at 0.714 s
  const mbdae::Result r = up_to(run_before_singular("A02_n_four_bar_N2.yaml"), t_end);
  ASSERT_NEAR(r.data[0].back(), t_end, 1e-9);
  check_four_bar(r, 2, t_end, 1e-6);
}

// The benchmark proper (shortened to 5 s; the full 20 s run is in make_table.py): the mechanism
// passes the horizontal singular configuration (N extra instantaneous degrees of freedom) twice
// a revolution, the first at 0.72 s. The scene integrates the penalty formulation
// (formulation/index1_dae.h), whose Newton matrix stays regular there; index3, index2-ggl and
// index1 fail with IDA_CONV_FAIL at the first crossing (docs/iftomm-benchmarks.md).
TEST(A02NFourBar, N40PassesSingularConfigurations) {
  const double t_end = 5.0;
  const mbdae::Result r = run("A02_n_four_bar_N40.yaml", t_end);
  expect_ran_to(r, t_end);
  // Horizontal configurations passed: sign changes of y_B0 = sin(theta), against the reference.
  const auto t = series(r, "t"), y = series(r, "y_B0");
  const auto ref = four_bar_reference(40, t);
  int passed = 0, expected = 0;
  for (size_t i = 1; i < t.size(); ++i) {
    passed += (y[i - 1] > 0) != (y[i] > 0);
    expected += (std::sin(ref[i - 1].first) > 0) != (std::sin(ref[i].first) > 0);
  }
  std::printf("  horizontal configurations passed: %d (reference %d)\n", passed, expected);
  EXPECT_EQ(passed, expected);
  EXPECT_EQ(expected, 5);
  // bias: |lambda| / (p beta^2) with |lambda| up to about 1e3 N (the pivots carry the 81 bars'
  // weight, 795 N, and their centripetal loads), p = 1e7 kg, beta = 1000/s: 1e-10 m (measured:
  // constraint violation at most 1.5e-10 m over the 20 s, docs/iftomm-benchmarks.md).
  check_four_bar(r, 40, t_end, 1e-5, 1e-10);
}

// A formulation that cannot pass the singular configuration stops there at once, diagnosed: with
// index1 at rtol 1e-10 the steps collapsed to 3e-19 s near 0.7216 s (t + h == t) and the run
// crawled for 110000 steps and 2.5 min to the step budget, until IDA's smallest step became 16
// ulps of t (core/ida_driver.cpp). Now it fails after about 1600 steps.
TEST(A02NFourBar, N40Index1StopsAtTheSingularConfigurationWithoutCrawling) {
  mbdae::Scene scene = mbdae::load_scene(scene_path("A02_n_four_bar_N40.yaml"));
  mbdae::AnalysisStep& step = integration_step(scene);
  step.t_end = 1.0;
  mbdae::RunOptions o;
  o.verbose = false;
  o.progress = false;
  o.formulation = "index1-no-handover";  // index1 itself: "index1" runs as index2-ggl below rtol 1e-9
  o.rtol = 1e-10;
  const mbdae::Result r = mbdae::run(scene, o);
  EXPECT_EQ(r.status, "integration_failed") << r.message;
  EXPECT_NE(r.message.find("singular configuration at t = 0.7215"), std::string::npos) << r.message;
  const auto& last = r.summary["steps"].back();
  EXPECT_NEAR(last["t_reached"].get<double>(), kA02FirstSingular, 1e-6);
  EXPECT_LT(last["statistics"]["steps"].get<long>(), 10000);
}

// Engine bug found with these scenes (scenes/repro_end_step_conv_fail.yaml, generated by
// make_scenes.py): the A02 N = 40 four-bar at index 3 to 0.48 s at rtol 1e-11, atol 1e-13,
// newton_convergence 0.001 failed on its last step, the one IDA shortened to land on the end
// time (IDA_CONV_FAIL at t = 0.479828; 0.47 and 0.49 s completed; 0.24 s from the first singular
// configuration). Traced on the earlier scene (started from rest at -0.05 s, failing at 0.60 s):
// the shortened step converged but failed the error test once, and each smaller retry converged
// less well (index-3 condition ~ 1/h^2) than the Newton coefficient 0.001 asks. Fixed in
// core/ida_driver.cpp: the end of a run is a stop time only where the inputs have a breakpoint
// there; otherwise the last step goes past it and the end is interpolated.
TEST(EngineFindings, LastStepToTheEndTime) {
  mbdae::RunOptions o;
  o.verbose = false;
  o.progress = false;
  const mbdae::Result r = mbdae::run(mbdae::load_scene(scene_path("repro_end_step_conv_fail.yaml")), o);
  expect_ran_to(r, 0.48);
}

// --- A04 Bricard mechanism ----------------------------------------------------------------------

TEST(A04Bricard, OneRedundantEquationAndExactKinematics) {
  const mbdae::Result r = run("A04_bricard.yaml");
  expect_ran_to(r, 10.0);
  // 5 bodies: 35 coordinates; 6 revolutes (30) + 5 Euler norms; rank 34.
  const auto& rc = r.summary["redundant_constraints"];
  std::printf("  redundant: %s\n", rc["redundant"].dump().c_str());
  EXPECT_EQ(rc["equations"].get<int>(), 35);
  EXPECT_EQ(rc["rank"].get<int>(), 34);
  EXPECT_EQ(redundant_count(r), 1);
  EXPECT_EQ(r.summary["constraint_equations"].get<int>(), 34);

  const auto t = series(r, "t");
  std::vector<double> q[6];
  for (int k = 1; k <= 5; ++k) q[k] = series(r, "q" + std::to_string(k));
  const auto rate = series(r, "q1_rate"), e = series(r, "energy");

  // Closed form along the whole motion: q = (theta, phi, theta, phi, theta), sin(-phi) =
  // sin(theta) / (1 + sin(theta)).
  double rel = 0, ee = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double th = q[1][i], s = std::sin(th);
    rel = std::max({rel, std::fabs(q[3][i] - th), std::fabs(q[5][i] - th), std::fabs(q[4][i] - q[2][i]),
                    std::fabs(std::sin(-q[2][i]) - s / (1 + s))});
    ee = std::max(ee, std::fabs(e[i] - e[0]));
  }
  // Libration period: successive crossings of theta = pi/2 in the same direction.
  std::vector<double> u(t.size());
  for (size_t i = 0; i < t.size(); ++i) u[i] = q[1][i] - kPi / 2;
  const auto up = crossings(t, u, rate, +1), down = crossings(t, u, rate, -1);
  ASSERT_EQ(up.size(), 2u);
  ASSERT_EQ(down.size(), 2u);
  const double period_ref = 4.9917115137;  // notes, section 3.2 (box 0.1 m)
  const double period = 0.5 * ((up[1] - up[0]) + (down[1] - down[0]));
  // Point table (section 3.2): theta and P1..P4 at t.
  struct Row {
    double t, theta, p[12];
  };
  const Row table[] = {
      {0.5, 0.2525288405, {0.968283679, 0, -0.249853391, 0.774717808, -0.979815048, -0.199906159, 0.968283679,
                           -1.224625159, 0.750146609, 0, -0.979815048, 0.800093841}},
      {1.0, 1.0350284595, {0.510501461, 0, -0.859876885, 0.274481319, -0.886707939, -0.462330003, 0.510501461,
                           -1.649167599, 0.140123115, 0, -0.886707939, 0.537669997}},
      {1.5, 2.1149912645, {-0.517729492, 0, -0.855544372, -0.279017575, -0.887361379, -0.461074596, -0.517729492,
                           -1.646538413, 0.144455628, 0, -0.887361379, 0.538925404}},
      {2.5, 3.1415758387, {-1.000000000, 0, -0.000016815, -0.999983185, -1.000000000, -0.000016815, -1.000000000,
                           -1.000016815, 0.999983185, 0, -1.000000000, 0.999983185}},
      {5.0, 0.0000672600, {0.999999998, 0, -0.000067260, 0.999932742, -0.999999998, -0.000067255, 0.999999998,
                           -1.000067258, 0.999932740, 0, -0.999999998, 0.999932745}},
      {7.0, 2.9017436213, {-0.971373849, 0, -0.237555983, -0.784913057, -0.981403582, -0.191955747, -0.971373849,
                           -1.214541875, 0.762444017, 0, -0.981403582, 0.808044253}},
      {10.0, 0.0002690489, {0.999999964, 0, -0.000269049, 0.999730987, -0.999999964, -0.000268977, 0.999999964,
                            -1.000269013, 0.999730951, 0, -0.999999964, 0.999731023}}};
  const char* names[12] = {"P1x", "P1y", "P1z", "P2x", "P2y", "P2z", "P3x", "P3y", "P3z", "P4x", "P4y", "P4z"};
  std::vector<double> p[12];
  for (int k = 0; k < 12; ++k) p[k] = series(r, names[k]);
  double ep = 0, ep2 = 0, eth = 0;
  for (const Row& row : table) {
    const int i = sample_at(t, row.t);
    ASSERT_GE(i, 0);
    eth = std::max(eth, std::fabs(q[1][i] - row.theta));
    for (int k = 0; k < 12; ++k) ep = std::max(ep, std::fabs(p[k][i] - row.p[k]));
    for (int k = 3; k < 6; ++k) ep2 = std::max(ep2, std::fabs(p[k][i] - row.p[k]));
  }
  std::printf("  A04: joint-angle relation %.3e rad; period %.10f s (ref %.10f, error %.3e); "
              "max |theta - ref| %.3e; max |P - ref| %.3e m (P1..P4), %.3e m (P2, OpenSim's \"P3\"); "
              "max |E - E0| %.3e J\n",
              rel, period, period_ref, period - period_ref, eth, ep, ep2, ee);
  EXPECT_LT(rel, 1e-9);
  EXPECT_LT(std::fabs(period - period_ref), 1e-6);
  EXPECT_LT(ep, 1e-6);  // the table has 9 decimals; rtol 1e-11 gives about 7e-8
  EXPECT_LT(ee, 1e-5);
}

// --- A05 stiff flyball governor -----------------------------------------------------------------

TEST(A05StiffFlyballGovernor, SleeveMotionAndAngularMomentum) {
  const mbdae::Result r = run("A05_stiff_flyball_governor.yaml");
  expect_ran_to(r, 10.0);
  EXPECT_EQ(redundant_count(r), 0);
  const auto t = series(r, "t"), s = series(r, "s"), s_rate = series(r, "s_rate"), omega = series(r, "omega");
  const auto ba = series(r, "bA"), bb = series(r, "bB"), ba_rate = series(r, "bA_rate"), bb_rate = series(r, "bB_rate");
  const auto phi = series(r, "phi"), h = series(r, "H"), e = series(r, "energy");
  const auto la = series(r, "lengthA"), lb = series(r, "lengthB");

  // The benchmark's initial state (docs/iftomm-benchmarks-sources.md section 4.1): s = 0.5 m, rods
  // 30 deg below horizontal, the shaft spinning at omega0 = 2 pi rad/s and every body turning
  // rigidly with it (v = omega0 e_z x r), given in the scene as initial_velocities.
  const double deg = kPi / 180, omega0 = 2 * kPi;
  const auto bx = series(r, "bxA"), bz = series(r, "bzA");
  const auto bvx = series(r, "bvxA"), bvy = series(r, "bvyA"), bvz = series(r, "bvzA");
  const auto svx = series(r, "sleeve_vx"), svy = series(r, "sleeve_vy"), svz = series(r, "sleeve_vz");
  const int i0 = 0;
  ASSERT_EQ(t[i0], 0.0);
  const double ball_x = 0.05 + std::cos(30 * deg), ball_z = 1 - std::sin(30 * deg);  // hinge (0.05, 0, 1), L = 1
  std::printf("  t = 0: s - 0.5 = %.3e, beta - 30 deg = %.3e / %.3e rad, omega - 2 pi = %.3e, phi = %.3e, "
              "s' = %.3e, beta' = %.3e / %.3e; ball velocity - omega0 e_z x r = (%.3e, %.3e, %.3e), "
              "sleeve point (%.3e, %.3e, %.3e)\n",
              s[i0] - 0.5, ba[i0] - 30 * deg, -bb[i0] - 30 * deg, omega[i0] - omega0, phi[i0], s_rate[i0],
              ba_rate[i0], bb_rate[i0], bvx[i0], bvy[i0] - omega0 * ball_x, bvz[i0], svx[i0],
              svy[i0] - omega0 * 0.05, svz[i0]);
  EXPECT_NEAR(s[i0], 0.5, 1e-12);
  EXPECT_NEAR(ba[i0], 30 * deg, 1e-12);
  EXPECT_NEAR(bb[i0], -30 * deg, 1e-12);
  EXPECT_NEAR(phi[i0], 0.0, 1e-12);
  EXPECT_NEAR(la[i0], 0.5, 1e-12);  // the springs start unstretched
  EXPECT_NEAR(lb[i0], 0.5, 1e-12);
  EXPECT_NEAR(bx[i0], ball_x, 1e-12);
  EXPECT_NEAR(bz[i0], ball_z, 1e-12);
  EXPECT_NEAR(omega[i0], omega0, 1e-12);  // the shaft speed
  EXPECT_NEAR(s_rate[i0], 0.0, 1e-12);
  EXPECT_NEAR(ba_rate[i0], 0.0, 1e-12);
  EXPECT_NEAR(bb_rate[i0], 0.0, 1e-12);
  EXPECT_NEAR(bvx[i0], 0.0, 1e-12);  // the ball: omega0 e_z x (ball_x, 0, ball_z), 5.7556 m/s in +y
  EXPECT_NEAR(bvy[i0], omega0 * ball_x, 1e-12);
  EXPECT_NEAR(bvz[i0], 0.0, 1e-12);
  EXPECT_NEAR(svx[i0], 0.0, 1e-12);  // the sleeve point (0.05, 0, 0.5) turns with the shaft
  EXPECT_NEAR(svy[i0], omega0 * 0.05, 1e-12);
  EXPECT_NEAR(svz[i0], 0.0, 1e-12);

  // Axial angular momentum, exactly conserved: H0 = J(30, 30) 2 pi (section 4.2).
  const double h0 = 53.868998658418;
  // Energy: the notes' E0 = 237.4139504415 J leaves out the shaft's constant potential energy
  // m g z_c = 0.3 * 9.81 * 0.5 = 1.4715 J, which mbdae's potential_energy sensor includes.
  const double e0 = 237.4139504415 + 0.3 * kG * 0.5;
  double dh = 0, rise = 0;
  for (int i = i0; i < static_cast<int>(t.size()); ++i) {
    dh = std::max(dh, std::fabs(h[i] - h0));
    if (i > i0) rise = std::max(rise, e[i] - e[i - 1]);  // the dampers only take energy out
  }
  // s(t) (section 4.2; RK4 on the 4-DOF Lagrangian, converged to 1e-11).
  const double table[][2] = {{0.1, 0.523836475569}, {0.2, 0.585079811821}, {0.3, 0.658632348780},
                             {0.4, 0.717713236451}, {0.5, 0.743249424786}, {0.6, 0.727631221687},
                             {0.7, 0.675467139538}, {0.8, 0.603181284689}, {0.9, 0.536282328409},
                             {1.0, 0.501420922380}, {1.5, 0.740684595969}, {2.0, 0.505909294297},
                             {3.0, 0.513246078340}, {4.0, 0.523223371026}, {5.0, 0.535563103722},
                             {6.0, 0.549928665906}, {7.0, 0.565938157720}, {8.0, 0.583178336710},
                             {9.0, 0.601218402048}, {10.0, 0.619622917062}};
  double es = 0, t_worst = 0;
  for (const auto& row : table) {
    const int i = sample_at(t, row[0]);
    ASSERT_GE(i, 0);
    if (std::fabs(s[i] - row[1]) > es) es = std::fabs(s[i] - row[1]), t_worst = row[0];
  }
  const int i10 = sample_at(t, 10.0);
  std::printf("  A05: s(10) = %.9f (ref 0.619622917062), max |s - s_ref| over the table = %.3e m at %.1f s; "
              "max |H - H0| = %.3e (H0 = %.6f); E(0) - E0 = %.3e J, dissipated in 10 s %.4e J, "
              "largest energy rise between samples %.3e J\n",
              s[i10], es, t_worst, dh, h0, e[i0] - e0, e[i0] - e[i10], rise);
  const int i1 = sample_at(t, 1.0);
  std::printf("  A05: dissipated in the first second %.4e J\n", e[i0] - e[i1]);
  EXPECT_LT(es, 1e-3);  // no published tolerance: the A01/A02 high-precision threshold
  EXPECT_LT(es, 1e-7);  // what rtol 1e-13 gives (about 2e-9)
  EXPECT_LT(dh / h0, 1e-7);
  EXPECT_NEAR(e[i0], e0, 1e-5);
  // The notes: about 3.1e-3 J dissipated in 10 s, 2.47e-3 J of it in the first second.
  EXPECT_NEAR(e[i0] - e[i10], 3.1e-3, 0.1e-3);
  EXPECT_NEAR(e[i0] - e[i1], 2.47e-3, 0.05e-3);
  EXPECT_LT(rise, 1e-6);  // the dampers only take energy out
}

// Sensitivities of the governor, one parameter per run, against central differences of rtol
// 1e-12 runs (steps stated per parameter) over the 10 s: the initial shaft speed, a spring's
// free length, a ball's mass. Before 2026-11-27 (night) F_y s came from one central difference
// of the twins along s, whose truncation on these stiff springs (d^2 times the third
// derivative, growing with |d s|) put them up to 1.8e-1 off, with status ok; they now use the
// assembled F_y (docs/sensitivities.md, Method).
TEST(A05StiffFlyballGovernor, SensitivitiesMatchCentralDifferences) {
  const mbdae::Scene scene = mbdae::load_scene(scene_path("A05_stiff_flyball_governor.yaml"));
  const struct {
    const char* path;
    double value, h;
  } params[] = {{"analysis.dynamics.initial_velocities.phi", 2 * kPi, 6e-4},
                {"forces.springA.free_length", 0.5, 1e-5},
                {"bodies.ballA.mass", 5.0, 1e-4}};
  for (const auto& p : params) {
    mbdae::RunOptions o;
    o.verbose = o.progress = o.report_failures = false;
    o.sensitivities = {p.path};
    const mbdae::Result r = mbdae::run(scene, o);
    ASSERT_TRUE(r.ok()) << p.path << ": " << r.message;
    mbdae::RunOptions tight;
    tight.verbose = tight.progress = false;
    tight.rtol = 1e-12;
    auto text = [](double v) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", v);
      return std::string(buf);
    };
    const mbdae::Result plus = mbdae::run(mbdae::with_parameters(scene, {{p.path, text(p.value + p.h)}}), tight);
    const mbdae::Result minus = mbdae::run(mbdae::with_parameters(scene, {{p.path, text(p.value - p.h)}}), tight);
    ASSERT_TRUE(plus.ok() && minus.ok());
    for (const char* sensor : {"s", "omega", "bA"}) {
      const std::string name = std::string("d(") + sensor + ")/d(" + p.path + ")";
      const auto k = std::find(r.sensitivity_columns.begin(), r.sensitivity_columns.end(), name) - r.sensitivity_columns.begin();
      ASSERT_LT(k, static_cast<long>(r.sensitivity_columns.size())) << name;
      const auto &a = plus.column(sensor), &b = minus.column(sensor), &sens = r.sensitivities[k];
      double worst = 0, scale = 0;
      for (size_t i = 0; i < sens.size() && i < a.size(); ++i) {
        const double fd = (a[i] - b[i]) / (2 * p.h);
        worst = std::max(worst, std::fabs(sens[i] - fd));
        scale = std::max(scale, std::fabs(fd));
      }
      std::printf("measured: A05 d(%s)/d(%s): %.2e of the largest\n", sensor, p.path, worst / scale);
      EXPECT_LT(worst / scale, 1e-4) << name;
    }
  }
}

}  // namespace
