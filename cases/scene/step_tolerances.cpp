#include "cases/scene/step_tolerances.h"

namespace mbdae {

StepTolerances step_tolerances(const System& sys, const double* q, const AnalysisStep& step, double rtol,
                               double atol_override) {
  StepTolerances t;
  t.scales = model_scales(sys, q, step.t0, step.t_end);
  if (step.length_scale > 0) t.scales.length = step.length_scale;
  if (step.time_scale > 0) t.scales.time = t.scales.fast_time = step.time_scale;
  const double aq = atol_override > 0 ? atol_override
                    : step.atol > 0   ? step.atol
                                      : default_position_atol(t.scales, rtol);
  t.absolute = absolute_tolerances(t.scales, aq);
  if (step.atol_rotation > 0) {
    t.absolute.rotation = step.atol_rotation;
    t.absolute.rotation_rate = step.atol_rotation / t.scales.time;
  }
  if (step.atol_velocity > 0) t.absolute.velocity = step.atol_velocity;
  const double rate = default_baumgarte_rate(t.scales);
  t.baumgarte_alpha = step.baumgarte_alpha >= 0 ? step.baumgarte_alpha : rate;
  t.baumgarte_beta = step.baumgarte_beta >= 0 ? step.baumgarte_beta : rate;
  return t;
}

nlohmann::ordered_json to_json(const StepTolerances& t) {
  return {{"length_scale", t.scales.length},
          {"time_scale", t.scales.time},
          {"fast_time_scale", t.scales.fast_time},
          {"atol_position", t.absolute.position},
          {"atol_rotation", t.absolute.rotation},
          {"atol_velocity", t.absolute.velocity},
          {"atol_rotation_rate", t.absolute.rotation_rate}};
}

}  // namespace mbdae
