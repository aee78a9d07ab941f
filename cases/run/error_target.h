// Accuracy on demand (`mbdae run --error-target E [--error-sensors a,b]`, `error_target` and
// `error_sensors` on the scene's integration step, `run(error_target=...)` in Python): the run is
// repeated with rtol and atol tightened together until the global error estimate
// (cases/run/error_estimate.h) times a safety margin of 3 is at most E for every sensor named
// (default: every output sensor, E then relative to each one's scale). Each try starts from
// proportionality (error ~ rtol); at most 6 tries, rtol within [1e-13, 0.5]; a try whose estimate
// did not fall by half when rtol fell is a floor: index3 (the scene's formulation, not one the
// caller chose) then goes on as index2-ggl, else the search ends. When E cannot be met the
// run ends with status accuracy_not_met (exit 3), keeping the most accurate try's rows.
// docs/formulation.md, "Accuracy on demand".
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cases/mbdae.h"

namespace mbdae {

struct ErrorControl {
  bool estimate = false;             // --error-estimate / error_estimate: true
  double target = 0;                 // > 0: --error-target / error_target
  std::vector<std::string> sensors;  // --error-sensors / error_sensors (empty: every output sensor)
  bool warnings = true;              // the estimate's warnings on stderr (off: summary.json only)
  bool active() const { return estimate || target > 0; }
};

constexpr double kErrorTargetMargin = 3.0;  // the estimate is within a factor 3 (docs/work-precision.md)
constexpr int kErrorTargetMaxTries = 6;

// The command line's (or Python's) request completed by the scene's own fields (the last
// integration step's error_estimate, error_target and error_sensors); the request wins.
ErrorControl error_control(const Scene& scene, const ErrorControl& requested);

// The output sensors' names of a scene (its `output` list, else every sensor of the model).
std::vector<std::string> output_sensor_names(const Scene& scene);
// `option`: message for every name in `names` that is not an output sensor (with "did you mean").
std::vector<std::string> check_error_sensors(const Scene& scene, const std::vector<std::string>& names,
                                             const std::string& option);

// The sinks of the next try (fresh writers from the second try on: results.csv and the rest are
// rewritten by each try); the factory owns them.
using SinkFactory = std::function<std::vector<Sink*>()>;

// The run as asked: with a target, the search above; with an estimate only, the run and its
// estimate (cases/run/error_estimate.h); else plain run(). summary.json (summary_path, when not
// empty) gets "error_estimate" and "error_target".
Result run_controlled(const Scene& scene, const RunOptions& options, const ErrorControl& control,
                      const SinkFactory& make_sinks, const std::string& summary_path);

}  // namespace mbdae
