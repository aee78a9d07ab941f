// Functions of time: values against closed forms, derivatives against central differences,
// breakpoints.
#include <gtest/gtest.h>

#include <cmath>

#include "core/time_function.h"

namespace mbdae {
namespace {

TimeFunction sweep() {
  TimeFunction f;
  f.kind = TimeFunction::Kind::kSweep;
  f.a = 0.005;
  f.b = 1.0;
  f.c = 10.0;
  f.t0 = 0.0;
  f.t1 = 10.0;
  return f;
}

void expect_derivatives(const TimeFunction& f, double t) {
  const double h = 1e-5;
  EXPECT_NEAR(f.derivative(t), (f.value(t + h) - f.value(t - h)) / (2 * h), 1e-6 * (1 + std::fabs(f.derivative(t))));
  EXPECT_NEAR(f.second_derivative(t), (f.derivative(t + h) - f.derivative(t - h)) / (2 * h),
              1e-5 * (1 + std::fabs(f.second_derivative(t))));
}

TEST(TimeFunction, SweepMatchesTheSpecFormula) {
  const TimeFunction f = sweep();
  for (double t : {0.0, 0.3, 5.0, 12.5, 20.0}) {
    // z = zmax sin(2 pi (f0 + (f1 - f0)/(t1 - t0) t/2) t)
    const double z = 0.005 * std::sin(2 * M_PI * (1.0 + 0.9 * t / 2) * t);
    EXPECT_NEAR(f.value(t), z, 1e-15);
    if (t > 0) expect_derivatives(f, t);
  }
  // Instantaneous frequency 1 + 0.9 t: 19 Hz at 20 s.
  EXPECT_NEAR(f.derivative(20.0), 0.005 * 2 * M_PI * 19.0 * std::cos(2 * M_PI * (1.0 + 9.0) * 20.0), 1e-12);
}

TEST(TimeFunction, StepPiecewiseLinearSinePolynomial) {
  TimeFunction s;
  s.kind = TimeFunction::Kind::kStep;
  s.a = 0.0;
  s.b = -0.1;
  s.t0 = 0.2;
  EXPECT_EQ(s.value(0.1999999), 0.0);
  EXPECT_EQ(s.value(0.2), -0.1);
  EXPECT_EQ(s.breakpoints(), std::vector<double>{0.2});

  TimeFunction p;
  p.kind = TimeFunction::Kind::kPiecewiseLinear;
  p.ts = {0, 1, 2};
  p.ys = {0.2, -1.1, 1.2};
  EXPECT_NEAR(p.value(0.5), -0.45, 1e-15);
  EXPECT_NEAR(p.value(1.5), 0.05, 1e-15);
  EXPECT_EQ(p.value(-1), 0.2);
  EXPECT_EQ(p.value(3), 1.2);
  EXPECT_NEAR(p.derivative(0.5), -1.3, 1e-15);
  EXPECT_NEAR(p.derivative(1.0), 2.3, 1e-15);  // right derivative at a knot
  EXPECT_EQ(p.breakpoints(), (std::vector<double>{0, 1, 2}));

  TimeFunction w;
  w.kind = TimeFunction::Kind::kSine;
  w.a = 2;
  w.b = 3;
  w.c = 0.4;
  w.d = 1;
  expect_derivatives(w, 0.37);
  EXPECT_NEAR(w.value(0.37), 2 * std::sin(2 * M_PI * 3 * 0.37 + 0.4) + 1, 1e-15);

  TimeFunction c;
  c.kind = TimeFunction::Kind::kPolynomial;
  c.ys = {1, -2, 3};
  EXPECT_NEAR(c.value(2), 1 - 4 + 12, 1e-15);
  EXPECT_NEAR(c.derivative(2), -2 + 12, 1e-15);
  EXPECT_NEAR(c.second_derivative(2), 6, 1e-15);
}

// A polynomial of degree 50000 (a scene can give that many coefficients): the factor i (i - 1)
// of the second derivative, 2.5e9, does not fit an int (it overflowed, UBSan: signed integer
// overflow, and gave a negative second derivative). t^50000 at t = 1: 50000 * 49999.
TEST(TimeFunction, SecondDerivativeOfAHighDegreePolynomial) {
  TimeFunction f;
  f.kind = TimeFunction::Kind::kPolynomial;
  f.ys.assign(50001, 0.0);
  f.ys.back() = 1.0;
  EXPECT_EQ(f.value(1.0), 1.0);
  EXPECT_EQ(f.derivative(1.0), 50000.0);
  EXPECT_EQ(f.second_derivative(1.0), 50000.0 * 49999.0);
}

}  // namespace
}  // namespace mbdae
