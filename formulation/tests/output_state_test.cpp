// Output samples: a state that cannot be made consistent is reported (MultibodyDae::
// output_failure), never handed out as if it were one.
#include <gtest/gtest.h>

#include <cmath>

#include "formulation/index3_dae.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

struct Pendulum {
  System sys = build_system(testing::pendulum(1.0, 0.5, 0.02, 0.3));
  Index3Dae dae{sys, 1.0};
  std::vector<double> y, yp, q, v, a;
  Pendulum() {
    dae.modes.assign(sys.forces.size(), 0);
    y.assign(dae.size(), 0.0);
    yp.assign(dae.size(), 0.0);
    std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
    dae.consistent_initial_values(0.0, y, yp);
  }
};

TEST(OutputState, ConsistentSampleIsNotReported) {
  Pendulum p;
  p.dae.consistent_output(0.0, p.y.data(), p.yp.data(), p.q, p.v, p.a, true);
  EXPECT_TRUE(p.dae.output_failure.empty()) << p.dae.output_failure;
  for (double x : p.a) EXPECT_TRUE(std::isfinite(x));
}

TEST(OutputState, ProjectionThatDoesNotConvergeIsReported) {
  // Euler parameters all zero: the normalization row of the constraint Jacobian (2 p^T) is
  // zero, the projection's Newton matrix singular, and the sample stays off the constraints.
  Pendulum p;
  for (int k = 3; k < 7; ++k) p.y[k] = 0.0;
  p.dae.consistent_output(0.0, p.y.data(), p.yp.data(), p.q, p.v, p.a, true);
  EXPECT_NE(p.dae.output_failure.find("projection onto the position constraints did not converge"), std::string::npos)
      << "reported: '" << p.dae.output_failure << "'";
}

TEST(OutputState, NonFiniteStateIsReported) {
  Pendulum p;
  p.y[0] = NAN;
  p.dae.consistent_output(0.0, p.y.data(), p.yp.data(), p.q, p.v, p.a, false);
  EXPECT_NE(p.dae.output_failure.find("not finite"), std::string::npos) << "reported: '" << p.dae.output_failure << "'";
}

}  // namespace
}  // namespace mbdae
