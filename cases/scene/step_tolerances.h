// The tolerances and stabilization of an integration step in the model's units: the scene's
// values where given, else derived from the model's scales (formulation/tolerance_scales.h).
#pragma once

#include <nlohmann/json.hpp>

#include "cases/scene/scene.h"
#include "formulation/tolerance_scales.h"

namespace mbdae {

struct StepTolerances {
  ModelScales scales;
  AbsoluteTolerances absolute;
  double baumgarte_alpha = 0, baumgarte_beta = 0;
};

// q: the configuration the step starts from; atol_override > 0 replaces the step's atol.
StepTolerances step_tolerances(const System& sys, const double* q, const AnalysisStep& step, double rtol,
                               double atol_override);
// For summary.json: the scales and the absolute tolerances used.
nlohmann::ordered_json to_json(const StepTolerances& t);

}  // namespace mbdae
