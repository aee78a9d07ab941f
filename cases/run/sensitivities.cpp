// Sensitivities of a run's outputs to scene parameters: the twins and what they follow
// (cases/run/sensitivities.h).
#include "cases/run/sensitivities.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cases/run/run_stages.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/field_ranges.h"  // parse_number
#include "core/errors.h"
#include "core/finite_check.h"
#include "formulation/constraints.h"  // constraint_group
#include "formulation/mechanics.h"  // initial_modes
#include "formulation/model_rules.h"  // did_you_mean
#include "formulation/parameter_reach.h"
#include "formulation/kinematic_sensitivities.h"
#include "formulation/tolerance_scales.h"
#include "formulation/twin_sensitivities.h"

namespace mbdae {
namespace {

using json = nlohmann::ordered_json;

// Analysis settings are not parameters of the model, except the initial rates of joints.
bool analysis_setting(const std::string& path) {
  return path.rfind("analysis.", 0) == 0 && path.find(".initial_velocities.") == std::string::npos;
}

std::string number_text(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string short_text(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// "m/(N/m)": a sensitivity's unit from the sensor's and the parameter's.
std::string ratio_unit(const std::string& y, const std::string& p) {
  if (p.empty() || p == "1") return y;
  auto group = [](const std::string& u) { return u.find_first_of("/ *") != std::string::npos ? "(" + u + ")" : u; };
  return (y.empty() ? "1" : group(y)) + "/" + group(p);
}

std::unique_ptr<TwinRun> make_twin(const RunContext& c, const SensitivityParameter& p, double value) {
  auto tw = std::make_unique<TwinRun>();
  try {
    tw->scene = with_parameters(c.scene, {{p.path, number_text(value)}});
  } catch (const SceneError& e) {  // a value at the edge of its range (a mass of 1e-300, ...)
    throw ModelError(c.scene.file, 0, "sensitivities",
                     "'" + p.path + "' cannot be differentiated here: its twin at " + number_text(value) +
                         " is not a valid scene (" + (e.messages.empty() ? std::string(e.what()) : e.messages.front()) + ")");
  }
  tw->options = c.options;
  tw->options.verbose = tw->options.progress = tw->options.report_failures = false;
  tw->options.sensitivities.clear();
  json summary;
  std::shared_ptr<const System> all;
  std::shared_ptr<const System> sys = build_checked_system(tw->scene, tw->options, summary, &all);
  if (sys->nq() != c.system->nq() || sys->num_constraint_rows() != c.system->num_constraint_rows())
    throw ModelError(c.scene.file, 0, "sensitivities",
                     "'" + p.path + "' changes the model's coordinates or equations (" +
                         std::to_string(sys->num_constraint_rows()) + " constraint equations at " + number_text(value) +
                         " against " + std::to_string(c.system->num_constraint_rows()) + "): it cannot be differentiated");
  tw->context = std::make_unique<RunContext>(RunContext{tw->scene, tw->options, tw->sinks, tw->result, sys, all, {}, {}});
  tw->context->q = sys->q0;
  output_columns(*tw->context);
  return tw;
}

// A parameter that moves the time of a breakpoint inside an integrated step: the twins keep
// their own breakpoints and the sensitivities jump at the run's (formulation/twin_sensitivities.h).
// That holds for a force's step (a ground profile's, a point force's): q and v continuous, v'
// jumping. Refused, naming the breakpoint (check_breakpoints): a drive's breakpoint (a kink or
// jump of a constraint's target moves q or v themselves), breakpoints that appear, vanish, merge
// or come within twice the twins' step of each other, one moved onto an analysis step's start or
// end, and any other input that varies with time (each twin holds its inputs over the d between
// its breakpoint and the run's, which is exact for steps only).
bool moves_inside_integrated_step(const RunContext& c, double b) {
  for (const AnalysisStep& step : c.scene.steps)
    if (integrates(step) && b > step.t0 && b < step.t_end) return true;
  return false;
}

std::string step_span(const AnalysisStep& step) {
  return integrates(step) ? "t = " + short_text(step.t0) + " to " + short_text(step.t_end) : "at t = " + short_text(step.t0);
}

// The analysis step whose start or end (a static step's time: its t0) lies between the run's
// breakpoint b and a twin's bt, or at either: there the run's start or end sees one side of the
// input's jump and the twin the other, which has no derivative. Null if none.
const AnalysisStep* crossed_step(const RunContext& c, double b, double bt) {
  for (const AnalysisStep& step : c.scene.steps)
    for (const double x : {step.t0, step.t_end})
      if ((integrates(step) || x == step.t0) && (b - x) * (bt - x) <= 0) return &step;
  return nullptr;
}

std::vector<double> drive_breakpoints(const System& sys) {
  std::vector<double> t;
  for (const Constraint& k : sys.constraints)
    if (k.type == Constraint::Type::kCoordinate)
      for (double b : k.target.breakpoints()) t.push_back(b);
  return t;
}

// Why a moved breakpoint's jump is not covered ("" where it is). check_breakpoints has refused
// breakpoints that appear, vanish or merge before.
std::string breakpoint_refusal(const System& sys, const System& twin) {
  if (drive_breakpoints(sys) != drive_breakpoints(twin)) return "a driven coordinate's breakpoint";
  for (const Force& f : sys.forces) {
    for (const TimeFunction* g : {&f.fx, &f.fy, &f.fz, &f.ground})
      if (g->kind != TimeFunction::Kind::kConstant && g->kind != TimeFunction::Kind::kStep)
        return "a model whose force '" + f.name + "' has an input that varies with time (" + g->describe() +
               "), which the twins cannot hold over their step (only a step can be)";
    for (const Expression& e : f.expression)
      if (!e.variables.empty() && e.variables.front() == 0)  // t is variable 0
        return "a model whose force '" + f.name + "' has an expression of t, which the twins cannot hold over "
               "their step (only a step can be)";
    if (f.law)
      return "a model with the user law '" + f.name + "' (" + f.law->name + "), which may read t, and the twins "
             "cannot hold it over their step";
  }
  return "";
}

double nearest(const std::vector<double>& ts, double t) {
  double best = NAN;
  for (const double x : ts)
    if (!(std::fabs(x - t) >= std::fabs(best - t))) best = x;
  return best;
}

void check_breakpoints(const RunContext& c, SensitivityParameter& p) {
  const std::vector<double> own = c.system->breakpoints();
  auto same_time = [](double a, double b) { return std::fabs(a - b) <= 4 * 2.220446049250313e-16 * std::max(std::fabs(a), std::fabs(b)); };
  const std::vector<double> minus = p.twin[1]->context->system->breakpoints();  // for dt/dp
  for (int side = 0; side < 2; ++side) {
    const System& twin_sys = *p.twin[side]->context->system;
    const std::vector<double> twin = side == 0 ? twin_sys.breakpoints() : minus;
    auto refuse = [&](double b, double bt, const std::string& what) {
      throw ModelError(c.scene.file, 0, "sensitivities",
                       "'" + p.path + "' moves the breakpoint at t = " + short_text(b) + " (" +
                           (std::isfinite(bt) ? "to " + short_text(bt) + " " : "") + "with " + p.path + " = " +
                           short_text(side == 0 ? p.value + p.delta : p.value - p.delta) + ") " + what +
                           ": it cannot be differentiated");
    };
    if (twin.size() != own.size()) {  // two breakpoints merge or split: name the first unmatched
      for (const double b : own)
        if (std::none_of(twin.begin(), twin.end(), [&](double x) { return same_time(x, b); }))
          refuse(b, NAN, "onto another breakpoint (its twin has " + std::to_string(twin.size()) + " breakpoints, the run " +
                             std::to_string(own.size()) + ")");
      for (const double bt : twin)
        if (std::none_of(own.begin(), own.end(), [&](double x) { return same_time(x, bt); }))
          refuse(nearest(own, bt), NAN, "so that it splits off another breakpoint (its twin has " + std::to_string(twin.size()) +
                                            " breakpoints, the run " + std::to_string(own.size()) + ")");
    }
    for (size_t k = 0; k < own.size(); ++k) {
      const double b = own[k], bt = twin[k];
      if (same_time(b, bt)) continue;
      if (const AnalysisStep* step = crossed_step(c, b, bt))
        refuse(b, bt, "onto or across the start or end of analysis step " + std::to_string(step - c.scene.steps.data()) +
                          " (" + step_span(*step) + "), where the input's two sides differ");
      // The twins' breakpoints matched to the run's by their order: a twin's must stay well
      // inside its gaps (two steps 1e-5 s apart against a twins' step of 2e-5 s swapped them).
      for (const size_t n : {k - 1, k + 1})
        if (n < own.size() && std::fabs(bt - b) >= 0.5 * std::fabs(own[n] - b))
          refuse(b, NAN, "to within half its distance of the breakpoint at t = " + short_text(own[n]) +
                            " (closer than twice the twins' step)");
      if (!moves_inside_integrated_step(c, b)) continue;
      const std::string why = breakpoint_refusal(*c.system, twin_sys);
      if (!why.empty())
        refuse(b, bt, "inside an integrated step, and the sensitivities' jump there is computed only for a force's "
                      "step: this is " + why);
      if (side == 0)
        p.moved_breakpoints.push_back(
            {{"t", b},
             {"dt_dp", (bt - minus[k]) / (2 * p.delta)},
             {"note", "the sensitivities jump there by (y'- - y'+) dt/dp on q and v (docs/sensitivities.md)"}});
    }
  }
}

// The scale of the twins' step d = kRelativeStep scale. A length's is the model's length scale
// (formulation/tolerance_scales.h) where |p| is smaller: a point's coordinate depends on where
// the origin is, and one at 0 or 1e-12 m on a 1 m suspension is moved as any other point of it.
// A mass's or an inertia's is |p|, but not below 1e-3 of the model's largest (a wheel of 1e-15
// kg beside a 400 kg chassis, moved by 3e-5 |p|, made twins that differed by rounding only:
// sensitivities of exactly 0). An angle's at least 1 rad (57.3 deg). A time's (a step's time, a
// knot's) is the model's fast time scale, whatever |p|: an instant's step must not grow with the
// clock (a ground step at 50 s stepped by 1.5e-3 s, and its twins' restarts at the landings after
// it, nonlinear in d s, put the sensitivities 4.6e-4 off), nor shrink to rounding near t = 0.
// Otherwise |p|, or 1 in p's unit at 0.
double parameter_scale(const RunContext& c, double value, const std::string& unit) {
  const System& sys = *c.system;
  if (unit == "s") return model_scales(sys, sys.q0.data(), 0, 1).fast_time;
  double floor = 0;
  if (unit == "m") floor = model_scales(sys, sys.q0.data(), 0, 1).length;
  if (unit == "rad") floor = 1;
  if (unit == "deg") floor = 180 / M_PI;
  for (const SystemBody& b : sys.bodies) {
    if (unit == "kg") floor = std::max(floor, 1e-3 * b.mass);
    if (unit == "kg m^2") floor = std::max(floor, 1e-3 * b.inertia.cwiseAbs().maxCoeff());
  }
  const double scale = std::max(std::fabs(value), floor);
  return scale > 0 ? scale : 1.0;
}

}  // namespace

bool sensitivity_formulation(const std::string& formulation) { return formulation.rfind("index3", 0) != 0; }

const char* const kIndex3SensitivityNote =
    "at index 3 the sensitivities' velocities and multipliers are not in the local error test and their errors "
    "grow with the steps (the A01 pendulum's bob against its length: 1e-3 of the largest sensitivity after 10 s, "
    "index3-positions diverges; index2-ggl 6e-7 at the same rtol 1e-8), and in the test the difference noise of "
    "F_p stops the steps at index3's rounding-level tolerances (docs/sensitivities.md)";

namespace {

// The scene's parameter list, or the message why it has none (a scene built in code).
std::vector<ParameterEntry> entries_or_problem(const Scene& scene, const std::string& option, std::string& problem) {
  try {
    return scene_parameters(scene);
  } catch (const SceneError& e) {
    problem = option + ": " + (e.messages.empty() ? std::string(e.what()) : e.messages.front());
    return {};
  }
}

std::vector<std::string> path_problems(const std::vector<ParameterEntry>& entries, const std::vector<std::string>& paths,
                                       const std::string& formulation, const std::string& option) {
  std::vector<std::string> out;
  std::vector<std::string> names;
  for (const ParameterEntry& e : entries) names.push_back(e.path);
  for (size_t i = 0; i < paths.size(); ++i) {
    const std::string& path = paths[i];
    const std::string head = option + " '" + path + "': ";
    auto it = std::find_if(entries.begin(), entries.end(), [&](const ParameterEntry& e) { return e.path == path; });
    double v = 0;
    if (std::find(paths.begin(), paths.begin() + i, path) != paths.begin() + i)
      out.push_back(head + "asked twice");
    else if (it == entries.end())
      out.push_back(head + "no such parameter (`mbdae params SCENE` lists them)" + did_you_mean(path, names));
    else if (analysis_setting(path))
      out.push_back(head + "a setting of the analysis, not a parameter of the model: it cannot be differentiated");
    else if (!parse_number(it->value, v))
      out.push_back(head + "names '" + it->value + "' (" + it->file + ":" + std::to_string(it->line) +
                    "), not a single number" + (it->value.rfind('[', 0) == 0 ? "; name one element: " + path + ".0" : ""));
  }
  if (!formulation.empty() && !sensitivity_formulation(formulation))
    out.push_back(option + ": not with formulation " + formulation + " (" + kIndex3SensitivityNote +
                  "); use index2-ggl, index1 or penalty, or leave the scene's formulation (its index3 steps then run "
                  "as index2-ggl)");
  return out;
}

}  // namespace

std::vector<std::string> check_sensitivity_paths(const Scene& scene, const std::vector<std::string>& paths,
                                                 const std::string& formulation, const std::string& option) {
  if (paths.empty()) return {};
  std::string problem;
  const std::vector<ParameterEntry> entries = entries_or_problem(scene, option, problem);
  if (!problem.empty()) return {problem};
  return path_problems(entries, paths, formulation, option);
}

std::shared_ptr<RunSensitivities> open_sensitivities(RunContext& c) {
  const std::vector<std::string>& paths = c.options.sensitivities;
  if (paths.empty()) return nullptr;
  std::string problem;
  const std::vector<ParameterEntry> entries = entries_or_problem(c.scene, "sensitivities", problem);
  const std::vector<std::string> problems =
      problem.empty() ? path_problems(entries, paths, c.options.formulation, "sensitivities") : std::vector{problem};
  if (!problems.empty()) throw ModelError(c.scene.file, 0, "sensitivities", problems.front());
  auto rs = std::make_shared<RunSensitivities>();
  for (const std::string& path : paths) {
    const ParameterEntry& e = *std::find_if(entries.begin(), entries.end(), [&](const ParameterEntry& x) { return x.path == path; });
    SensitivityParameter p;
    p.path = path;
    p.unit = e.unit;
    parse_number(e.value, p.value);
    p.scale = parameter_scale(c, p.value, p.unit);
    p.delta = kRelativeStep * p.scale;
    p.twin[0] = make_twin(c, p, p.value + p.delta);
    p.twin[1] = make_twin(c, p, p.value - p.delta);
    check_breakpoints(c, p);
    rs->parameters.push_back(std::move(p));
  }
  // Columns: each output sensor by each parameter.
  Result& r = c.result;
  r.sensitivity_columns = {"t"};
  r.sensitivity_units = {"s"};
  for (size_t k = 1; k < r.columns.size(); ++k)
    for (const SensitivityParameter& p : rs->parameters) {
      r.sensitivity_columns.push_back("d(" + r.columns[k] + ")/d(" + p.path + ")");
      r.sensitivity_units.push_back(ratio_unit(r.units[k], p.unit));
    }
  r.sensitivities.assign(r.sensitivity_columns.size(), {});
  rs->last_positions.assign(rs->parameters.size(), std::vector<double>(c.system->nq(), 0.0));
  return rs;
}

bool wrote_row(const RunContext& c, double t) {
  const Result& r = c.result;
  return r.rows() == r.sensitivities[0].size() + 1 && r.data[0].back() == t;
}

RunContext* twin_context(RunContext& c, size_t parameter, int side) {
  if (!c.sensitivities || !c.sensitivities->active) return nullptr;
  return c.sensitivities->parameters[parameter].twin[side]->context.get();
}

void sensitivities_failed(RunContext& c, const std::string& status, const std::string& message) {
  RunSensitivities& rs = *c.sensitivities;
  if (!rs.active) return;
  rs.active = false;
  rs.status = status;
  rs.message = message;
  if (c.options.report_failures) std::fprintf(stderr, "mbdae: sensitivities: %s\n", message.c_str());
}

void follow_static_stage(RunContext& c, int step, json& js) {
  if (!c.sensitivities || !c.sensitivities->active) return;
  json out, solved;
  for (SensitivityParameter& p : c.sensitivities->parameters) {
    json sides[2], tj[2];
    for (int side = 0; side < 2; ++side) {
      RunContext& t = *p.twin[side]->context;
      if (!analysis_type(t.scene.steps[step].type).stage(t, t.scene.steps[step], tj[side])) {
        sensitivities_failed(c, "twin_failed",
                             "the twin at " + p.path + " = " + number_text(side == 0 ? p.value + p.delta : p.value - p.delta) +
                                 " failed in analysis step " + std::to_string(step) + ": " + t.result.message);
        return;
      }
      sides[side] = sensors_json(*t.system, initial_modes(*t.system, t.q.data(), t.scene.steps[step].t0), t.q.data(),
                                 t.scene.steps[step].t0);
    }
    for (const auto& [name, plus] : sides[0].items())
      if (plus.is_number() && sides[1].contains(name) && sides[1][name].is_number())
        out[name][p.path] = (plus.get<double>() - sides[1][name].get<double>()) / (2 * p.delta);
    // Force parameters the step solved for (an equilibrium's free length).
    if (tj[0].contains("parameters"))
      for (const auto& [name, plus] : tj[0]["parameters"].items())
        if (plus.is_number() && tj[1]["parameters"].contains(name))
          solved[name][p.path] = (plus.get<double>() - tj[1]["parameters"][name].get<double>()) / (2 * p.delta);
  }
  js["sensitivities"] = out;
  if (!solved.empty()) js["parameter_sensitivities"] = solved;
}

void record_sensitivity_sample(RunContext& c, TwinSensitivities& ts, double t, const double* y, const double* yp,
                               const double* const* s, const double* const* sp, bool project) {
  RunSensitivities& rs = *c.sensitivities;
  if (!rs.active || !wrote_row(c, t)) return;
  try {
    if (!ts.sensors(t, y, yp, s, sp, project, rs.sensor_work)) return sensitivities_failed(c, "output_failed", ts.failure());
  } catch (const SolveError& e) {  // a twin's loads not finite at y +- d s: the sensitivities stop, the run goes on
    return sensitivities_failed(c, "output_failed", "at t = " + number_text(t) + ": " + e.what());
  }
  record_sensitivity_row(c, t, s);
}

void record_kinematic_sample(RunContext& c, KinematicSensitivities& ks, const std::vector<char>& modes,
                             const CoordinateTurns* turns, double t, const double* q, const double* v) {
  RunSensitivities& rs = *c.sensitivities;
  if (!rs.active || !wrote_row(c, t)) return;
  if (!ks.sensors(modes, turns, q, v, t, rs.sensor_work, rs.position_work))
    return sensitivities_failed(c, "singular", ks.failure() + " (t = " + number_text(t) + ")");
  rs.position_pointers.resize(rs.position_work.size());
  for (size_t i = 0; i < rs.position_work.size(); ++i) rs.position_pointers[i] = rs.position_work[i].data();
  record_sensitivity_row(c, t, rs.position_pointers.data());
}

void record_sensitivity_row(RunContext& c, double t, const double* const* s) {
  RunSensitivities& rs = *c.sensitivities;
  Result& r = c.result;
  const std::vector<std::vector<double>>& ds = rs.sensor_work;
  const size_t np = rs.parameters.size();
  std::vector<double>& row = rs.row_work;
  row.resize(r.sensitivity_columns.size());
  row[0] = t;
  for (size_t k = 0; k < c.column_sensors.size(); ++k)
    for (size_t i = 0; i < np; ++i) row[1 + k * np + i] = ds[i][c.column_sensors[k]];
  if (const int k = first_non_finite(row.data(), static_cast<int>(row.size())); k >= 0)
    return sensitivities_failed(c, "not_finite",
                                r.sensitivity_columns[k] + " is not finite at t = " + number_text(t));
  for (size_t k = 0; k < row.size(); ++k) r.sensitivities[k].push_back(row[k]);
  const int nq = c.system->nq();
  for (size_t i = 0; i < np; ++i) std::copy(s[i], s[i] + nq, rs.last_positions[i].begin());
}

void sensitivity_statistics(RunContext& c, const IdaStats& st, json& stats) {
  stats["sensitivity_residual_evaluations"] = st.sensitivity_residual_evals;
  stats["sensitivity_nonlinear_iterations"] = st.sensitivity_nonlinear_iterations;
  stats["sensitivity_nonlinear_failures"] = st.sensitivity_nonlinear_failures;
  // Where a failure first took them out of the local error test for a window after each start,
  // and the retries from the last accepted step that took.
  if (st.sensitivity_test_off_time >= 0) {
    stats["sensitivity_error_test_windows_from"] = st.sensitivity_test_off_time;
    stats["sensitivity_fallbacks"] = st.sensitivity_fallbacks;
  }
  RunSensitivities& rs = *c.sensitivities;
  rs.event_times.insert(rs.event_times.end(), st.event_times.begin(), st.event_times.end());
}

void follow_integration_stage(RunContext& c) {
  if (!c.sensitivities || !c.sensitivities->active) return;
  RunSensitivities& rs = *c.sensitivities;
  for (size_t i = 0; i < rs.parameters.size(); ++i) {
    SensitivityParameter& p = rs.parameters[i];
    for (int side = 0; side < 2; ++side) {
      RunContext& t = *p.twin[side]->context;
      const double d = side == 0 ? p.delta : -p.delta;
      for (size_t k = 0; k < c.q.size(); ++k) t.q[k] = c.q[k] + d * rs.last_positions[i][k];
      t.turns = c.turns;
    }
  }
}

NormalizedSensitivities normalized_sensitivities(const Result& r) {
  NormalizedSensitivities out;
  if (r.sensitivity_columns.empty() || !r.summary.contains("sensitivities")) return out;
  const json& params = r.summary["sensitivities"]["parameters"];
  const size_t np = params.size();
  out.columns = {"t"};
  out.data = {r.sensitivities[0]};
  for (size_t k = 1; k < r.columns.size(); ++k) {
    double scale = 0;
    for (double y : r.data[k]) scale = std::fmax(scale, std::fabs(y));
    // A sensor zero throughout has no scale; without samples (static steps only) every column is
    // kept, empty, so the file has sensitivities.csv's columns rather than `t` alone.
    if (!(scale > 0) && r.rows() > 0) continue;
    for (size_t i = 0; i < np; ++i) {
      const size_t col = 1 + (k - 1) * np + i;
      const double f = params[i]["value"].get<double>() / scale;
      out.columns.push_back(r.sensitivity_columns[col] + "*p/max|" + r.columns[k] + "|");
      out.data.emplace_back(r.sensitivities[col]);
      for (double& v : out.data.back()) v *= f;
    }
  }
  return out;
}

// How F_p is formed for p (formulation/parameter_reach.h), for summary.json.
std::string reach_text(const System& sys, const SensitivityParameter& p) {
  const ParameterReach r = parameter_reach(sys, *p.twin[0]->context->system, *p.twin[1]->context->system);
  if (!r.local) return "the twins' whole residuals (the parameter changes the model's structure)";
  std::string out = "the terms it may reach:";
  for (int b : r.bodies) out += " body " + sys.bodies[b].name + ",";
  for (int k : r.forces) out += " force " + sys.forces[k].name + ",";
  std::vector<std::string> groups;  // a joint's or cut's several constraints named once
  for (int k : r.constraints)
    if (std::find(groups.begin(), groups.end(), constraint_group(sys.constraints[k])) == groups.end())
      groups.push_back(constraint_group(sys.constraints[k]));
  for (const std::string& g : groups) out += " " + g + ",";
  if (r.bodies.empty() && r.forces.empty() && r.constraints.empty())
    return "zero (the parameter reaches no term of the dynamics' residual)";
  out.pop_back();
  if (!r.constraints.empty()) out += " (its constraints' terms with index2-ggl; index1 and penalty take the twins' whole residuals)";
  return out;
}

void close_sensitivities(RunContext& c) {
  if (!c.sensitivities) return;
  const RunSensitivities& rs = *c.sensitivities;
  json params = json::array();
  for (const SensitivityParameter& p : rs.parameters) {
    params.push_back({{"path", p.path}, {"value", p.value}, {"unit", p.unit}, {"difference_step", p.delta}});
    if (!p.moved_breakpoints.empty()) params.back()["moves_breakpoints"] = p.moved_breakpoints;
    params.back()["residual_derivative"] = reach_text(*c.system, p);
  }
  json columns = json::array();
  for (size_t k = 0; k < c.result.sensitivity_columns.size(); ++k)
    columns.push_back({{"name", c.result.sensitivity_columns[k]}, {"unit", c.result.sensitivity_units[k]}});
  json j;
  j["method"] = "IDAS forward sensitivities (staggered corrector on the run's Newton matrix; sensitivities in the "
                "local error test, their tolerances at least 1e-9 of the state's size, out of it for windows after a "
                "failure there); F_y s exact from the formulation without assembling F_y; F_p (over the terms each "
                "parameter reaches), consistent initial values and sensors by central differences over twin models "
                "at p +- d (docs/sensitivities.md)";
  j["parameters"] = params;
  j["columns"] = columns;
  j["rows"] = c.result.sensitivities.empty() ? 0 : c.result.sensitivities[0].size();
  if (!rs.event_times.empty()) {
    j["event_times"] = rs.event_times;
    j["events_note"] = "restarted at each event from the state's sensitivities, made consistent with the new modes; "
                       "the jump (y'- - y'+) dt_event/dp is zero because every switching force (wheel_contact) is "
                       "continuous at its switch (docs/sensitivities.md)";
  }
  // A run that stopped (failed, interrupted) ends the sensitivities' rows with its own.
  const std::string run_status = c.result.summary.value("status", std::string());
  if (rs.status == "ok" && run_status != "ok") {
    j["status"] = run_status;
    j["message"] = "the run stopped (" + run_status + "): the sensitivities' rows end with its rows";
  } else {
    j["status"] = rs.status;
    if (!rs.message.empty()) j["message"] = rs.message;
  }
  c.result.summary["sensitivities"] = j;
}

}  // namespace mbdae
