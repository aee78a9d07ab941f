#include "cases/scene/step_tolerances.h"

namespace mbdae {

StepTolerances step_tolerances(const System& sys, const double* q, const AnalysisStep& step, double rtol,
                               double atol_override) {
  StepTolerances t;
  t.scales = model_scales(sys, q, step.t0, step.t_end);
  if (step.length_scale > 0) t.scales.length = step.length_scale;
  if (step.time_scale > 0) t.scales.time = t.scales.fast_time = step.time_scale;
  // A run's rtol (--rtol, RunOptions::rtol) other than the scene's scales the absolute
  // tolerances the scene fixes by the same ratio, unless an atol is given with it: a looser rtol
  // then buys a quicker run also on scenes that fix atol.
  if (atol_override <= 0 && step.rtol > 0 && rtol > 0 && rtol != step.rtol &&
      (step.atol > 0 || step.atol_rotation > 0 || step.atol_velocity > 0))
    t.scene_atol_factor = rtol / step.rtol;
  const double f = t.scene_atol_factor;
  const double aq = atol_override > 0 ? atol_override
                    : step.atol > 0   ? f * step.atol
                                      : default_position_atol(t.scales, rtol);
  t.absolute = absolute_tolerances(t.scales, aq);
  if (step.atol_rotation > 0) {
    t.absolute.rotation = f * step.atol_rotation;
    t.absolute.rotation_rate = t.absolute.rotation / t.scales.time;
  }
  if (step.atol_velocity > 0) t.absolute.velocity = f * step.atol_velocity;
  return t;
}

nlohmann::ordered_json to_json(const StepTolerances& t) {
  nlohmann::ordered_json j = {{"length_scale", t.scales.length},
                              {"time_scale", t.scales.time},
                              {"fast_time_scale", t.scales.fast_time},
                              {"atol_position", t.absolute.position},
                              {"atol_rotation", t.absolute.rotation},
                              {"atol_velocity", t.absolute.velocity},
                              {"atol_rotation_rate", t.absolute.rotation_rate}};
  if (t.scene_atol_factor != 1.0) j["scene_atol_scaled_by"] = t.scene_atol_factor;
  return j;
}

}  // namespace mbdae
