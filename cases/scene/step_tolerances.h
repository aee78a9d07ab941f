// The tolerances of an integration step in the model's units: the scene's
// values where given, else derived from the model's scales (formulation/tolerance_scales.h).
#pragma once

#include <nlohmann/json.hpp>

#include "cases/scene/scene.h"
#include "formulation/tolerance_scales.h"

namespace mbdae {

struct StepTolerances {
  ModelScales scales;
  AbsoluteTolerances absolute;
  // rtol / the scene's rtol when the run's rtol differs from the scene's and no atol is given
  // with it: the factor applied to the scene's atol, atol_rotation and atol_velocity (else 1).
  double scene_atol_factor = 1.0;
};

// q: the configuration the step starts from; rtol the run's; atol_override > 0 replaces the
// step's atol (else the scene's absolute tolerances are scaled by rtol / step.rtol).
StepTolerances step_tolerances(const System& sys, const double* q, const AnalysisStep& step, double rtol,
                               double atol_override);
// For summary.json: the scales and the absolute tolerances used.
nlohmann::ordered_json to_json(const StepTolerances& t);

}  // namespace mbdae
