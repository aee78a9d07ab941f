// Functions of time used for driven coordinates, ground profiles and point forces.
// Each kind gives its value and first two derivatives in closed form, and the times where
// it is not smooth (breakpoints), so the integrator can stop and restart there.
#pragma once

#include <string>
#include <vector>

namespace mbdae {

struct TimeFunction {
  enum class Kind { kConstant, kStep, kPiecewiseLinear, kSine, kSweep, kPolynomial };
  Kind kind = Kind::kConstant;
  // kConstant: a = value. kStep: a = before, b = after, t0 = switch time.
  // kSine: a = amplitude, b = frequency (Hz), c = phase (rad), d = offset.
  // kSweep: a = amplitude, b = f0, c = f1, t0, t1: a sin(2 pi (b t + k t^2 / 2)), k = (c-b)/(t1-t0)
  //   with t measured from t0 (zero before t0).
  // kPiecewiseLinear: knots (t_i, y_i), constant outside.
  // kPolynomial: coefficients c_0 + c_1 t + ...
  double a = 0, b = 0, c = 0, d = 0, t0 = 0, t1 = 1;
  std::vector<double> ts, ys;

  double value(double t) const;
  double derivative(double t) const;
  double second_derivative(double t) const;
  // Times where the function or one of its first two derivatives jumps.
  std::vector<double> breakpoints() const;
  std::string describe() const;

  static TimeFunction constant(double v) {
    TimeFunction f;
    f.a = v;
    return f;
  }
};

}  // namespace mbdae
