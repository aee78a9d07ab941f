#include "cases/run/error_estimate.h"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>

#include "cases/run/run_stages.h"
#include "cases/run/sensitivities.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/field_ranges.h"
#include "core/output.h"
#include "formulation/formulation_registry.h"

namespace mbdae {
namespace {

using json = nlohmann::ordered_json;

constexpr double kMinRtol = 1e-14, kMaxRtol = 0.5;  // the range of cases/field_ranges.h

// The last integration step of a run's summary (its rtol, atol and statistics are those used).
const json* integration_step(const json& summary) {
  const json* found = nullptr;
  if (summary.contains("steps"))
    for (const auto& s : summary["steps"])
      if (s.value("type", std::string()) == "dynamics" || s.value("type", std::string()) == "kinematics") found = &s;
  return found;
}

// Largest |a - b| of column ca / cb over the samples both results have (matched by time) and the
// largest |a|.
void compare_column(const Result& a, const Result& b, int ca, int cb, double& difference, double& scale) {
  difference = scale = 0;
  const std::vector<double>& ta = a.data[0];
  const std::vector<double>& tb = b.data[0];
  size_t i = 0, j = 0;
  while (i < ta.size() && j < tb.size()) {
    const double eps = 1e-9 * std::max(1.0, std::fabs(ta[i]));
    if (ta[i] < tb[j] - eps) { ++i; continue; }
    if (tb[j] < ta[i] - eps) { ++j; continue; }
    difference = std::max(difference, std::fabs(a.data[ca][i] - b.data[cb][j]));
    scale = std::max(scale, std::fabs(a.data[ca][i]));
    ++i;
    ++j;
  }
}

double statistic(const json& step, const char* key) {
  return step.contains("statistics") ? step["statistics"].value(key, 0.0) : 0.0;
}

// The run's tolerances, formulation, cost and constraint violations from its summary.
void describe_run(const Result& first, ErrorEstimate& e) {
  const json* step = integration_step(first.summary);
  if (!step) return;
  e.rtol = step->value("rtol", 0.0);
  e.atol = step->value("atol", 0.0);
  e.formulation = step->value("formulation", std::string());
  e.steps = static_cast<long>(statistic(*step, "steps"));
  e.cpu_seconds = statistic(*step, "cpu_seconds");
  e.position_violation = statistic(*step, "max_position_violation_steps");
  e.velocity_violation = statistic(*step, "max_velocity_violation_steps");
  if (step->contains("tolerances")) {
    e.length_scale = (*step)["tolerances"].value("length_scale", 0.0);
    e.time_scale = (*step)["tolerances"].value("time_scale", 0.0);
  }
}

bool stabilized(const ErrorEstimate& e) {
  const Formulation* f = find_formulation(e.formulation);
  return f && (f->uses_penalty || f->uses_baumgarte);
}

// The estimate of every sensor from the differences to the comparison run, divided by `divisor`.
void fill_sensors(ErrorEstimate& e, const Result& first, const Result& second, double divisor) {
  e.sensors.clear();
  e.units.clear();
  e.error.clear();
  e.scale.clear();
  e.difference.clear();
  e.floor.clear();
  e.exceeded.clear();
  for (size_t c = 1; c < first.columns.size(); ++c) {
    const int cb = second.column_index(first.columns[c]);
    if (cb < 0) continue;
    double difference, scale;
    compare_column(first, second, static_cast<int>(c), cb, difference, scale);
    const std::string unit = c < first.units.size() ? first.units[c] : "";
    const double floor = std::max<double>(e.steps, 1) * DBL_EPSILON * scale;
    e.sensors.push_back(first.columns[c]);
    e.units.push_back(unit);
    e.difference.push_back(difference);
    e.floor.push_back(floor);
    e.scale.push_back(scale);
    e.error.push_back(std::max(difference / divisor, floor));
    if (scale > 0 && e.error.back() > 10 * e.rtol * scale) e.exceeded.push_back(first.columns[c]);
  }
  // The constraints are judged where they drift (index1, penalty): index3 and index2-ggl solve them
  // at every step (index3's |Phi_q v| is not an error of its output velocities: docs/formulation.md).
  if (!stabilized(e)) return;
  if (e.length_scale > 0 && e.position_violation > 10 * e.rtol * e.length_scale)
    e.exceeded.push_back("constraints.position");
  if (e.length_scale > 0 && e.time_scale > 0 && e.velocity_violation * e.time_scale > 10 * e.rtol * e.length_scale)
    e.exceeded.push_back("constraints.velocity");
}

// True when every sensor's difference is within its rounding floor: the comparison run took the
// same steps and cannot tell the error.
bool agrees_to_rounding(const ErrorEstimate& e) {
  for (size_t k = 0; k < e.sensors.size(); ++k)
    if (e.difference[k] > e.floor[k]) return false;
  return !e.sensors.empty();
}

void describe_comparison(const Result& second, ErrorEstimate& e) {
  e.comparison_status = second.status;
  const json* step = integration_step(second.summary);
  if (!step) return;
  e.comparison_rtol = step->value("rtol", 0.0);
  e.comparison_atol = step->value("atol", 0.0);
  e.comparison_formulation = step->value("formulation", std::string());
  e.comparison_steps = static_cast<long>(statistic(*step, "steps"));
  e.comparison_cpu_seconds += statistic(*step, "cpu_seconds");
}

// The run's rtol: the options' or the last integration step's.
double run_rtol(const Scene& scene, const RunOptions& options) {
  if (options.rtol > 0) return options.rtol;
  double rtol = 1e-6;
  for (const AnalysisStep& s : scene.steps)
    if (integrates(s)) rtol = s.rtol;
  return rtol;
}

// The last integration step's index, or -1.
int last_integration(const Scene& scene) {
  int k = -1;
  for (size_t i = 0; i < scene.steps.size(); ++i)
    if (integrates(scene.steps[i])) k = static_cast<int>(i);
  return k;
}

}  // namespace

Scene comparison_scene(const Scene& scene, const RunOptions& options, double& penalty) {
  penalty = 0;
  const int k = last_integration(scene);
  if (k < 0 || !scene.source) return scene;
  const AnalysisStep& step = scene.steps[k];
  const std::string formulation = options.formulation.empty() ? step.formulation : options.formulation;
  const Formulation* f = find_formulation(formulation);
  if (!f || !f->uses_penalty) return scene;
  try {  // the penalty's bias falls like 1 / penalty: a stiffer penalty shows it
    penalty = 10 * step.penalty;
    return with_parameters(scene, {{"analysis." + std::to_string(k) + ".penalty", format_number(penalty)}});
  } catch (const std::exception&) {
    penalty = 0;
    return scene;
  }
}

json ErrorEstimate::to_json() const {
  json j;
  j["method"] = method;
  j["description"] = method == "second_formulation"
                         ? "the run and a second formulation at its tolerances agree to the rounding floor of the "
                           "first comparison; error = max |x - x_other| over the samples (an upper bound)"
                         : "the run repeated at factor * rtol (and factor * atol where given; penalty: with 10 times "
                           "the penalty); error = max |x - x_k| / |1 - factor| over the samples, at least steps * eps * scale";
  j["rtol"] = rtol;
  j["atol"] = atol;
  j["factor"] = factor;
  j["comparison"] = {{"formulation", comparison_formulation}, {"rtol", comparison_rtol}, {"atol", comparison_atol},
                     {"status", comparison_status},          {"steps", comparison_steps},
                     {"cpu_seconds", comparison_cpu_seconds}};
  if (comparison_penalty > 0) j["comparison"]["penalty"] = comparison_penalty;
  j["cpu_seconds"] = {{"run", cpu_seconds},
                      {"estimate", comparison_cpu_seconds},
                      {"ratio", cpu_seconds > 0 ? comparison_cpu_seconds / cpu_seconds : 0.0}};
  json s = json::object();
  for (size_t k = 0; k < sensors.size(); ++k)
    s[sensors[k]] = {{"error", error[k]},
                     {"scale", scale[k]},
                     {"relative", relative(k)},
                     {"exceeded", std::find(exceeded.begin(), exceeded.end(), sensors[k]) != exceeded.end()},
                     {"difference", difference[k]},
                     {"rounding_floor", floor[k]}};
  j["sensors"] = s;
  const double vel_scale = time_scale > 0 ? length_scale / time_scale : 0.0;
  j["constraints"] = {
      {"position", {{"max", position_violation}, {"scale", length_scale},
                    {"relative", length_scale > 0 ? position_violation / length_scale : 0.0}}},
      {"velocity", {{"max", velocity_violation}, {"scale", vel_scale},
                    {"relative", vel_scale > 0 ? velocity_violation / vel_scale : 0.0}}}};
  j["promise"] = "error <= 10 rtol scale";
  j["exceeded"] = exceeded;
  return j;
}

bool error_estimate_requested(const Scene& scene) {
  for (const auto& s : scene.steps)
    if (s.error_estimate) return true;
  return false;
}

RunOptions comparison_options(const Scene& scene, const RunOptions& options, double factor,
                              const std::atomic<bool>* stop) {
  RunOptions c = options;
  c.verbose = c.progress = c.report_failures = false;
  c.sensitivities.clear();  // the estimate compares the outputs only
  // A run with sensitivities runs the scene's index3 steps as index2-ggl (cases/run/sensitivities.h):
  // the comparison run must use the same formulation.
  if (!options.sensitivities.empty() && options.formulation.empty())
    for (const AnalysisStep& s : scene.steps)
      if (integrates(s) && !sensitivity_formulation(s.formulation)) c.formulation = "index2-ggl";
  c.stop = stop;
  const double rtol = run_rtol(scene, options);
  // Tighter (rtol / factor) unless that leaves the tolerance's range: then looser by the same factor.
  const double k = rtol / factor >= kMinRtol || factor * rtol > kMaxRtol ? 1.0 / factor : factor;
  c.rtol = std::max(kMinRtol, k * rtol);
  c.atol = options.atol > 0 ? k * options.atol : 0.0;
  // The comparison integrates as the run does: an index3 (index1) run stays index3 (index1) where
  // the comparison's tighter rtol would hand over to index2-ggl (run_stages.h), which costs 2 to 3
  // times index3's run on the suspension (docs/formulation.md, "index3 hands over").
  const int last = last_integration(scene);
  const std::string ran = last >= 0 ? step_formulation(scene.steps[last], options) : "";
  const auto same = [&](const AnalysisStep& s) { return !integrates(s) || step_formulation(s, options) == ran; };
  if (c.formulation == options.formulation && handover_rtol(ran) > 0 &&
      std::all_of(scene.steps.begin(), scene.steps.end(), same) && step_formulation(scene.steps[last], c) != ran)
    c.formulation = ran + "-no-handover";
  return c;
}

ErrorEstimate compare_runs(const Scene& scene, const RunOptions& options, const Result& first,
                           const Result& second, double factor) {
  ErrorEstimate e;
  e.method = "tolerance_proportionality";
  describe_run(first, e);
  describe_comparison(second, e);
  if (!second.ok() || first.rows() == 0 || e.rtol <= 0) return e;
  // The factor used (labelled: a clamped comparison tolerance changes it).
  e.factor = e.comparison_rtol / e.rtol;
  // Tighter comparison (k < 1): d = (1 - k) e; looser: d = (k - 1) e.
  const double divisor = std::fabs(e.factor - 1.0);
  if (!(divisor > 1e-3)) {
    e.comparison_status = "same_tolerance";
    return e;
  }
  fill_sensors(e, first, second, divisor);
  if (!agrees_to_rounding(e)) return e;
  // Same steps, same answer: compare with a second formulation at the run's own tolerances.
  RunOptions other = options;
  other.verbose = other.progress = other.report_failures = false;
  other.sensitivities.clear();
  other.rtol = e.rtol;
  other.atol = e.atol;
  // Another formulation whose error keeps falling with rtol (index3 would hand over, or sit at
  // its floor: an upper bound 1e4 times the error); index1 as itself (it would hand over to
  // index2-ggl below rtol 1e-9).
  other.formulation = e.formulation == "index2-ggl" ? "index1-no-handover" : "index2-ggl";
  const Result third = run(scene, other);
  e.method = "second_formulation";
  describe_comparison(third, e);
  e.factor = 1.0;
  if (third.ok()) fill_sensors(e, first, third, 1.0);
  return e;
}

ErrorEstimate estimate_global_error(const Scene& scene, const RunOptions& options, const Result& first,
                                    double factor) {
  double penalty = 0;
  const Scene cscene = comparison_scene(scene, options, penalty);
  const Result second = run(cscene, comparison_options(scene, options, factor, options.stop));
  ErrorEstimate e = compare_runs(scene, options, first, second, factor);
  e.comparison_penalty = penalty;
  return e;
}

Result run_estimated(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks,
                     ErrorEstimate& estimate) {
  std::atomic<bool> stop_comparison{false};
  const RunOptions copt = comparison_options(scene, options, 3.0, &stop_comparison);
  double penalty = 0;
  const Scene cscene = comparison_scene(scene, options, penalty);
  auto comparison = std::async(std::launch::async, [&] { return run(cscene, copt); });
  Result r;
  try {
    r = run(scene, options, sinks);
  } catch (...) {
    stop_comparison = true;
    comparison.wait();
    throw;
  }
  // The comparison stops with the run, or on the user's stop request while it goes on.
  const auto user_stop = [&] { return options.stop && options.stop->load(); };
  if (!r.ok()) stop_comparison = true;
  while (comparison.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
    if (user_stop()) stop_comparison = true;
  const Result second = comparison.get();
  if (!r.ok()) return r;
  if (user_stop()) {  // the run is whole, its estimate is not: say so (exit 128 + signal)
    r.status = r.summary["status"] = "interrupted";
    r.message = r.summary["message"] = "interrupted during the error estimate: the run itself is complete";
    r.exit_code = 3;
    return r;
  }
  estimate = compare_runs(scene, options, r, second, 3.0);
  estimate.comparison_penalty = penalty;
  r.summary["error_estimate"] = estimate.to_json();
  return r;
}

void warn_about(const ErrorEstimate& e) {
  if (!e.ok()) {
    std::fprintf(stderr, "mbdae: warning: no error estimate, the comparison run at rtol %g failed (%s)\n",
                 e.comparison_rtol, e.comparison_status.c_str());
    return;
  }
  // The penalty formulation's error may be its constraint bias, which a tighter rtol does not remove.
  const char* advice = e.comparison_penalty > 0 ? "tighten rtol, or raise the penalty if it is the constraint bias "
                                                  "(docs/formulation.md, \"Singular configurations\")"
                                                : "tighten rtol";
  for (size_t k = 0; k < e.sensors.size(); ++k)
    if (std::find(e.exceeded.begin(), e.exceeded.end(), e.sensors[k]) != e.exceeded.end())
      std::fprintf(stderr,
                   "mbdae: warning: sensor %s: estimated global error %.3g is %.3g times rtol %g of its scale %.3g "
                   "(the tolerance promises at most 10): %s\n",
                   e.sensors[k].c_str(), e.error[k], e.error[k] / (e.rtol * e.scale[k]), e.rtol, e.scale[k], advice);
  const double vscale = e.time_scale > 0 ? e.length_scale / e.time_scale : 0.0;
  for (const auto& [name, value, scale] : {std::tuple<const char*, double, double>{"position", e.position_violation, e.length_scale},
                                           {"velocity", e.velocity_violation, vscale}})
    if (std::find(e.exceeded.begin(), e.exceeded.end(), std::string("constraints.") + name) != e.exceeded.end())
      std::fprintf(stderr,
                   "mbdae: warning: constraint violation at %s level %.3g is %.3g times rtol %g of its scale %.3g "
                   "(the tolerance promises at most 10)\n",
                   name, value, value / (e.rtol * scale), e.rtol, scale);
}

Result run_with_error_estimate(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks,
                               const std::string& summary_path, bool warn) {
  ErrorEstimate e;
  Result r = run_estimated(scene, options, sinks, e);
  if (!summary_path.empty() && (r.ok() || r.summary.contains("error_estimate") || r.status == "interrupted"))
    write_json_file(summary_path, r.summary);
  if (r.ok() && warn) warn_about(e);
  return r;
}

}  // namespace mbdae
