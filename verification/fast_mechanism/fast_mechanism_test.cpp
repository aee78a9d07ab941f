// The fast mechanism (slider_crank_fast.yaml) against its one-degree-of-freedom Lagrange
// reference: the reference converged and fast enough, and every formulation at the scene's
// default tolerances within 10 x rtol of it, relative to each quantity's scale, for positions
// and velocities alike (issue 13).
#include <gtest/gtest.h>

#include <cmath>

#include "verification/fast_mechanism/fast_mechanism_errors.h"
#include "verification/fast_mechanism/slider_crank_reference.h"

namespace mbdae {
namespace {

TEST(FastMechanism, ReferenceConvergedAndFast) {
  std::vector<double> times;
  for (int k = 0; k <= 120; ++k) times.push_back(1e-3 * k);
  const auto fine = slider_crank_reference({}, times, 1e-13);
  const auto coarse = slider_crank_reference({}, times, 1e-11);
  double d_theta = 0, d_rate = 0;
  for (size_t k = 0; k < times.size(); ++k) {
    d_theta = std::max(d_theta, std::fabs(fine[k].theta - coarse[k].theta));
    d_rate = std::max(d_rate, std::fabs(fine[k].rate - coarse[k].rate));
  }
  EXPECT_LT(d_theta, 1e-9);          // rad, on about 80 rad
  EXPECT_LT(d_rate / fine.back().rate, 1e-11);
  EXPECT_GT(fine.back().rate, 1000.0);  // rad/s within the run
}

class FastMechanismFormulation : public ::testing::TestWithParam<std::string> {};

TEST_P(FastMechanismFormulation, DefaultTolerancesKeepTheirPromise) {
  Scene scene = load_fast_mechanism();
  RunOptions opt;
  opt.formulation = GetParam();
  const Result r = run(scene, opt);
  ASSERT_TRUE(r.ok()) << r.message;
  const FastMechanismErrors e = fast_mechanism_errors(r);
  const double rtol = scene.steps.back().rtol;
  for (size_t k = 0; k < e.sensors.size(); ++k)
    EXPECT_LE(e.error[k], 10 * rtol * e.scale[k])
        << GetParam() << ": " << e.sensors[k] << " error " << e.error[k] << " on a scale of " << e.scale[k];
  std::printf("%s: relative errors positions %.3g, velocities %.3g (rtol %g)\n", GetParam().c_str(), e.position,
              e.velocity, rtol);
}

INSTANTIATE_TEST_SUITE_P(Formulations, FastMechanismFormulation,
                         ::testing::Values("index3", "index2-ggl", "index1", "penalty"));

}  // namespace
}  // namespace mbdae
