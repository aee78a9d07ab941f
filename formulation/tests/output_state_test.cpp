// Output samples: a state that cannot be made consistent is reported (MultibodyDae::
// output_failure), never handed out as if it were one.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "formulation/augmented_solver.h"
#include "formulation/index3_dae.h"
#include "formulation/redundancy.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

struct Pendulum {
  System sys = build_system(testing::pendulum(1.37, 0.523, 0.0217, 0.3));
  Index3Dae dae{sys, 1.0};
  std::vector<double> y, yp, q, v, a;
  Pendulum() {
    dae.state().modes.assign(sys.forces.size(), 0);
    y.assign(dae.size(), 0.0);
    yp.assign(dae.size(), 0.0);
    std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
    dae.consistent_initial_values(0.0, y, yp);
  }
};

TEST(OutputState, ConsistentSampleIsNotReported) {
  Pendulum p;
  p.dae.consistent_output(0.0, p.y.data(), p.yp.data(), p.q, p.v, p.a, true);
  EXPECT_TRUE(p.dae.state().output_failure.empty()) << p.dae.state().output_failure;
  for (double x : p.a) EXPECT_TRUE(std::isfinite(x));
}

TEST(OutputState, ProjectionThatDoesNotConvergeIsReported) {
  // Euler parameters all zero: the normalization row of the constraint Jacobian (2 p^T) is
  // zero, the projection's Newton matrix singular, and the sample stays off the constraints.
  Pendulum p;
  for (int k = 3; k < 7; ++k) p.y[k] = 0.0;
  p.dae.consistent_output(0.0, p.y.data(), p.yp.data(), p.q, p.v, p.a, true);
  EXPECT_NE(p.dae.state().output_failure.find("projection onto the position constraints did not converge"), std::string::npos)
      << "reported: '" << p.dae.state().output_failure << "'";
}

TEST(OutputState, NonFiniteStateIsReported) {
  Pendulum p;
  p.y[0] = NAN;
  p.dae.consistent_output(0.0, p.y.data(), p.yp.data(), p.q, p.v, p.a, false);
  EXPECT_NE(p.dae.state().output_failure.find("not finite"), std::string::npos) << "reported: '" << p.dae.state().output_failure << "'";
}


// Output accelerations by refinement on an earlier factorization (AugmentedSolver::
// output_accelerations) against the direct solve at the same state, along a moving four-bar
// (positions and velocities projected onto the constraints every `h`, 400 samples).
AugmentedSolver::RefinementStats refined_against_direct(double h, double speed, int* points) {
  System sys = build_system(testing::four_bar(0.7));
  std::vector<double> q = sys.q0, v(sys.nq()), a(sys.nq()), a_ref(sys.nq());
  AugmentedSolver(sys).positions(q.data(), 0.0, 1e-13, 50);
  sys = without_redundant_constraints(sys, find_redundant_constraints(sys, q.data(), 0.0));
  AugmentedSolver sampler(sys), direct(sys);
  sampler.prepare_output_accelerations();
  const std::vector<char> modes(sys.forces.size(), 0);
  for (int i = 0; i < sys.nq(); ++i) v[i] = speed * std::sin(1.0 + i);
  EXPECT_TRUE(direct.velocities(q.data(), 0.0, v.data()));
  const double tolerance = 1e-10;
  double worst = 0;
  for (int k = 0; k <= 400; ++k) {
    const double t = k * h;
    if (k > 0) {  // a symplectic Euler step, then back onto the constraints
      EXPECT_TRUE(direct.accelerations(modes, q.data(), v.data(), t, a_ref.data(), nullptr));
      for (int i = 0; i < sys.nq(); ++i) {
        v[i] += h * a_ref[i];
        q[i] += h * v[i];
      }
      EXPECT_TRUE(direct.positions(q.data(), t, 1e-13, 50).converged);
      EXPECT_TRUE(direct.velocities(q.data(), t, v.data()));
    }
    EXPECT_TRUE(sampler.output_accelerations(modes, q.data(), v.data(), t, a.data(), tolerance));
    EXPECT_TRUE(direct.accelerations(modes, q.data(), v.data(), t, a_ref.data(), nullptr));
    double err = 0, norm = 0;
    for (int i = 0; i < sys.nq(); ++i) {
      err = std::fmax(err, std::fabs(a[i] - a_ref[i]));
      norm = std::fmax(norm, std::fabs(a_ref[i]));
    }
    worst = std::fmax(worst, err / norm);
  }
  EXPECT_LT(worst, 10 * tolerance);
  std::printf("h %g: refined %ld, direct %ld, corrections %ld, extrapolation through %d samples, worst relative error %.2e\n",
              h, sampler.refinement.refined, sampler.refinement.direct, sampler.refinement.corrections,
              sampler.extrapolation_points(), worst);
  *points = sampler.extrapolation_points();
  return sampler.refinement;
}

// Fine samples of a smooth motion: most samples refined (a few factored: the first, and where K
// drifted from K0), two corrections each (the least the error estimate needs), the
// extrapolation's degree above the quadratic.
TEST(OutputState, RefinedAccelerationsMatchTheDirectSolve) {
  int points = 0;
  const auto r = refined_against_direct(1e-3, 2.0, &points);
  EXPECT_GT(r.refined, 300) << "direct " << r.direct;
  EXPECT_GT(r.direct, 0);
  EXPECT_LT(r.corrections, 2.2 * r.refined);
  EXPECT_GT(points, 3);
}

// Coarse samples of a fast motion (20 ms apart, velocities 15 times those above): the
// extrapolation falls to a low degree and most samples are factored afresh; the same accuracy.
TEST(OutputState, CoarseSamplesLowerTheExtrapolationDegree) {
  int points = 0;
  refined_against_direct(2e-2, 30.0, &points);
  EXPECT_LE(points, 2);
}

// A mechanism at rest (a pendulum hanging straight down, v = 0, its angle off the vertical by
// 1e-14 rad or less, as an integrator holds it): a = 0 up to rounding. The refined samples agree
// with the direct solve within 1e-10 of g, and all but the first are refined. (The acceptance
// relative to the forces' |Q| / m is measured on Dynamics I, docs/performance.md: this clean model
// also converges with the acceptance relative to |a| alone.)
TEST(OutputState, MechanismAtRestIsRefined) {
  System sys = build_system(testing::pendulum(1.37, 0.523, 0.0217, 0.0));
  std::vector<double> q = sys.q0, v(sys.nq(), 0.0), a(sys.nq()), a_ref(sys.nq());
  AugmentedSolver sampler(sys), direct(sys);
  ASSERT_TRUE(direct.positions(q.data(), 0.0, 1e-13, 50).converged);
  sampler.prepare_output_accelerations();
  const std::vector<char> modes(sys.forces.size(), 0);
  double largest = 0;
  for (int k = 0; k < 100; ++k) {
    q = build_system(testing::pendulum(1.37, 0.523, 0.0217, 1e-14 * std::sin(k))).q0;
    ASSERT_TRUE(sampler.output_accelerations(modes, q.data(), v.data(), 1e-3 * k, a.data(), 1e-10));
    ASSERT_TRUE(direct.accelerations(modes, q.data(), v.data(), 1e-3 * k, a_ref.data(), nullptr));
    for (int i = 0; i < sys.nq(); ++i) {
      EXPECT_LT(std::fabs(a[i] - a_ref[i]), 1e-10 * 9.81) << "sample " << k << ", coordinate " << i;
      largest = std::fmax(largest, std::fabs(a_ref[i]));
    }
  }
  std::printf("at rest: refined %ld, direct %ld, largest |a| of the direct solve %.2e\n",
              sampler.refinement.refined, sampler.refinement.direct, largest);
  EXPECT_GE(sampler.refinement.refined, 95);
}

// The sensitivities' solve on a sample's factorization (output_derivative) names what overflowed
// as the sensitivities, whether the sample was factored (its first: one solve) or refined.
TEST(OutputState, SensitivitiesThatOverflowAreNamedSo) {
  System sys = build_system(testing::pendulum(1.37, 0.523, 0.0217, 0.3));
  std::vector<double> q = sys.q0, v(sys.nq(), 0.0), a(sys.nq());
  AugmentedSolver sampler(sys);
  ASSERT_TRUE(sampler.positions(q.data(), 0.0, 1e-13, 50).converged);
  sampler.prepare_output_accelerations();
  const std::vector<char> modes(sys.forces.size(), 0);
  const int n = sys.nq() + sys.num_constraint_rows();
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(sampler.output_accelerations(modes, q.data(), v.data(), 1e-3 * k, a.data(), 1e-10));
    std::vector<double> g(n, 1.0), dx(n, 0.0);
    g[0] = NAN;
    try {
      sampler.output_derivative(q.data(), 1e-3 * k, g.data(), dx.data(), 1e-10);
      ADD_FAILURE() << "sample " << k << ": a NaN right side gave no error";
    } catch (const SolveError& e) {
      EXPECT_EQ(e.status, "overflow");
      EXPECT_NE(std::string(e.what()).find("the accelerations' sensitivities are not finite"), std::string::npos)
          << "sample " << k << ": " << e.what();
    }
  }
  EXPECT_GE(sampler.refinement.refined, 1);
  EXPECT_GE(sampler.refinement.direct, 1);
}

}  // namespace
}  // namespace mbdae
