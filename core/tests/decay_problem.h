// A small index-1 DAE with a closed-form solution and its sensitivity to the initial value, for
// the IDA driver's tests (core/tests/ida_driver_test.cpp) and the allocation test
// (verification/benchmarks/allocation_test.cpp):
//   F1 = y1' + y1 - u(t) = 0      (differential, in the error test)
//   F2 = y2 - 2 y1       = 0      (algebraic, out of it, like the multibody velocities)
// u = 0, or a unit step at t = 0.5 declared as a breakpoint.
#pragma once

#include <cmath>
#include <vector>

#include "core/dae_problem.h"
#include "core/sensitivity_problem.h"

namespace mbdae::testing {

class DecayProblem : public DaeProblem {
 public:
  bool step_input = false;       // unit step of u at t = 0.5
  bool end_breakpoint = false;   // declare t = 2 a breakpoint too
  double switch_level = -1;      // > 0: event where y1 crosses it
  double switch_time = -1;       // > 0: event at this time (g = t - switch_time)
  double fail_after = 1e300;     // the residual is not computable (recoverable error) after this
  long residual_calls = 0, jacobian_calls = 0;
  std::vector<double> restart_times;
  std::vector<bool> restart_was_event;

  DecayProblem() {
    pattern_.rows = pattern_.cols = 2;
    pattern_.colptr = {0, 2, 3};
    pattern_.rowind = {0, 1, 1};
  }
  int size() const override { return 2; }
  const CscPattern& jacobian_pattern() override { return pattern_; }
  double u(double t) const {
    // Left limit at the end of a segment: the jump belongs to the next one.
    const double tt = t < segment_end_ ? t : std::nextafter(segment_end_, 0.0);
    return step_input && tt >= 0.5 ? 1.0 : 0.0;
  }
  int residual(double t, const double* y, const double* yp, double* r) override {
    ++residual_calls;
    if (t > fail_after) return 1;
    r[0] = yp[0] + y[0] - u(t);
    r[1] = y[1] - 2 * y[0];
    return 0;
  }
  int jacobian(double, double cj, const double*, const double*, double* v) override {
    ++jacobian_calls;
    v[0] = 1 + cj;  // (0, 0)
    v[1] = -2;      // (1, 0)
    v[2] = 1;       // (1, 1)
    return 0;
  }
  void error_test_mask(double* id) const override {
    id[0] = 1;
    id[1] = 0;
  }
  int num_switches() const override { return switch_level > 0 || switch_time > 0 ? 1 : 0; }
  void switches(double t, const double* y, double* g) override {
    g[0] = switch_time > 0 ? t - switch_time : y[0] - switch_level;
  }
  void restart(double t, double* y, double* yp, const int* roots) override {
    restart_times.push_back(t);
    restart_was_event.push_back(roots != nullptr);
    y[1] = 2 * y[0];
    yp[0] = -y[0] + u(t);
    yp[1] = 2 * yp[0];
  }
  std::vector<double> breakpoints() const override {
    std::vector<double> b;
    if (step_input) b.push_back(0.5);
    if (end_breakpoint) b.push_back(2.0);
    return b;
  }
  void set_segment(double, double t_end) override { segment_end_ = t_end; }
  double segment_end() const { return segment_end_; }

  double exact(double t) const {
    if (!step_input || t <= 0.5) return std::exp(-t);
    return 1 + (std::exp(-0.5) - 1) * std::exp(-(t - 0.5));
  }

 private:
  CscPattern pattern_;
  double segment_end_ = 1e300;
};

// The sensitivity of DecayProblem to its initial value y0(0) = p: s0' = -s0, s1 = 2 s0, s(0) =
// (1, 2), so s0(t) = exp(-t). `fail_after`: its residual cannot be evaluated after that time.
class DecayInitialValue : public SensitivityProblem {
 public:
  double fail_after = 1e300;
  // copies > 1: the same sensitivity `copies` times, copy i scaled by 2^i (exact in binary, so
  // copy i is 2^i copy 0 bit for bit: IDAS's solves of several sensitivities at once).
  int copies = 1;
  int count() const override { return copies; }
  double scale(int) const override { return 1.0; }
  int residual(double t, const double*, const double*, const double*, const double* const* s, const double* const* sp,
               double* const* r) override {
    if (t > fail_after) return -1;
    for (int i = 0; i < copies; ++i) {
      r[i][0] = sp[i][0] + s[i][0];
      r[i][1] = s[i][1] - 2 * s[i][0];
    }
    return 0;
  }
  void initial(double, const double*, const double*, double* const* s, double* const* sp) override {
    for (int i = 0; i < copies; ++i) {
      const double c = std::ldexp(1.0, i);
      s[i][0] = c, s[i][1] = 2 * c, sp[i][0] = -c, sp[i][1] = -2 * c;
    }
  }
  void restart(double, const double*, const double*, double* const* s, double* const* sp) override {
    for (int i = 0; i < copies; ++i) {
      sp[i][0] = -s[i][0];
      sp[i][1] = -2 * s[i][0];
    }
  }
  bool in_error_test() const override { return true; }
};

}  // namespace mbdae::testing
