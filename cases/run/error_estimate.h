// A global error estimate on request (`mbdae run --error-estimate`, or `error_estimate: true` on
// an integration step): the run is repeated at rtol / 100 (and atol / 100), and each output
// sensor's largest difference to that tighter run over the common samples is its estimated
// global error. The estimate is flagged when it exceeds what the tolerance promises,
// 10 rtol times the sensor's scale (its largest magnitude in the tighter run).
// Built on the public API (cases/mbdae.h): run() gives both results in memory.
#pragma once

#include <string>
#include <vector>

#include "cases/mbdae.h"

namespace mbdae {

struct ErrorEstimate {
  double rtol = 0, atol = 0;                 // of the run estimated
  double reference_rtol = 0, reference_atol = 0;  // of the tighter run
  std::string reference_status;              // "ok" or the tighter run's failure
  std::vector<std::string> sensors;
  std::vector<double> error, scale;          // per sensor
  std::vector<std::string> exceeded;         // sensors whose error exceeds 10 rtol scale
  nlohmann::ordered_json to_json() const;
};

// Whether the scene asks for an estimate (error_estimate: true on an integration step).
bool error_estimate_requested(const Scene& scene);

// Repeats the run `first` (made with `options`) at rtol / factor, atol / factor.
ErrorEstimate estimate_global_error(const Scene& scene, const RunOptions& options, const Result& first,
                                    double factor = 100.0);

// The command line's run with an estimate: runs through `sinks`, estimates, adds "error_estimate"
// to the result's summary (rewriting `summary_path` when it is not empty), and warns on stderr
// for every sensor over its promise.
Result run_with_error_estimate(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks,
                               const std::string& summary_path);

}  // namespace mbdae
