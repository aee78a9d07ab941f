// The fast mechanism (slider_crank_fast.yaml) against its one-degree-of-freedom Lagrange
// reference: the reference converged and fast enough; every formulation at the scene's default
// tolerances against it, for positions and velocities alike; index3's error per unit step against
// the positions-only test; the global error estimate (issue 13).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cases/run/error_estimate.h"
#include "verification/fast_mechanism/fast_mechanism_errors.h"
#include "verification/fast_mechanism/slider_crank_reference.h"

namespace mbdae {
namespace {

TEST(FastMechanism, ReferenceConvergedAndFast) {
  std::vector<double> times;
  for (int k = 0; k <= 200; ++k) times.push_back(1e-4 * k);
  const auto fine = slider_crank_reference({}, times, 1e-13);
  const auto coarse = slider_crank_reference({}, times, 1e-12);
  double d_theta = 0, d_rate = 0;
  for (size_t k = 0; k < times.size(); ++k) {
    d_theta = std::max(d_theta, std::fabs(fine[k].theta - coarse[k].theta));
    d_rate = std::max(d_rate, std::fabs(fine[k].rate - coarse[k].rate));
  }
  EXPECT_LT(d_theta, 1e-10);  // rad
  EXPECT_LT(d_rate / fine.back().rate, 1e-10);
  EXPECT_GT(fine.back().rate, 1000.0);  // rad/s within the run
}

Result run_fast(const Scene& scene, const std::string& formulation) {
  RunOptions opt;
  opt.formulation = formulation;
  return run(scene, opt);
}

// The promise at the scene's default tolerances (rtol 1e-6, atol from the model's
// scales): every position and velocity within 10 rtol of its scale (the largest |x_ref|).
// index3 (velocity error per unit step) meets it (measured 6.5e-8 and 1.3e-7 relative,
// docs/work-precision.md); since issue 21 the other formulations test their errors per unit of
// the run's span and meet it too (before, per step, they missed it: the crank's phase error grew
// with omega t, 3.8e-5 to 8.5e-4 relative, and only three digits were asserted here): measured
// index2-ggl 1.3e-7 and 2.2e-7, index1 8.5e-8 and 1.5e-7, penalty 2.9e-6 and 5.1e-6 (its bias).
void expect_within(const Scene& scene, const std::string& formulation, double factor) {
  const Result r = run_fast(scene, formulation);
  ASSERT_TRUE(r.ok()) << r.message;
  const FastMechanismErrors e = fast_mechanism_errors(r);
  for (size_t k = 0; k < e.sensors.size(); ++k)
    EXPECT_LE(e.error[k], factor * e.scale[k])
        << formulation << ": " << e.sensors[k] << " error " << e.error[k] << " on a scale of " << e.scale[k];
  const double rtol = scene.steps.back().rtol;
  std::printf("%s: relative errors positions %.3g, velocities %.3g (%.3g and %.3g rtol)\n", formulation.c_str(),
              e.position, e.velocity, e.position / rtol, e.velocity / rtol);
}

TEST(FastMechanism, Index3KeepsThePromiseAtDefaultTolerances) {
  const Scene scene = load_fast_mechanism();
  expect_within(scene, "index3", 10 * scene.steps.back().rtol);
}

class FastMechanismFormulation : public ::testing::TestWithParam<std::string> {};

TEST_P(FastMechanismFormulation, KeepsThePromiseAtDefaultTolerances) {
  const Scene scene = load_fast_mechanism();
  expect_within(scene, GetParam(), 10 * scene.steps.back().rtol);
}

INSTANTIATE_TEST_SUITE_P(Formulations, FastMechanismFormulation,
                         ::testing::Values("index2-ggl", "index1", "penalty"));

// Velocity error per unit step (index3) against the positions-only test (index3-positions):
// measured 2.3e5 times smaller errors.
TEST(FastMechanism, Index3ErrorPerUnitStepBeatsPositionsOnly) {
  const Scene scene = load_fast_mechanism();
  const FastMechanismErrors unit_step = fast_mechanism_errors(run_fast(scene, "index3"));
  const FastMechanismErrors positions = fast_mechanism_errors(run_fast(scene, "index3-positions"));
  EXPECT_LT(1000 * unit_step.position, positions.position);
  EXPECT_LT(1000 * unit_step.velocity, positions.velocity);
}

// The error estimate (cases/run/error_estimate.h) finds the error of a formulation that misses
// the promise within a factor 3 and warns: index3-positions (positions only, per step; until
// issue 21 this was index2-ggl, which now keeps the promise).
TEST(FastMechanism, ErrorEstimateSeesTheMissedPromise) {
  const Scene scene = load_fast_mechanism();
  RunOptions opt;
  opt.formulation = "index3-positions";
  const Result r = run(scene, opt);
  ASSERT_TRUE(r.ok());
  const FastMechanismErrors truth = fast_mechanism_errors(r);
  const ErrorEstimate est = estimate_global_error(scene, opt, r);
  ASSERT_EQ(est.reference_status, "ok");
  ASSERT_EQ(est.sensors.size(), truth.sensors.size());
  for (size_t k = 0; k < est.sensors.size(); ++k) {
    EXPECT_GT(est.error[k], truth.error[k] / 3) << est.sensors[k];
    EXPECT_LT(est.error[k], truth.error[k] * 3) << est.sensors[k];
  }
  EXPECT_EQ(est.exceeded.size(), est.sensors.size());
}

}  // namespace
}  // namespace mbdae
