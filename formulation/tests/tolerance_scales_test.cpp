// The model's length and time scales and the defaults they give (formulation/tolerance_scales.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "formulation/ggl_dae.h"
#include "formulation/index1_dae.h"
#include "formulation/index3_dae.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"
#include "formulation/tolerance_scales.h"

namespace mbdae {
namespace {

// A pendulum of length d under gravity: L = d (pivot to centre of mass), T = sqrt(d / g).
TEST(ToleranceScales, PendulumLengthAndTime) {
  for (double d : {0.03, 1.0}) {
    Model m = testing::pendulum(2.0, d, 0.1, 0.0);
    m.gravity = Vec3(0, 0, -9.81);
    const System sys = build_system(m);
    const ModelScales s = model_scales(sys, sys.q0.data(), 0.0, 10.0);
    EXPECT_NEAR(s.length, d, 1e-12 * d);
    EXPECT_NEAR(s.time, std::sqrt(d / 9.81), 1e-12);
    EXPECT_EQ(s.fast_time, s.time);
    // Baumgarte alpha = beta = k / T_f (index1 k = 1, penalty 5): 15.7/s for penalty on the 1 m
    // pendulum (20/s was the fixed default).
    EXPECT_NEAR(default_baumgarte_rate(s, 5.0), 5.0 / std::sqrt(d / 9.81), 1e-9);
    EXPECT_NEAR(default_baumgarte_rate(s, 1.0), 1.0 / std::sqrt(d / 9.81), 1e-9);
    // Absolute tolerances in model units from a_q = rtol L.
    const AbsoluteTolerances a = absolute_tolerances(s, default_position_atol(s, 1e-6));
    EXPECT_NEAR(a.position, 1e-6 * d, 1e-20);
    EXPECT_NEAR(a.rotation, 1e-6, 1e-18);          // the same for a 3 cm and a 1 m pendulum
    EXPECT_NEAR(a.velocity, 1e-6 * d / s.time, 1e-18);
    EXPECT_NEAR(a.rotation_rate, 1e-6 / s.time, 1e-15);
  }
}

// Without gravity the time scale is the span; a spring's sqrt(m/k) sets the fast time scale.
TEST(ToleranceScales, SpanAndSpring) {
  Model m = testing::pendulum(2.0, 0.5, 0.1, 0.0);
  m.gravity = Vec3::Zero();
  System sys = build_system(m);
  EXPECT_NEAR(model_scales(sys, sys.q0.data(), 0.0, 3.0).time, 3.0, 1e-15);
  Force spring;
  spring.type = ForceSpec::Type::kSpringDamper;
  spring.bi = 0;
  spring.stiffness = 800.0;
  sys.forces.push_back(spring);
  const ModelScales s = model_scales(sys, sys.q0.data(), 0.0, 3.0);
  EXPECT_NEAR(s.fast_time, std::sqrt(2.0 / 800.0), 1e-15);
  EXPECT_NEAR(default_baumgarte_rate(s, 5.0), 100.0, 1e-9);
}

// index3's velocity error per unit step: the positions' weights are the plain ones times
// (T/h)^2, capped at the rounding of the model's positions (1e3 eps max(L, |r|)) and of the
// Euler parameters (1e3 eps); index3-positions keeps the plain weights.
TEST(ToleranceScales, Index3VelocityErrorPerUnitStep) {
  Model m = testing::pendulum(2.0, 0.03, 0.1, 0.0);
  m.gravity = Vec3(0, 0, -9.81);
  const System sys = build_system(m);
  const ModelScales s = model_scales(sys, sys.q0.data(), 0.0, 1.0);
  const double rtol = 1e-6;
  const AbsoluteTolerances a = absolute_tolerances(s, default_position_atol(s, rtol));
  Index3Dae unit_step(sys, 1.0, true), plain(sys, 1.0, false);
  unit_step.set_absolute_tolerances(a);
  plain.set_absolute_tolerances(a);
  std::vector<double> y(unit_step.size(), 0.0);
  std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
  std::vector<double> w(y.size()), w0(y.size());
  double rmax = 0;
  for (int i = 0; i < 3; ++i) rmax += std::fabs(y[i]);
  const double floor_length = 1e3 * 2.220446049250313e-16 * std::max(s.length, rmax);
  const double floor_rotation = 1e3 * 2.220446049250313e-16;
  plain.error_weights(1e-3, y.data(), rtol, a.position, w0.data());
  for (int i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(w0[i], 1.0 / (rtol * std::fabs(y[i]) + a.position));
  // h = T / 10: at rtol 1e-6 (the handover's) the weights times (T/h)^2 = 100, above the floor.
  const double h = s.time / 10;
  unit_step.error_weights(h, y.data(), rtol, a.position, w.data());
  for (int i = 0; i < 7; ++i) {
    const double plain_w = 1.0 / (rtol * std::fabs(y[i]) + (i < 3 ? a.position : a.rotation));
    EXPECT_NEAR(w[i], 100 * plain_w, 1e-9 * w[i]) << i;
  }
  // Looser, also times the span factor c = S / T, at most 5 and at most rtol / 1e-6: a 1 s run
  // (S / T = 18 here) at rtol 1e-4 and 3e-6, a run of 3 T at 1e-4.
  ASSERT_GT(a.span / a.time, 10.0);
  struct Case {
    double periods, rtol, c;
  };
  for (const Case k : {Case{0, 1e-4, 5.0}, Case{0, 3e-6, 3.0}, Case{3, 1e-4, 3.0}}) {
    const ModelScales sl = k.periods > 0 ? model_scales(sys, sys.q0.data(), 0.0, k.periods * s.time) : s;
    const AbsoluteTolerances al = absolute_tolerances(sl, default_position_atol(sl, k.rtol));
    Index3Dae span_test(sys, 1.0, true);
    span_test.set_absolute_tolerances(al);
    span_test.error_weights(sl.time / 10, y.data(), k.rtol, al.position, w.data());
    for (int i = 0; i < 7; ++i) {
      const double plain_w = 1.0 / (k.rtol * std::fabs(y[i]) + (i < 3 ? al.position : al.rotation));
      EXPECT_NEAR(w[i], 100 * k.c * plain_w, 1e-9 * w[i]) << k.periods << " T, rtol " << k.rtol << ", " << i;
    }
  }
  // h = T / 1e6: (T/h)^2 = 1e12 would ask for less than the rounding: the floor.
  unit_step.error_weights(s.time / 1e6, y.data(), rtol, a.position, w.data());
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(w[i], 1.0 / (i < 3 ? floor_length : floor_rotation), 1e-9 * w[i]) << i;
}
// index2-ggl's velocity weights per unit of the span are also times the span factor
// c = min(S / T, 5, rtol / 1e-6) (its velocity errors add up into the positions over the run);
// its positions' are index1's, whose velocities have no such factor (a 1 s run, S / T = 18).
TEST(ToleranceScales, GglVelocitiesPerUnitSpanTimesTheSpanFactor) {
  Model m = testing::pendulum(2.0, 0.03, 0.1, 0.0);
  m.gravity = Vec3(0, 0, -9.81);
  const System sys = build_system(m);
  const ModelScales s = model_scales(sys, sys.q0.data(), 0.0, 1.0);
  ASSERT_GT(s.span / s.time, 10.0);
  struct Case {
    double rtol, c;
  };
  for (const Case k : {Case{1e-4, 5.0}, Case{3e-6, 3.0}, Case{1e-6, 1.0}}) {
    const AbsoluteTolerances a = absolute_tolerances(s, default_position_atol(s, k.rtol));
    GglDae ggl(sys);
    Index1Dae index1(sys);
    ggl.set_absolute_tolerances(a);
    index1.set_absolute_tolerances(a);
    const int nq = static_cast<int>(sys.q0.size());
    std::vector<double> yg(ggl.size(), 0.0), yi(index1.size(), 0.0), wg(ggl.size()), wi(index1.size());
    std::copy(sys.q0.begin(), sys.q0.end(), yg.begin());
    std::copy(sys.q0.begin(), sys.q0.end(), yi.begin());
    ggl.error_weights(s.time / 10, yg.data(), k.rtol, a.position, wg.data());
    index1.error_weights(s.time / 10, yi.data(), k.rtol, a.position, wi.data());
    for (int i = 0; i < nq; ++i) {
      EXPECT_NEAR(wg[i], wi[i], 1e-12 * wi[i]) << "rtol " << k.rtol << ", q " << i;
      EXPECT_NEAR(wg[nq + i], k.c * wi[nq + i], 1e-12 * wg[nq + i]) << "rtol " << k.rtol << ", v " << i;
    }
  }
}

}  // namespace
}  // namespace mbdae
