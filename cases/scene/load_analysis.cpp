// Reading analysis steps (span, tolerances, formulation, checks) and the animation section.
#include "cases/scene/loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <sstream>
#include "cases/scene/field_ranges.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/scene.h"
#include "cases/scene/scene_overrides.h"
#include "cases/scene/scene_validation.h"
#include "core/errors.h"
#include "core/expression.h"
#include "formulation/formulation_registry.h"

namespace mbdae::scene_load {


// `initial_velocities` of a dynamics step: coordinate names to rates.
void Loader::initial_velocities(const YAML::Node& n, const std::string& type, AnalysisStep& s) {
  if (!has(n, "initial_velocities")) return;
  const YAML::Node iv = n["initial_velocities"];
  if (type == "kinematics")
    error(iv, "initial_velocities", "does not apply to a kinematics step (its velocities follow from the drives)");
  record(n, "initial_velocities", iv);
  if (!iv.IsMap()) {
    error(iv, "initial_velocities", "expected a mapping of coordinate names to rates, got " + describe(iv));
    return;
  }
  for (const auto& kv : iv) {
    const auto cname = key_of(kv.first, "initial_velocities");
    if (!cname) continue;
    if (const auto x = to_number(kv.second, "initial_velocities." + *cname)) s.initial_velocities.emplace_back(*cname, *x);
  }
}


// A true/false field (absent: `out` unchanged).
void Loader::flag(const YAML::Node& n, const char* key, bool& out) {
  if (!has(n, key)) return;
  const std::string v = text(n, key, "false");
  if (v == "true" || v == "false") out = v == "true";
  else if (n[key].IsScalar()) error(n[key], key, "expected true or false, got " + quote(v));
}


// The time span, tolerances and model scales of a step, each checked against its range.
void Loader::step_span_and_tolerances(const YAML::Node& n, bool integrates, AnalysisStep& s) {
  const auto t0 = opt_number(n, "t0"), t_end = opt_number(n, "t_end"), output_step = opt_number(n, "output_step");
  const auto rtol = opt_number(n, "rtol"), atol = opt_number(n, "atol"), max_step = opt_number(n, "max_step");
  s.t0 = t0.value_or(s.t0);
  s.t_end = t_end.value_or(s.t_end);
  s.output_step = output_step.value_or(s.output_step);
  s.rtol = rtol.value_or(s.rtol);
  s.atol = atol.value_or(s.atol);
  s.max_step = max_step.value_or(s.max_step);
  // Tolerances in model units (formulation/tolerance_scales.h): absent means derived.
  for (auto [key, field] : {std::pair<const char*, double*>{"length_scale", &s.length_scale}, {"time_scale", &s.time_scale},
                            {"atol_rotation", &s.atol_rotation}, {"atol_velocity", &s.atol_velocity}}) {
    const auto x = opt_number(n, key);
    if (x && !(*x > 0)) error(n[key], key, "must be positive, got " + format_number(*x));
    else if (x) *field = *x;
  }
  const bool times_ok = (t0 || !has(n, "t0")) && (t_end || !has(n, "t_end"));
  if (integrates && times_ok && !(s.t_end > s.t0))
    error(at(n, "t_end"), "t_end", "the time span is empty (t_end " + format_number(s.t_end) +
                                       " must exceed t0 " + format_number(s.t0) + ")");
  if (integrates && (output_step || !has(n, "output_step"))) {
    const std::string why = output_step_range_error(s.output_step, times_ok ? s.t0 : 0, times_ok ? s.t_end : 0);
    if (!why.empty()) error(at(n, "output_step"), "output_step", why);
  }
  if (rtol && !rtol_range_error(s.rtol).empty()) error(n["rtol"], "rtol", rtol_range_error(s.rtol));
  if (atol && !atol_range_error(s.atol).empty()) error(n["atol"], "atol", atol_range_error(s.atol));
  if (max_step && s.max_step < 0) error(n["max_step"], "max_step", "must not be negative (0: no limit), got " + format_number(s.max_step));
  if (const auto x = opt_number(n, "max_steps")) {
    if (!(*x >= 1 && *x <= 1e15 && *x == std::floor(*x)))
      error(n["max_steps"], "max_steps", "expected a whole number of steps in [1, 1e15], got " + format_number(*x));
    else s.max_steps = *x;
  }
}


// The formulation and its parameters (constraint scale, Baumgarte rates, penalty, Newton).
void Loader::step_formulation(const YAML::Node& n, AnalysisStep& s) {
  s.formulation = text(n, "formulation", "index3");
  if (has(n, "formulation") && n["formulation"].IsScalar() && !find_formulation(s.formulation))
    error(n["formulation"], "formulation", "unknown formulation " + quote(s.formulation) + " (" + formulation_names() + ")");
  const auto scale = opt_number(n, "constraint_scale");
  s.constraint_scale = scale.value_or(s.constraint_scale);
  if (scale && s.constraint_scale < 0)
    error(n["constraint_scale"], "constraint_scale", "must not be negative (0: automatic), got " + format_number(s.constraint_scale));
  s.newton_convergence = opt_number(n, "newton_convergence").value_or(s.newton_convergence);
  if (!(s.newton_convergence > 0 && s.newton_convergence <= 1))
    error(at(n, "newton_convergence"), "newton_convergence", "out of range (0, 1], got " + format_number(s.newton_convergence));
  s.newton_solve = text(n, "newton_solve", s.newton_solve);
  if (has(n, "newton_solve") && n["newton_solve"].IsScalar() && s.newton_solve != "full" && s.newton_solve != "reduced")
    error(n["newton_solve"], "newton_solve", "expected full or reduced, got " + quote(s.newton_solve));
  s.baumgarte_alpha = opt_number(n, "baumgarte_alpha").value_or(s.baumgarte_alpha);
  s.baumgarte_beta = opt_number(n, "baumgarte_beta").value_or(s.baumgarte_beta);
  if (has(n, "baumgarte_alpha") && !(s.baumgarte_alpha >= 0)) error(at(n, "baumgarte_alpha"), "baumgarte_alpha", "must not be negative, got " + format_number(s.baumgarte_alpha));
  if (has(n, "baumgarte_beta") && !(s.baumgarte_beta >= 0)) error(at(n, "baumgarte_beta"), "baumgarte_beta", "must not be negative, got " + format_number(s.baumgarte_beta));
  s.penalty = opt_number(n, "penalty").value_or(s.penalty);
  if (!(s.penalty > 0)) error(at(n, "penalty"), "penalty", "must be positive, got " + format_number(s.penalty));
}


// The checks a step reports on: the assembly mode check and the quiet sensors.
void Loader::step_checks(const YAML::Node& n, bool integrates, AnalysisStep& s) {
  s.mode_check = text(n, "mode_check", s.mode_check);
  if (has(n, "mode_check") && n["mode_check"].IsScalar() && s.mode_check != "warn" && s.mode_check != "fail" &&
      s.mode_check != "off")
    error(n["mode_check"], "mode_check", "expected warn, fail or off, got " + quote(s.mode_check));
  const auto mode_deg = opt_number(n, "mode_check_deg");
  s.mode_check_deg = mode_deg.value_or(s.mode_check_deg);
  if (mode_deg && !(s.mode_check_deg > 0 && s.mode_check_deg <= 180))
    error(n["mode_check_deg"], "mode_check_deg", "out of range (0, 180], got " + format_number(s.mode_check_deg));
  s.quiet_until = opt_number(n, "quiet_until").value_or(s.quiet_until);
  s.quiet_sensors = names(n, "quiet_sensors");
  if (integrates && !s.quiet_sensors.empty() && !has(n, "quiet_until"))
    error(n["quiet_sensors"], "quiet_until", "missing (quiet_sensors are watched until quiet_until)");
}


AnalysisStep Loader::step(const YAML::Node& n) {
  AnalysisStep s;
  s.where = where(n);
  const Fields& general = analysis_fields();
  if (!check_keys(n, "analysis step", general)) return s;
  const std::string type = text(n, "type", "", true);
  const AnalysisType* kind = find_analysis_type(type);
  if (kind) s.type = kind->type;
  else if (!type.empty()) error(n["type"], "type", "unknown analysis " + quote(type) + " (" + analysis_type_names() + ")");
  const bool integrates = kind && kind->integrates;
  if (kind) applies(n, (std::string("aeiou").find(type[0]) == std::string::npos ? "a " : "an ") + type + " step", general,
                    kind->fields);
  initial_velocities(n, type, s);
  s.hold = names(n, "hold");
  s.release = names(n, "release");
  s.unknowns = names(n, "unknowns");
  step_span_and_tolerances(n, integrates, s);
  flag(n, "output_projection", s.output_projection);
  flag(n, "error_estimate", s.error_estimate);
  // The error target (cases/run/error_target.h): a positive error, and the sensors it is for.
  const auto target = opt_number(n, "error_target");
  if (target && !(*target > 0 && std::isfinite(*target)))
    error(n["error_target"], "error_target", "must be a positive error in the sensors' units, got " + format_number(*target));
  else if (target) s.error_target = *target;
  s.error_sensors = names(n, "error_sensors");
  if (!s.error_sensors.empty() && !target)
    error(n["error_sensors"], "error_target", "missing (error_sensors name the sensors of error_target)");
  step_formulation(n, s);
  step_checks(n, integrates, s);
  return s;
}


// The `animation` section (cases/output/animation_spec.h), from the model file or the scene.
void Loader::animation(const YAML::Node& n, AnimationSpec& a) {
  if (!check_keys(n, "animation", {"write", "frame_rate", "max_frames", "disk_budget_mb", "format", "start", "end",
                                   "axis_length", "shapes"}))
    return;
  a.section = where(n);
  const std::pair<const char*, SourceLocation*> located[] = {
      {"frame_rate", &a.frame_rate_at}, {"max_frames", &a.max_frames_at}, {"disk_budget_mb", &a.disk_budget_at}};
  for (const auto& [key, loc] : located)
    if (has(n, key)) *loc = where(n[key]);
  flag(n, "write", a.write);
  auto positive = [&](const char* key, double& x, bool zero_ok) {
    const auto v = opt_number(n, key);
    if (v && (zero_ok ? *v >= 0 : *v > 0)) x = *v;
    else if (v) error(n[key], key, std::string("must be ") + (zero_ok ? "zero or positive" : "positive") + ", got " + format_number(*v));
  };
  positive("frame_rate", a.frame_rate, false);
  positive("axis_length", a.axis_length, true);
  if (const auto m = opt_number(n, "max_frames")) {
    if (*m >= 2 && *m <= kMaxAnimationFrames && std::floor(*m) == *m) a.max_frames = static_cast<int>(*m);
    else error(n["max_frames"], "max_frames", "expected a whole number from 2 to 1e5, got " + format_number(*m));
  }
  if (const auto b = opt_number(n, "disk_budget_mb")) {
    if (*b >= 1 && *b <= 1e6) a.disk_budget_mb = *b;
    else error(n["disk_budget_mb"], "disk_budget_mb", "expected megabytes from 1 to 1e6, got " + format_number(*b));
  }
  if (has(n, "format")) {
    const std::string f = text(n, "format", "", true);
    if (f == "binary") a.format = VtkFormat::kBinary;
    else if (f == "ascii") a.format = VtkFormat::kAscii;
    else error(n["format"], "format", "expected binary or ascii, got " + quote(f));
  }
  a.start = opt_number(n, "start").value_or(a.start);
  a.end = opt_number(n, "end").value_or(a.end);
  if (!(a.end > a.start)) error(at(n, "end"), "end", "must exceed start");
  if (!has(n, "shapes")) return;
  if (!n["shapes"].IsSequence()) return error(n["shapes"], "shapes", "expected a list, got " + describe(n["shapes"]));
  a.shapes.clear();
  for (const auto& sn : n["shapes"]) {
    if (!check_keys(sn, "shape", {"body", "type", "center", "axis", "size", "radius", "length"})) continue;
    AnimationShape s;
    s.where = where(sn);
    s.body = name(sn, "body");
    const std::string type = text(sn, "type", "", true);
    s.center = vec3(sn, "center", s.center);
    s.axis = vec3(sn, "axis", s.axis);
    s.size = vec3(sn, "size", s.size, type == "box");
    s.radius = number(sn, "radius", 0, type == "cylinder" || type == "sphere");
    s.length = number(sn, "length", 0, type == "cylinder");
    if (type == "box") s.type = AnimationShape::Type::kBox;
    else if (type == "cylinder") s.type = AnimationShape::Type::kCylinder;
    else if (type == "sphere") s.type = AnimationShape::Type::kSphere;
    else if (has(sn, "type")) error(sn["type"], "type", "unknown shape " + quote(type) + " (box, cylinder, sphere)");
    if (type == "box" && !(s.size.minCoeff() > 0)) error(at(sn, "size"), "size", "edge lengths must be positive");
    if ((type == "cylinder" || type == "sphere") && !(s.radius > 0)) error(at(sn, "radius"), "radius", "must be positive");
    if (type == "cylinder" && !(s.length > 0)) error(at(sn, "length"), "length", "must be positive");
    if (!(s.axis.norm() > 0)) error(at(sn, "axis"), "axis", "must not be zero");
    a.shapes.push_back(s);
  }
}

}  // namespace mbdae::scene_load
