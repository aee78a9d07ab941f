// A global error estimate on request (`mbdae run --error-estimate`, or `error_estimate: true` on
// an integration step), by tolerance proportionality (docs/formulation.md, "Global error
// estimate"): the run is repeated at rtol / k (and atol / k where the run's atol is given), k = 3,
// in a second thread while the run itself goes on. If the error follows the tolerance, the
// difference d of the two runs is (1 - 1/k) times the run's error; so each sensor's estimate is
//   max(d / (1 - 1/k), rounding floor)
// where the rounding floor is steps * eps * scale (what double precision cannot resolve over that
// many steps). A tighter comparison keeps the estimate within a factor 2 of the error for any
// order of convergence from 0.3 up (a looser one would not: d grows like k^order). The penalty
// formulation's comparison also has 10 times the penalty, so that its constraint bias (about
// 1 / penalty) shows in d. When the two runs agree to rounding (the step sequence did not change
// with the tolerance: a floor), the run is compared with a second formulation at its tolerance
// instead, and that whole difference is the estimate (an upper bound of the run's error plus the
// other's). The constraint violations |Phi| and |Phi_q v| relative to the length scale are
// reported beside the sensors. Anything over the promise, 10 rtol of its scale, is flagged in
// `exceeded` and warned about on stderr.
// Built on the public API (cases/mbdae.h): run() gives both results in memory.
#pragma once

#include <string>
#include <vector>

#include "cases/mbdae.h"

namespace mbdae {

struct ErrorEstimate {
  std::string method;                 // "tolerance_proportionality" or "second_formulation"
  double rtol = 0, atol = 0, factor = 1.0 / 3;  // of the run estimated; comparison at factor * rtol
  std::string formulation;
  long steps = 0;
  double cpu_seconds = 0;             // the run's integration CPU
  // The comparison run (the one actually used for the estimate).
  double comparison_rtol = 0, comparison_atol = 0;
  std::string comparison_formulation, comparison_status = "not_run";
  long comparison_steps = 0;
  double comparison_cpu_seconds = 0;  // every comparison run made (a fallback included)
  double comparison_penalty = 0;      // > 0: the penalty of the comparison run (penalty formulation)
  std::vector<std::string> sensors, units;
  // Per sensor: the estimate, its scale (largest |x| in the run), the difference of the two runs
  // and the rounding floor.
  std::vector<double> error, scale, difference, floor;
  // Constraint violations of the run (max over its steps) and the scales they are judged on.
  double position_violation = 0, velocity_violation = 0, length_scale = 0, time_scale = 0;
  std::vector<std::string> exceeded;  // sensors (and "constraints.position"/"constraints.velocity")
                                      // over 10 rtol of their scale
  bool ok() const { return comparison_status == "ok"; }
  double relative(size_t k) const { return scale[k] > 0 ? error[k] / scale[k] : 0.0; }
  nlohmann::ordered_json to_json() const;
};

// Whether the scene asks for an estimate (error_estimate: true on an integration step).
bool error_estimate_requested(const Scene& scene);

// The scene of the comparison run: the penalty formulation's with 10 times the penalty (`penalty`
// set to it), else the scene itself.
Scene comparison_scene(const Scene& scene, const RunOptions& options, double& penalty);

// The options of the comparison run of a run made with `options`: rtol / factor, atol / factor
// (atol 0 stays 0: derived from the rtol), or factor times both when rtol / factor is below 1e-14;
// no printing, stopped by `stop`.
RunOptions comparison_options(const Scene& scene, const RunOptions& options, double factor,
                              const std::atomic<bool>* stop);

// The estimate from the run `first` and its comparison run `second` (made with
// comparison_options). Runs the second-formulation fallback (sequentially) when the two agree to
// rounding.
ErrorEstimate compare_runs(const Scene& scene, const RunOptions& options, const Result& first,
                           const Result& second, double factor = 3.0);

// Makes the comparison run after `first` (sequentially) and estimates.
ErrorEstimate estimate_global_error(const Scene& scene, const RunOptions& options, const Result& first,
                                    double factor = 3.0);

// Runs the scene through `sinks` and, in a second thread at the same time, its comparison run;
// estimates and stores "error_estimate" in the result's summary. A stop request (options.stop)
// ends both: the result is "interrupted" even if the run itself had finished (its rows kept).
Result run_estimated(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks,
                     ErrorEstimate& estimate);

// The warnings of an estimate on stderr (one per exceeded item, and a failed comparison).
void warn_about(const ErrorEstimate& e);

// The command line's run with an estimate: run_estimated, then summary.json rewritten at
// `summary_path` (when not empty) and the warnings (unless `warn` is false).
Result run_with_error_estimate(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks,
                               const std::string& summary_path, bool warn = true);

}  // namespace mbdae
