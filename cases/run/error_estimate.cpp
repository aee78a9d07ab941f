#include "cases/run/error_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/output.h"

namespace mbdae {
namespace {

// The last integration step of a run's summary (its rtol and atol are those used).
const nlohmann::ordered_json* integration_step(const nlohmann::ordered_json& summary) {
  const nlohmann::ordered_json* found = nullptr;
  if (summary.contains("steps"))
    for (const auto& s : summary["steps"])
      if (s.value("type", std::string()) == "dynamics" || s.value("type", std::string()) == "kinematics") found = &s;
  return found;
}

// Largest |a - b| of column c over the samples both results have (matched by time) and the
// largest |b|.
void compare_column(const Result& a, const Result& b, int ca, int cb, double& error, double& scale) {
  error = scale = 0;
  const std::vector<double>& ta = a.data[0];
  const std::vector<double>& tb = b.data[0];
  size_t i = 0, j = 0;
  while (i < ta.size() && j < tb.size()) {
    const double eps = 1e-9 * std::max(1.0, std::fabs(ta[i]));
    if (ta[i] < tb[j] - eps) { ++i; continue; }
    if (tb[j] < ta[i] - eps) { ++j; continue; }
    error = std::max(error, std::fabs(a.data[ca][i] - b.data[cb][j]));
    scale = std::max(scale, std::fabs(b.data[cb][j]));
    ++i;
    ++j;
  }
}

}  // namespace

nlohmann::ordered_json ErrorEstimate::to_json() const {
  nlohmann::ordered_json j;
  j["method"] = "the run repeated at rtol / 100, atol / 100; error = max |x - x_tight| over the samples";
  j["rtol"] = rtol;
  j["atol"] = atol;
  j["reference_rtol"] = reference_rtol;
  j["reference_atol"] = reference_atol;
  j["reference_status"] = reference_status;
  nlohmann::ordered_json s = nlohmann::ordered_json::object();
  for (size_t k = 0; k < sensors.size(); ++k)
    s[sensors[k]] = {{"error", error[k]}, {"scale", scale[k]},
                     {"relative", scale[k] > 0 ? error[k] / scale[k] : 0.0}};
  j["sensors"] = s;
  j["promise"] = "error <= 10 rtol scale";
  j["exceeded"] = exceeded;
  return j;
}

bool error_estimate_requested(const Scene& scene) {
  for (const auto& s : scene.steps)
    if (s.error_estimate) return true;
  return false;
}

ErrorEstimate estimate_global_error(const Scene& scene, const RunOptions& options, const Result& first,
                                    double factor) {
  ErrorEstimate e;
  const auto* step = integration_step(first.summary);
  if (!step) return e;
  e.rtol = step->value("rtol", 0.0);
  e.atol = step->value("atol", 0.0);
  RunOptions tight = options;
  tight.verbose = tight.progress = false;
  tight.rtol = e.reference_rtol = std::max(1e-14, e.rtol / factor);
  tight.atol = e.reference_atol = e.atol / factor;
  const Result ref = run(scene, tight);
  e.reference_status = ref.status;
  if (!ref.ok() || first.rows() == 0) return e;
  for (size_t c = 1; c < first.columns.size(); ++c) {
    const int cb = ref.column_index(first.columns[c]);
    if (cb < 0) continue;
    double error, scale;
    compare_column(first, ref, static_cast<int>(c), cb, error, scale);
    e.sensors.push_back(first.columns[c]);
    e.error.push_back(error);
    e.scale.push_back(scale);
    if (scale > 0 && error > 10 * e.rtol * scale) e.exceeded.push_back(first.columns[c]);
  }
  return e;
}

Result run_with_error_estimate(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks,
                               const std::string& summary_path) {
  Result r = run(scene, options, sinks);
  if (!r.ok()) return r;
  const ErrorEstimate e = estimate_global_error(scene, options, r);
  r.summary["error_estimate"] = e.to_json();
  if (!summary_path.empty()) write_json_file(summary_path, r.summary);
  if (e.reference_status != "ok")
    std::fprintf(stderr, "mbdae: warning: no error estimate, the run at rtol %g failed (%s)\n", e.reference_rtol,
                 e.reference_status.c_str());
  for (size_t k = 0; k < e.sensors.size(); ++k)
    if (std::find(e.exceeded.begin(), e.exceeded.end(), e.sensors[k]) != e.exceeded.end())
      std::fprintf(stderr,
                   "mbdae: warning: sensor %s: estimated global error %.3g is %.3g times rtol %g of its scale %.3g "
                   "(the tolerance promises at most 10): tighten rtol\n",
                   e.sensors[k].c_str(), e.error[k], e.error[k] / (e.rtol * e.scale[k]), e.rtol, e.scale[k]);
  return r;
}

}  // namespace mbdae
