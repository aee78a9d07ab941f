#include "cases/run/error_target.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cases/scene/analysis_types.h"
#include "cases/run/error_estimate.h"
#include "cases/scene/field_ranges.h"
#include "cases/scene/scene_validation.h"
#include "core/output.h"

namespace mbdae {
namespace {

using json = nlohmann::ordered_json;

const AnalysisStep* last_integration_step(const Scene& scene) {
  const AnalysisStep* found = nullptr;
  for (const AnalysisStep& s : scene.steps)
    if (integrates(s)) found = &s;
  return found;
}

// One try: the run through fresh sinks and its estimate.
Result try_once(const Scene& scene, const RunOptions& options, const SinkFactory& make_sinks, ErrorEstimate& e) {
  return run_estimated(scene, options, make_sinks ? make_sinks() : std::vector<Sink*>{}, e);
}

// The largest margin * estimate / target over the targeted sensors (> 1: not met); -1 when a
// targeted sensor has no estimate.
// A relative target uses each sensor's scale, but at least 1e-3 of the largest scale of its unit:
// a sensor that stays near 0 while others of its unit move is not held below their rounding.
double worst_ratio(const ErrorEstimate& e, const ErrorControl& c, json& sensors) {
  double worst = 0;
  for (size_t k = 0; k < e.sensors.size(); ++k) {
    const bool named = std::find(c.sensors.begin(), c.sensors.end(), e.sensors[k]) != c.sensors.end();
    if (!c.sensors.empty() && !named) continue;
    double unit_scale = 0;
    for (size_t j = 0; j < e.sensors.size(); ++j)
      if (e.units[j] == e.units[k]) unit_scale = std::max(unit_scale, e.scale[j]);
    const double target = c.sensors.empty() ? c.target * std::max(e.scale[k], 1e-3 * unit_scale) : c.target;
    const double ratio = target > 0 ? kErrorTargetMargin * e.error[k] / target : (e.error[k] > 0 ? HUGE_VAL : 0.0);
    sensors[e.sensors[k]] = {{"target", target}, {"estimate", e.error[k]}, {"scale", e.scale[k]}};
    worst = std::max(worst, ratio);
  }
  return e.ok() && !sensors.empty() ? worst : -1.0;
}

// The scene's atol per unit rtol (0: atol derived from rtol by the model's scales).
double atol_per_rtol(const Scene& scene, const RunOptions& options) {
  const AnalysisStep* step = last_integration_step(scene);
  const double rtol = options.rtol > 0 ? options.rtol : step ? step->rtol : 1e-6;
  const double atol = options.atol > 0 ? options.atol : step ? step->atol : 0.0;
  return atol / rtol;
}

void write_summary(const std::string& path, const Result& r) {
  if (!path.empty()) write_json_file(path, r.summary);
}

// The summary's error_target, and accuracy_not_met (exit 3) when the search ended without it.
void conclude(Result& r, const ErrorControl& control, const ErrorEstimate& e, bool met, const std::string& why,
              double worst, const json& sensors, const json& tries) {
  const double rtol = tries.back()["rtol"].get<double>();
  r.summary["error_target"] = {
      {"target", control.target}, {"relative_to_scale", control.sensors.empty()}, {"margin", kErrorTargetMargin},
      {"max_tries", kErrorTargetMaxTries}, {"met", met},
      {"chosen", {{"formulation", e.formulation}, {"rtol", rtol}, {"atol", e.atol}}},
      {"sensors", sensors}, {"tries", tries}};
  if (!r.ok() || met) return;
  r.status = r.summary["status"] = "accuracy_not_met";
  const std::string by = worst > 0 ? "; the estimate times the margin is " + format_number(worst) + " times the target" : "";
  r.message = r.summary["message"] = "error target " + format_number(control.target) + " not met: " + why + by +
                                     " at rtol " + format_number(rtol) + " (results are that try's)";
  r.exit_code = 3;
  std::fprintf(stderr, "mbdae: %s\n", r.message.c_str());
}

}  // namespace

ErrorControl error_control(const Scene& scene, const ErrorControl& requested) {
  ErrorControl c = requested;
  if (const AnalysisStep* s = last_integration_step(scene)) {
    c.estimate = c.estimate || error_estimate_requested(scene);
    if (!(c.target > 0)) c.target = s->error_target;
    if (c.sensors.empty() && !(requested.target > 0)) c.sensors = s->error_sensors;
  }
  return c;
}

std::vector<std::string> output_sensor_names(const Scene& scene) {
  if (!scene.columns.empty()) return scene.columns;
  std::vector<std::string> names;
  for (const auto& s : scene.model.sensors) names.push_back(s.name);
  return names;
}

std::vector<std::string> check_error_sensors(const Scene& scene, const std::vector<std::string>& names,
                                             const std::string& option) {
  const std::vector<std::string> known = output_sensor_names(scene);
  std::vector<std::string> out;
  for (const auto& n : names)
    if (std::find(known.begin(), known.end(), n) == known.end())
      out.push_back(option + ": no output sensor named '" + n + "'" + did_you_mean(n, known));
  return out;
}

Result run_controlled(const Scene& scene, const RunOptions& options, const ErrorControl& control,
                      const SinkFactory& make_sinks, const std::string& summary_path) {
  if (!(control.target > 0)) {
    const std::vector<Sink*> sinks = make_sinks ? make_sinks() : std::vector<Sink*>{};
    return control.estimate ? run_with_error_estimate(scene, options, sinks, summary_path, control.warnings)
                            : run(scene, options, sinks);
  }
  const AnalysisStep* step = last_integration_step(scene);
  const double ratio = atol_per_rtol(scene, options);
  // First try: rtol = E when E is relative (the promise keeps the error near rtol), else the scene's.
  double rtol = control.sensors.empty() ? control.target : (options.rtol > 0 ? options.rtol : step ? step->rtol : 1e-6);
  rtol = std::clamp(rtol, 1e-13, 0.5);
  json tries = json::array(), sensors;
  Result r;
  ErrorEstimate e;
  double previous = -1, worst = -1;
  bool met = false;
  std::string formulation;  // set when the search leaves the scene's formulation
  std::string why = "6 tries made";
  for (int k = 0; k < kErrorTargetMaxTries; ++k) {
    RunOptions opt = options;
    if (!formulation.empty()) opt.formulation = formulation;
    opt.rtol = rtol;
    opt.atol = ratio > 0 ? std::min(1.0, ratio * rtol) : 0.0;
    e = ErrorEstimate{};
    r = try_once(scene, opt, make_sinks, e);
    sensors = json::object();
    worst = r.ok() ? worst_ratio(e, control, sensors) : -1.0;
    tries.push_back({{"formulation", e.formulation}, {"rtol", opt.rtol}, {"atol", e.atol}, {"status", r.status},
                     {"worst_margin_ratio", worst},
                     {"cpu_seconds", {{"run", e.cpu_seconds}, {"estimate", e.comparison_cpu_seconds}}}});
    // A solve that failed at a loose tolerance (a contact missed, Newton lost) may pass tighter.
    const bool retry = r.exit_code == 3 && r.status != "interrupted" && k + 1 < kErrorTargetMaxTries && rtol > 1e-12;
    if (!r.ok() && retry) {
      rtol /= 10;
      continue;
    }
    if (!r.ok()) break;
    if (worst < 0) { why = "no error estimate (comparison run " + e.comparison_status + ")"; break; }
    if (worst <= 1) { met = true; break; }
    if (previous > 0 && worst > 0.5 * previous) {
      // index3 at its rounding floor: go on with index2-ggl, whose error keeps falling with rtol
      // (docs/work-precision.md), unless the caller chose the formulation.
      const std::string used = opt.formulation.empty() ? (step ? step->formulation : "") : opt.formulation;
      if (options.formulation.empty() && formulation.empty() && used.rfind("index3", 0) == 0) {
        formulation = "index2-ggl";
        previous = -1;
        continue;
      }
      why = "the estimate stopped falling with rtol (a floor)";
      break;
    }
    if (rtol <= 1e-13) { why = "rtol reached 1e-13"; break; }
    previous = worst;
    rtol = std::max(1e-13, rtol * std::clamp(0.5 / worst, 1e-4, 0.5));
  }
  conclude(r, control, e, met, why, worst, sensors, tries);
  write_summary(summary_path, r);
  if (control.warnings && (r.ok() || r.status == "accuracy_not_met")) warn_about(e);
  return r;
}

}  // namespace mbdae
