// SUNDIALS IDA on a DaeProblem with a KLU sparse direct solver (core/klu_linear_solver.h, or
// core/reduced_linear_solver.h with IdaOptions::reduced_newton when the problem declares
// kinematic rows).
//
// Integration runs in one-step mode; output samples are interpolated from IDA's history
// (IDAGetDky), so sampling never shortens a step. Breakpoints are hit exactly with a stop time;
// events (sign changes of the problem's switching functions) are located by IDA's root finding.
// At both, the problem restarts itself (new modes, consistent y') and IDA is re-initialized.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "core/dae_problem.h"
#include "core/sensitivity_problem.h"

namespace mbdae {

struct IdaOptions {
  double t0 = 0, t1 = 1;
  double rtol = 1e-6, atol = 1e-8;
  double output_step = 0.01;  // sample spacing (0: only t0 and t1)
  double max_step = 0;        // 0: no limit
  double initial_step = 0;    // 0: IDA's own choice
  int max_order = 5;
  long max_steps = 2000000;   // per call of IDASolve (one step each here: no limit on the run)
  // The step budget of the run (all its steps, across restarts): the run fails (status
  // "step_limit") when it has taken max_total_steps steps, or earlier, as soon as the rate of
  // each of its last 10 windows of 10000 steps projects more than max_total_steps over [t0, t1]
  // (a load or a motion growing without bound, such as a torque exp(1000 t), makes the step
  // collapse: such a run never ends). 0: no budget. The longest run measured so far took 1.0e7
  // steps over 1000 s (docs/extreme-cases.md).
  long max_total_steps = 100000000;
  double nonlinear_convergence = 0.33;  // IDA's epcon
  double delta_cj = 0.01;               // relative change of cj that forces a new Newton matrix
  const std::atomic<bool>* stop = nullptr;  // set (from a signal handler) to stop after the next step
  // Newton solves reduced by the problem's kinematic rows (core/reduced_linear_solver.h); off
  // until two tests at the noise floor are revisited (docs/performance.md, "The reduced Newton
  // solve").
  bool reduced_newton = false;
  // Called after an accepted step during which the Newton matrix was factored afresh (its reused
  // pivots had degraded: the matrix nearly singular), with that step's t and y; false ends the
  // run there as integration_failed, for the caller to diagnose. Null: not asked.
  std::function<bool(double, const double*)> after_fresh_factorization;
  // Forward sensitivities of the solution (IDAS, core/sensitivity_problem.h), or null. Each
  // sample's (t, y, y', s_i, s_i') go to sensitivity_output right after the sample went to
  // `output` (y' null where `output` gets none).
  SensitivityProblem* sensitivities = nullptr;
  std::function<void(double, const double*, const double*, const double* const*, const double* const*)>
      sensitivity_output;
};

struct IdaStats {
  long steps = 0, residual_evals = 0, jacobian_evals = 0, linear_setups = 0;
  long error_test_failures = 0, nonlinear_iterations = 0, nonlinear_failures = 0;
  long restarts = 0;
  long fresh_factorizations = 0;  // KLU factorizations with a new pivot order (others refactor)
  std::vector<double> event_times;      // located switching events
  std::vector<double> breakpoint_times;  // stops at input discontinuities
  // The sensitivity equations' own work (IdaOptions::sensitivities; 0 without).
  long sensitivity_residual_evals = 0, sensitivity_nonlinear_iterations = 0;
  long sensitivity_error_test_failures = 0, sensitivity_nonlinear_failures = 0;
  std::string sensitivity_failure;  // non-empty: IDA failed with them, and the run went on without
  double sensitivity_test_off_time = -1;  // >= 0: where a failure first took them out of the error test
  int sensitivity_fallbacks = 0;           // retries from the last step (out of their error test)
  double cpu_seconds = 0;
  double last_step = 0;
  double t_reached = 0;
  bool ok = true;
  std::string status = "ok";  // or "integration_failed"
  std::string message;
};

// `output(t, y, yp)` receives each sample; returning false stops the run early.
IdaStats integrate(DaeProblem& problem, const IdaOptions& options, std::vector<double>& y,
                   std::vector<double>& yp,
                   const std::function<bool(double, const double*, const double*)>& output);

}  // namespace mbdae
