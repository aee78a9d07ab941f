// The IDA driver (core/ida_driver.cpp) on the small index-1 DAE of core/tests/decay_problem.h,
// whose solution is closed-form: y1 = e^-t (u = 0), y1 = 1 + (e^-0.5 - 1) e^-(t - 0.5) after the
// unit step at t = 0.5, y2 = 2 y1.
// Checked: output samples and the final state against the solution, the end of the run reached
// exactly (whether or not it is a breakpoint), breakpoints hit exactly with a restart, an event
// located by root finding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/ida_driver.h"
#include "core/tests/decay_problem.h"

namespace mbdae {
namespace {

using testing::DecayInitialValue;
using testing::DecayProblem;

struct Sample {
  double t, y1, y2;
};

// The decay over [0, 2] at rtol 1e-10, sampled every 0.1.
IdaOptions decay_options() {
  IdaOptions o;
  o.t0 = 0;
  o.t1 = 2;
  o.rtol = 1e-10;
  o.atol = 1e-12;
  o.output_step = 0.1;
  return o;
}

// Runs the decay from its initial values with options o, each sample appended to `samples`.
IdaStats run(DecayProblem& p, std::vector<Sample>& samples, std::vector<double>& y,
             const IdaOptions& o = decay_options()) {
  y = {1.0, 2.0};
  std::vector<double> yp = {-1.0, -2.0};
  return integrate(p, o, y, yp, [&](double t, const double* yy, const double*) {
    samples.push_back({t, yy[0], yy[1]});
    return true;
  });
}

void expect_follows_solution(const DecayProblem& p, const std::vector<Sample>& samples,
                             const std::vector<double>& y, const IdaStats& st) {
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(samples.size(), 21u);
  double worst = 0;
  for (size_t k = 0; k < samples.size(); ++k) {
    EXPECT_NEAR(samples[k].t, 0.1 * k, 1e-15);
    worst = std::fmax(worst, std::fabs(samples[k].y1 - p.exact(samples[k].t)));
    EXPECT_NEAR(samples[k].y2, 2 * samples[k].y1, 1e-9);
  }
  EXPECT_LT(worst, 1e-8);
  EXPECT_EQ(samples.back().t, 2.0);
  EXPECT_EQ(st.t_reached, 2.0);
  EXPECT_NEAR(y[0], p.exact(2.0), 1e-8);  // the final state is the state at t1
  EXPECT_NEAR(y[1], 2 * y[0], 1e-9);
}

TEST(IdaDriver, DecayFollowsTheSolutionToTheEnd) {
  DecayProblem p;
  std::vector<Sample> s;
  std::vector<double> y;
  const IdaStats st = run(p, s, y);
  expect_follows_solution(p, s, y, st);
  EXPECT_TRUE(st.breakpoint_times.empty());
  EXPECT_TRUE(p.restart_times.empty());
}

TEST(IdaDriver, BreakpointIsHitExactlyAndRestarted) {
  DecayProblem p;
  p.step_input = true;
  std::vector<Sample> s;
  std::vector<double> y;
  const IdaStats st = run(p, s, y);
  expect_follows_solution(p, s, y, st);
  ASSERT_EQ(st.breakpoint_times.size(), 1u);
  EXPECT_EQ(st.breakpoint_times[0], 0.5);
  ASSERT_EQ(p.restart_times.size(), 1u);
  EXPECT_EQ(p.restart_times[0], 0.5);
  EXPECT_FALSE(p.restart_was_event[0]);
}

TEST(IdaDriver, EndAtABreakpointIsAStopTime) {
  DecayProblem p;
  p.step_input = true;
  p.end_breakpoint = true;
  std::vector<Sample> s;
  std::vector<double> y;
  const IdaStats st = run(p, s, y);
  expect_follows_solution(p, s, y, st);
  EXPECT_EQ(st.breakpoint_times.size(), 1u);  // the end is no restart
  // The last segment ends at the end's breakpoint: its inputs (and the last sample's) are the
  // left limit there, as at every breakpoint.
  EXPECT_EQ(p.segment_end(), 2.0);
}

TEST(IdaDriver, EventIsLocatedAndRestarted) {
  DecayProblem p;
  p.switch_level = 0.3;  // e^-t = 0.3 at t = ln(10/3)
  std::vector<Sample> s;
  std::vector<double> y;
  const IdaStats st = run(p, s, y);
  expect_follows_solution(p, s, y, st);
  ASSERT_EQ(st.event_times.size(), 1u);
  EXPECT_NEAR(st.event_times[0], std::log(10.0 / 3.0), 1e-9);
  ASSERT_EQ(p.restart_times.size(), 1u);
  EXPECT_TRUE(p.restart_was_event[0]);
}

// IDA's counters restart at every re-initialization, and the driver adds them up. They must add
// up to the problem's own count of residual and Jacobian calls, also when an event falls right
// at the last accepted step (the driver then restarts from that step's state without going back:
// the statistics of that segment were collected twice).
TEST(IdaDriver, StatisticsAreCollectedOncePerSegment) {
  for (double switch_time : {-1.0, 0.7, 1e-14}) {
    DecayProblem p;
    p.switch_time = switch_time;
    p.step_input = true;
    std::vector<Sample> s;
    std::vector<double> y;
    const IdaStats st = run(p, s, y);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(st.residual_evals, p.residual_calls) << "event at " << switch_time;
    EXPECT_EQ(st.jacobian_evals, p.jacobian_calls) << "event at " << switch_time;
    EXPECT_EQ(st.event_times.size(), switch_time > 0 ? 1u : 0u);
    EXPECT_EQ(st.breakpoint_times.size(), 1u);
  }
}

// An IDA failure names IDA's flag and keeps IDA's own message (IDAGetReturnFlagName's string is
// malloc'd: it leaked 24 bytes on every failure, found by the leak checker of the sanitizer build).
TEST(IdaDriver, FailureNamesTheFlagAndTheTime) {
  DecayProblem p;
  p.fail_after = 0;  // no step can be taken
  std::vector<Sample> s;
  std::vector<double> y;
  const IdaStats st = run(p, s, y);
  ASSERT_FALSE(st.ok);
  EXPECT_EQ(st.status, "integration_failed");
  EXPECT_NE(st.message.find("IDA failed at t = 0 "), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("(IDA_REP_RES_ERR)"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("IDA: IDASolve: "), std::string::npos) << st.message;
  EXPECT_EQ(st.t_reached, 0.0);
  EXPECT_EQ(s.size(), 1u);  // the initial state
}

// A SolveError thrown by the output (the multibody front end throws one for a sensor that is not
// finite) ends the run with its status and message; the sample is not counted as written.
TEST(IdaDriver, OutputErrorStopsTheRun) {
  DecayProblem p;
  std::vector<Sample> s;
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o;
  o.t1 = 2;
  o.output_step = 0.1;
  const IdaStats st = integrate(p, o, y, yp, [&](double t, const double* yy, const double*) {
    if (t > 0.45) throw SolveError("non_finite", "sensor x is NaN at t = " + std::to_string(t));
    s.push_back({t, yy[0], yy[1]});
    return true;
  });
  ASSERT_FALSE(st.ok);
  EXPECT_EQ(st.status, "non_finite");
  EXPECT_NE(st.message.find("sensor x is NaN at t = 0.5"), std::string::npos) << st.message;
  EXPECT_EQ(s.size(), 5u);
  EXPECT_DOUBLE_EQ(st.t_reached, 0.5);
}

// IdaOptions::after_fresh_factorization sees the step after each fresh factorization (the
// decay's only one, the first Newton matrix) with that step's state; false ends the run there as
// integration_failed, the samples before it kept.
TEST(IdaDriver, AFreshFactorizationCheckCanEndTheRun) {
  DecayProblem p;
  std::vector<Sample> s;
  std::vector<double> y;
  IdaOptions o = decay_options();
  std::vector<double> seen;
  o.after_fresh_factorization = [&](double t, const double* yy) {
    seen.push_back(t);
    EXPECT_NEAR(yy[0], p.exact(t), 1e-6);
    return true;
  };
  IdaStats st = run(p, s, y, o);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_EQ(seen.size(), 1u);  // one fresh factorization: the rest refactor on its pivots
  EXPECT_GT(seen[0], 0.0);
  EXPECT_EQ(s.size(), 21u);
  s.clear();
  o.after_fresh_factorization = [](double, const double*) { return false; };
  st = run(p, s, y, o);
  ASSERT_FALSE(st.ok);
  EXPECT_EQ(st.status, "integration_failed");
  EXPECT_NE(st.message.find("pivots degraded"), std::string::npos) << st.message;
  EXPECT_EQ(st.t_reached, seen[0]);
  EXPECT_EQ(s.size(), 1u);  // the initial state only: the step's own samples are not written
}

// A setting IDA refuses (its maximum order must be 1 to 5) is an internal error naming the call,
// not a run that goes on with IDA's default (every SUNDIALS flag goes through one check).
TEST(IdaDriver, RefusedSettingNamesTheSundialsCall) {
  DecayProblem p;
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o;
  o.t1 = 2;
  o.max_order = 0;
  try {
    integrate(p, o, y, yp, [](double, const double*, const double*) { return true; });
    FAIL() << "a maximum order of 0 was accepted";
  } catch (const SolveError& e) {
    EXPECT_EQ(e.status, "internal_error");
    EXPECT_NE(std::string(e.what()).find("IDASetMaxOrd"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("IDA_ILL_INPUT"), std::string::npos) << e.what();
  }
}

TEST(IdaDriverSensitivities, FollowTheClosedFormThroughABreakpoint) {
  DecayProblem p;
  p.step_input = true;  // a breakpoint at 0.5: the sensitivities restart there
  DecayInitialValue sens;
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o = decay_options();
  o.sensitivities = &sens;
  double worst = 0;
  int rows = 0;
  o.sensitivity_output = [&](double t, const double*, const double*, const double* const* s, const double* const*) {
    worst = std::max({worst, std::fabs(s[0][0] - std::exp(-t)), std::fabs(s[0][1] - 2 * std::exp(-t))});
    ++rows;
  };
  const IdaStats st = integrate(p, o, y, yp, [](double, const double*, const double*) { return true; });
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(rows, 21);
  EXPECT_LT(worst, 1e-8);
  EXPECT_GT(st.sensitivity_residual_evals, 0);
  EXPECT_TRUE(st.sensitivity_failure.empty());
}

// Five sensitivities: IDAS solves them one after the other, mbdae's linear solver all five at the
// first (klu_linear_solver_expect_batch: four in one pass over the factors, then one). Copy i is
// 2^i copy 0 bit for bit at every sample, and copy 0 the closed form.
TEST(IdaDriverSensitivities, SeveralAreSolvedTogetherAndEachIsItsOwn) {
  DecayProblem p;
  p.step_input = true;
  DecayInitialValue sens;
  sens.copies = 5;
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o = decay_options();
  o.sensitivities = &sens;
  double worst = 0;
  int rows = 0, unequal = 0;
  o.sensitivity_output = [&](double t, const double*, const double*, const double* const* s, const double* const*) {
    worst = std::max({worst, std::fabs(s[0][0] - std::exp(-t)), std::fabs(s[0][1] - 2 * std::exp(-t))});
    for (int i = 1; i < 5; ++i)
      for (int k = 0; k < 2; ++k) unequal += s[i][k] != std::ldexp(s[0][k], i);
    ++rows;
  };
  const IdaStats st = integrate(p, o, y, yp, [](double, const double*, const double*) { return true; });
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_EQ(rows, 21);
  EXPECT_EQ(unequal, 0);
  EXPECT_LT(worst, 1e-8);
}

// Sensitivities that cannot go on stop; the run goes on without them to its end.
TEST(IdaDriverSensitivities, AFailureStopsThemNotTheRun) {
  DecayProblem p;
  DecayInitialValue sens;
  sens.fail_after = 1.0;
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o;
  o.t1 = 2;
  o.output_step = 0.1;
  o.sensitivities = &sens;
  double last_sensitivity = -1, last_sample = -1;
  o.sensitivity_output = [&](double t, const double*, const double*, const double* const*, const double* const*) {
    last_sensitivity = t;
  };
  const IdaStats st = integrate(p, o, y, yp, [&](double t, const double*, const double*) {
    last_sample = t;
    return true;
  });
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_DOUBLE_EQ(last_sample, 2.0);
  EXPECT_LE(last_sensitivity, 1.0 + 1e-12);
  EXPECT_GT(last_sensitivity, 0.5);
  EXPECT_NE(st.sensitivity_failure.find("IDA failed with the sensitivities"), std::string::npos) << st.sensitivity_failure;
  EXPECT_NEAR(y[0], std::exp(-2.0), 1e-5);
}

// Sensitivities whose local error test fails where their Newton iteration converges (forcing
// that is rough in t, a hash of it): out of the test for windows after each start of IDA
// (core/ida_sensitivities.cpp, sensitivities_out_of_test), they go on to the end.
TEST(IdaDriverSensitivities, AFailureInTheirErrorTestTakesThemOutOfIt) {
  struct Rough : DecayInitialValue {
    int residual(double t, const double*, const double*, const double*, const double* const* s, const double* const* sp,
                 double* const* r) override {
      const double g = 1e3 * (std::fmod(std::fabs(std::sin(t * 1e5) * 43758.5453), 1.0) - 0.5);
      r[0][0] = sp[0][0] + s[0][0] - g;
      r[0][1] = s[0][1] - 2 * s[0][0];
      return 0;
    }
  };
  DecayProblem p;
  Rough sens;
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o;
  o.t1 = 2;
  o.output_step = 0.1;
  o.sensitivities = &sens;
  double last_sensitivity = -1;
  o.sensitivity_output = [&](double t, const double*, const double*, const double* const*, const double* const*) {
    last_sensitivity = t;
  };
  const IdaStats st = integrate(p, o, y, yp, [](double, const double*, const double*) { return true; });
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_TRUE(st.sensitivity_failure.empty()) << st.sensitivity_failure;
  EXPECT_GE(st.sensitivity_test_off_time, 0.0);
  EXPECT_DOUBLE_EQ(last_sensitivity, 2.0);
  EXPECT_NEAR(y[0], std::exp(-2.0), 1e-5);
}

// IDAS evaluates the state's residual at each step's converged state for the sensitivity
// residual's `residual` argument: evaluated where the problem reads it, skipped where it does
// not, with the same steps and the same numbers either way.
TEST(IdaDriverSensitivities, ConvergedStateResidualOnlyWhereRead) {
  struct Unread : DecayInitialValue {
    bool reads_state_residual() const override { return false; }
  };
  long calls[2] = {0, 0}, steps[2] = {0, 0};
  std::vector<double> last[2];
  for (int k = 0; k < 2; ++k) {
    DecayProblem p;
    DecayInitialValue reads;
    Unread unread;
    std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
    IdaOptions o;
    o.t1 = 2;
    o.rtol = 1e-8;
    o.atol = 1e-10;
    o.output_step = 0.5;
    o.sensitivities = k == 0 ? static_cast<SensitivityProblem*>(&reads) : &unread;
    o.sensitivity_output = [&](double, const double*, const double*, const double* const* s, const double* const*) {
      last[k] = {s[0][0], s[0][1]};
    };
    const IdaStats st = integrate(p, o, y, yp, [](double, const double*, const double*) { return true; });
    ASSERT_TRUE(st.ok) << st.message;
    last[k].push_back(y[0]);
    calls[k] = p.residual_calls;
    steps[k] = st.steps;
  }
  EXPECT_EQ(steps[0], steps[1]);
  EXPECT_EQ(last[0], last[1]);  // bit for bit
  // One per step but the first (its vector is known from the first sensitivity residual on).
  EXPECT_GE(calls[0] - calls[1], steps[0] - 1) << calls[0] << " against " << calls[1];
}

}  // namespace
}  // namespace mbdae
