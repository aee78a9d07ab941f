// The integration stage of a run (kinematics or dynamics; cases/run/run_stages.h): the step's
// formulation from the registry, consistent initial values, IDA, and every output sample
// evaluated once into the Result's columns and handed to the sinks.
#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <cstdio>

#include "cases/scene/analysis_types.h"
#include "cases/run/failure_diagnosis.h"
#include "cases/run/run_stages.h"
#include "cases/run/sensitivities.h"
#include "cases/scene/step_tolerances.h"
#include "core/errors.h"
#include "core/finite_check.h"
#include "core/ida_driver.h"
#include "formulation/formulation_registry.h"
#include "formulation/initial_velocities.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "formulation/singularity.h"
#include "formulation/kinematic_sensitivities.h"
#include "formulation/twin_sensitivities.h"

namespace mbdae {
namespace {

using json = nlohmann::ordered_json;

double automatic_constraint_scale(const System& sys, const AnalysisStep& step) {
  // Scale the constraint rows like cj^2 M at a typical step (the output step or 1e-3 s).
  double m = 0;
  for (const auto& b : sys.bodies) m += b.mass;
  m = sys.bodies.empty() ? 1.0 : std::max(1e-6, m / sys.bodies.size());
  const double h = std::min(step.output_step > 0 ? step.output_step : 1e-3, 1e-3);
  return m / (h * h);
}

IdaOptions integration_options(const RunOptions& opt, const AnalysisStep& step, const StepTolerances& tol,
                               json& js) {
  IdaOptions io;
  io.t0 = step.t0;
  io.t1 = step.t_end;
  io.rtol = opt.rtol > 0 ? opt.rtol : step.rtol;
  io.atol = tol.absolute.position;
  io.output_step = opt.output_step > 0 ? opt.output_step : step.output_step;
  io.max_step = step.max_step;
  io.max_total_steps = static_cast<long>(step.max_steps);
  io.stop = opt.stop;
  io.nonlinear_convergence = step.newton_convergence;
  io.reduced_newton = step.newton_solve == "reduced";
  js["newton_convergence"] = io.nonlinear_convergence;
  js["rtol"] = io.rtol;
  js["output_projection"] = step.output_projection;
  js["atol"] = io.atol;
  js["tolerances"] = to_json(tol);
  js["output_step"] = io.output_step;
  return io;
}

// The parameters of the step's formulation.
FormulationParameters formulation_parameters(const System& sys, const Formulation& f, const AnalysisStep& step,
                                             const StepTolerances& tol, json& js) {
  // Index 3 scales its constraint rows like cj^2 M; the GGL and index-1 rows are scaled by
  // KLU's row scaling well enough (measured: no difference), so 1 unless the scene sets one.
  FormulationParameters p;
  p.constraint_scale = step.constraint_scale > 0 ? step.constraint_scale
                       : f.automatic_scale     ? automatic_constraint_scale(sys, step)
                                               : 1.0;
  // The scene's rates, else the formulation's default from the model's fast time scale.
  const double rate = default_baumgarte_rate(tol.scales, f.baumgarte_rate);
  p.baumgarte_alpha = step.baumgarte_alpha >= 0 ? step.baumgarte_alpha : rate;
  p.baumgarte_beta = step.baumgarte_beta >= 0 ? step.baumgarte_beta : rate;
  p.penalty = step.penalty;
  js["constraint_scale"] = p.constraint_scale;
  if (f.uses_penalty && p.penalty > 0) js["penalty"] = p.penalty;
  if (f.uses_baumgarte) {
    js["baumgarte_alpha"] = p.baumgarte_alpha;
    js["baumgarte_beta"] = p.baumgarte_beta;
  }
  return p;
}

// The DAE of the step's formulation, made by its registry entry.
std::unique_ptr<MultibodyDae> make_dae(const System& sys, const Formulation& f, const FormulationParameters& p,
                                       const StepTolerances& tol) {
  std::unique_ptr<MultibodyDae> dae = f.make(sys, p);
  dae->set_absolute_tolerances(tol.absolute);
  return dae;
}

// Modes, given initial rates, and consistent (y, y') at t0. False (after fail()) if impossible.
bool start(RunContext& c, const AnalysisStep& step, MultibodyDae& dae, std::vector<double>& y,
           std::vector<double>& yp, json& js) {
  const System& sys = *c.system;
  dae.state().modes = initial_modes(sys, c.q.data(), step.t0);
  if (c.turns) {  // the turns counted by the previous integration step
    dae.state().turns = *c.turns;
    dae.state().turns.timed = false;
  }
  dae.state().output.track_condition = step.type == AnalysisStep::Type::kKinematics;  // closeness to a singular configuration
  dae.state().output.accelerations = false;  // output samples solve for accelerations only if a sensor reports one
  for (const auto& s : sys.sensors)
    if (s.type == SensorSpec::Type::kAcceleration) dae.state().output.accelerations = true;
  // index3 runs far more accurate than rtol (error per unit step): 1e-3 rtol alone would let the
  // output solve's error show at loose rtol (docs/performance.md).
  dae.state().output.acceleration_tolerance = std::fmin(1e-10, 1e-3 * (c.options.rtol > 0 ? c.options.rtol : step.rtol));
  y.assign(dae.size(), 0.0);
  yp.assign(dae.size(), 0.0);
  std::copy(c.q.begin(), c.q.end(), y.begin());
  try {
    if (!step.initial_velocities.empty()) {
      // Given rates of joint coordinates; the rest of v from the constraints.
      std::vector<CoordinateRate> rates;
      for (const auto& [name, rate] : step.initial_velocities) rates.push_back({sys.coordinate_index(name), rate});
      solve_initial_velocities(sys, y.data(), step.t0, rates, y.data() + sys.nq());
    }
    dae.consistent_initial_values(step.t0, y, yp);
    if (!step.initial_velocities.empty()) {
      json rates;
      for (const auto& [name, rate] : step.initial_velocities)
        rates[name] = coordinate_rate(sys, sys.coordinate_index(name), y.data(), y.data() + sys.nq());
      js["initial_velocities"] = rates;  // as reached after the consistent start
    }
  } catch (const SolveError& e) {
    fail(c, e.status, e.what(), js);
    return false;
  }
  return true;
}

// The equations set aside as redundant, watched at every output sample. While the choice is
// valid they depend on the kept ones and hold as well as those do; a loop opening along them
// means the choice degraded and the motion is no longer the mechanism's (the penalty
// formulation, whose Newton matrix stays regular, would run on): the run stops, never `ok`.
struct SetAsideWatch {
  const System* all = nullptr;  // null: nothing set aside
  std::vector<int> off_all, off_kept;
  std::vector<double> phi_all, phi_kept;
  double floor = 0;  // the positions' promise: 10 rtol of the model's length
  bool degraded = false;
  double violation = 0, kept_violation = 0, t = 0;  // at the sample that failed

  SetAsideWatch(const RunContext& c, const StepTolerances& tol, double rtol) {
    if (!c.all_equations || c.all_equations->num_constraint_rows() <= c.system->num_constraint_rows()) return;
    all = c.all_equations.get();
    off_all = constraint_offsets(*all);
    off_kept = constraint_offsets(*c.system);
    phi_all.resize(off_all.back());
    phi_kept.resize(off_kept.back());
    floor = 10 * rtol * tol.scales.length;
  }
  // False where the equations set aside fail by more than 100 times the kept ones and by more
  // than the floor. Measured on the turntable four-bar: 1 to 2.5 times with the body-frame
  // choice (every formulation), 172 at the quarter turn with the world choice (penalty, which
  // ends 1.3 rad off otherwise).
  bool operator()(const System& kept, const double* q, double t_input) {
    if (!all) return true;
    constraint_values(*all, off_all, q, t_input, phi_all.data());
    constraint_values(kept, off_kept, q, t_input, phi_kept.data());
    const double va = max_abs(phi_all.data(), static_cast<int>(phi_all.size()));
    const double vk = max_abs(phi_kept.data(), static_cast<int>(phi_kept.size()));
    if (va <= std::fmax(100 * vk, floor)) return true;
    degraded = true;
    violation = va;
    kept_violation = vk;
    t = t_input;
    return false;
  }
};

// Evaluates each output sample once: the consistent state, the sensors, the Result's columns
// (reserved up front), the sinks, the quiet-sensor watch and the progress line.
struct Sampler {
  RunContext& c;
  const AnalysisStep& step;
  MultibodyDae& dae;
  SetAsideWatch& set_aside;
  std::vector<double> qo, vo, ao, sensors, row;
  double max_output_violation = 0;
  std::vector<int> quiet;
  std::vector<double> quiet_ref, quiet_max;
  std::chrono::steady_clock::time_point wall0 = std::chrono::steady_clock::now(), last_print = wall0;
  bool printed = false;
  std::string sink_error;  // a sink's failure (stops the run)
  std::function<void(double)> after_row;  // each written row's sensitivities (kinematic samples)

  Sampler(RunContext& c_, const AnalysisStep& s, MultibodyDae& d, SetAsideWatch& w, double output_step)
      : c(c_), step(s), dae(d), set_aside(w), sensors(c_.system->sensors.size()), row(c_.result.columns.size()) {
    const System& sys = *c.system;
    for (const auto& name : step.quiet_sensors)
      for (size_t k = 0; k < sys.sensors.size(); ++k)
        if (sys.sensors[k].name == name) quiet.push_back(static_cast<int>(k));
    quiet_max.assign(quiet.size(), 0.0);
    const double expected = std::floor((step.t_end - step.t0) / output_step) + 2;
    const size_t n = static_cast<size_t>(std::min(expected, double(1 << 22)));
    for (auto& col : c.result.data) col.reserve(col.size() + n);
  }

  bool operator()(double t, const double* y, const double* yp) {
    const System& sys = *c.system;
    max_output_violation =
        std::fmax(max_output_violation, dae.consistent_output(t, y, yp, qo, vo, ao, step.output_projection));
    if (!dae.state().output_failure.empty()) return false;  // not a consistent state: not written
    if (!set_aside(sys, qo.data(), dae.input_time(t))) return false;  // not the mechanism's motion: not written
    // Coordinate sensors count whole turns as the loads do (formulation/system.h, CoordinateTurns).
    evaluate_sensors(sys, dae.state().modes, qo.data(), vo.data(), ao.data(), dae.input_time(t), sensors.data(), nullptr,
                     &dae.state().turns);
    row[0] = t;
    for (size_t k = 0; k < c.column_sensors.size(); ++k) row[k + 1] = sensors[c.column_sensors[k]];
    if (const int k = first_non_finite(row.data(), static_cast<int>(row.size())); k >= 0)
      throw non_finite_error("sensor " + c.result.columns[k], row[k], t);  // the driver stops the run
    for (size_t k = 0; k < row.size(); ++k) c.result.data[k].push_back(row[k]);
    if (after_row) after_row(t);
    if (!c.sinks.empty()) {
      const Sample sample{t, row.data(), qo.data(), vo.data(), ao.empty() ? nullptr : ao.data(), &dae.state().modes,
                          dae.input_time(t)};
      try {
        for (Sink* s : c.sinks) s->sample(sample);
      } catch (const std::exception& e) {
        sink_error = e.what();
        return false;
      }
    }
    if (c.options.stop && c.options.stop->load(std::memory_order_relaxed)) return false;
    if (quiet_ref.empty())
      for (int k : quiet) quiet_ref.push_back(sensors[k]);
    if (t < step.quiet_until)
      for (size_t k = 0; k < quiet.size(); ++k)
        quiet_max[k] = std::fmax(quiet_max[k], std::fabs(sensors[quiet[k]] - quiet_ref[k]));
    if (c.options.progress) progress(t);
    return true;
  }

  void progress(double t) {
    const auto now = std::chrono::steady_clock::now();
    if (now - wall0 > std::chrono::seconds(1) && now - last_print > std::chrono::milliseconds(500)) {
      std::fprintf(stderr, "\r  t = %.4f of %.4f (%3.0f%%)", t, step.t_end, 100.0 * (t - step.t0) / (step.t_end - step.t0));
      last_print = now;
      printed = true;
    }
  }
};

// The sensitivities' twins for this step (cases/run/sensitivities.h): each twin's DAE with the
// run's formulation parameters, started from the twin's own chain of stages. Null when the
// sensitivities are off or a twin cannot start (they then stop; the run goes on).
std::unique_ptr<TwinSensitivities> twin_sensitivities(RunContext& c, const AnalysisStep& step, MultibodyDae& dae,
                                                      const Formulation& f, const FormulationParameters& fp,
                                                      const StepTolerances& tol) {
  if (!c.sensitivities || !c.sensitivities->active) return nullptr;
  const int k = static_cast<int>(&step - c.scene.steps.data());
  std::vector<ParameterTwins> twins;
  for (size_t i = 0; i < c.sensitivities->parameters.size(); ++i) {
    const SensitivityParameter& p = c.sensitivities->parameters[i];
    ParameterTwins pt;
    pt.delta = p.delta;
    pt.scale = p.scale;
    for (int side = 0; side < 2; ++side) {
      RunContext& t = *twin_context(c, i, side);
      std::unique_ptr<MultibodyDae> td = make_dae(*t.system, f, fp, tol);
      json tj;
      if (!start(t, t.scene.steps[k], *td, side == 0 ? pt.y_plus : pt.y_minus, side == 0 ? pt.yp_plus : pt.yp_minus, tj)) {
        sensitivities_failed(c, "twin_failed", "the twin of " + p.path + " cannot start analysis step " +
                                                   std::to_string(k) + ": " + t.result.message);
        return nullptr;
      }
      (side == 0 ? pt.plus : pt.minus) = std::move(td);
    }
    twins.push_back(std::move(pt));
  }
  return std::make_unique<TwinSensitivities>(dae, make_dae(*c.system, f, fp, tol), std::move(twins), true);
}

// A kinematic step whose constraints fix every coordinate (Phi_q square) and whose outputs need
// no accelerations: its samples' sensitivities by the implicit function theorem, none integrated.
bool kinematic_by_ift(const RunContext& c, const AnalysisStep& step) {
  if (!c.sensitivities || !c.sensitivities->active || step.type != AnalysisStep::Type::kKinematics ||
      !KinematicSensitivities::applicable(*c.system))
    return false;
  for (int k : c.column_sensors)
    if (c.system->sensors[k].type == SensorSpec::Type::kAcceleration) return false;
  return true;
}

// The implicit-function-theorem sensitivities of a kinematic step, over the twins' models.
std::unique_ptr<KinematicSensitivities> kinematic_sensitivities(RunContext& c, const AnalysisStep& step) {
  std::vector<std::pair<const System*, const System*>> twins;
  std::vector<double> deltas;
  for (size_t i = 0; i < c.sensitivities->parameters.size(); ++i) {
    twins.emplace_back(twin_context(c, i, 0)->system.get(), twin_context(c, i, 1)->system.get());
    deltas.push_back(c.sensitivities->parameters[i].delta);
  }
  return std::make_unique<KinematicSensitivities>(*c.system, std::move(twins), std::move(deltas));
}

// An error control that asked for positions below their rounding in most steps: the error
// stops following rtol (docs/formulation.md, "Error control"). A note in the step and the
// summary ("notes"), and on stderr unless quiet: the error itself may still be within the
// promise (a damped mechanism forgets its errors), which only an estimate can tell.
void note_rounding_floor(RunContext& c, const std::string& formulation, double rtol, double fraction, json& js) {
  if (!(fraction > 0.5)) return;
  const bool index3 = formulation.rfind("index3", 0) == 0;
  // index3 and index1 themselves hand over (below rtol 1e-6 and 1e-9): there a tighter rtol does buy accuracy.
  const char* further = formulation == "index3" ? "; below rtol 1e-6 index3 runs as index2-ggl, whose error follows rtol further"
                        : formulation == "index1" ? "; below rtol 1e-9 index1 runs as index2-ggl, whose error follows rtol further"
                        : index3               ? "; a tighter rtol buys steps, not accuracy; index2-ggl follows rtol further"
                                               : "; a tighter rtol buys steps, not accuracy";
  char buf[600];
  std::snprintf(buf, sizeof buf,
                "rtol %g: the %s error control asked for positions below their rounding (%s of the model's "
                "positions) in %.0f %% of the steps, so the error no longer falls with rtol at this rtol "
                "(docs/formulation.md, \"Error control\")%s; --error-estimate measures the error",
                rtol, formulation.c_str(), index3 ? "1e3 eps" : "100 eps", 100 * fraction, further);
  js["notes"].push_back(buf);
  c.result.summary["notes"].push_back(buf);
  if (c.options.verbose) std::fprintf(stderr, "mbdae: note: %s\n", buf);
}

// index3 asked below rtol 1e-6, index1 below 1e-9: the step records what was asked and why
// index2-ggl ran, in the step and the summary's notes (on stderr unless quiet).
void note_handover(RunContext& c, const std::string& asked, const std::string& used, double rtol, json& js) {
  const char* why = asked == "index3" ? "index3's error test would ask for positions below their rounding and its "
                                        "error would stop falling with rtol"
                                      : "index1's error test would stop at the velocities' rounding per step and its "
                                        "error would stop falling with rtol";
  char buf[500];
  std::snprintf(buf, sizeof buf,
                "rtol %g: %s runs as %s below rtol %g, where %s (docs/formulation.md); %s-no-handover keeps %s", rtol,
                asked.c_str(), used.c_str(), handover_rtol(asked), why, asked.c_str(), asked.c_str());
  js["formulation_asked"] = asked;
  js["formulation_handover"] = buf;
  c.result.summary["notes"].push_back(buf);
  if (c.options.verbose) std::fprintf(stderr, "mbdae: note: %s\n", buf);
}

// The step's formulation: the run option's, else the step's. With sensitivities a scene's index3
// step runs as index2-ggl, and says so (a formulation asked by name is refused before the run;
// docs/sensitivities.md), except a kinematic step whose sensitivities need no integration.
// A dynamics step's index3 below rtol 1e-6 (index1 below 1e-9) runs as index2-ggl, and says so
// (formulation/formulation_registry.h), unless the step runs at the tolerances its scene fixes.
std::string run_formulation(RunContext& c, const AnalysisStep& step, double rtol, json& js) {
  const std::string asked = !c.options.formulation.empty() ? c.options.formulation : step.formulation;
  const std::string name = step_formulation(step, c.options);
  if (name != asked) note_handover(c, asked, name, rtol, js);
  if (!c.sensitivities || !c.sensitivities->active || kinematic_by_ift(c, step) || sensitivity_formulation(name))
    return name;
  js["formulation_with_sensitivities"] = "index2-ggl instead of the scene's " + name + ": " + kIndex3SensitivityNote;
  return "index2-ggl";
}

// The step's sensitivities, when asked: integrated with the run (IDAS, io) or, for a kinematic
// step that allows it, by the implicit function theorem at each written row (the sampler).
struct StepSensitivities {
  std::unique_ptr<TwinSensitivities> integrated;
  std::unique_ptr<KinematicSensitivities> kinematic;
};

StepSensitivities attach_sensitivities(RunContext& c, const AnalysisStep& step, MultibodyDae& dae,
                                       const Formulation& f, const FormulationParameters& fp, const StepTolerances& tol,
                                       IdaOptions& io, Sampler& sampler, json& js) {
  StepSensitivities out;
  if (kinematic_by_ift(c, step)) {
    out.kinematic = kinematic_sensitivities(c, step);
    KinematicSensitivities* ks = out.kinematic.get();
    sampler.after_row = [&c, ks, &dae, &sampler](double t) {
      record_kinematic_sample(c, *ks, dae.state().modes, &dae.state().turns, t, sampler.qo.data(), sampler.vo.data());
    };
    js["sensitivity_method"] = "implicit function theorem at each sample (formulation/kinematic_sensitivities.h)";
    return out;
  }
  out.integrated = twin_sensitivities(c, step, dae, f, fp, tol);
  if (TwinSensitivities* ts = out.integrated.get()) {
    io.sensitivities = ts;
    const bool project = step.output_projection;
    io.sensitivity_output = [&c, ts, project](double t, const double* yy, const double* yyp, const double* const* s,
                                               const double* const* sp) {
      record_sensitivity_sample(c, *ts, t, yy, yyp, s, sp, project);
    };
  }
  return out;
}

// The step's events, breakpoints, reach, quiet sensors (summary.json) and the verbose line.
void describe_step(const RunContext& c, const AnalysisStep& step, const IdaStats& st, const MultibodyDae& dae,
                   const Sampler& sampler, json& js) {
  js["event_times"] = st.event_times;
  js["breakpoint_times"] = st.breakpoint_times;
  js["t_reached"] = st.t_reached;
  if (!sampler.quiet.empty()) {
    json qj;
    for (size_t k = 0; k < sampler.quiet.size(); ++k) qj[c.system->sensors[sampler.quiet[k]].name] = sampler.quiet_max[k];
    js["max_change_before"] = {{"time", step.quiet_until}, {"sensors", qj}};
  }
  if (c.options.verbose)
    std::printf("%s: %ld steps, %ld residual evaluations, %ld KLU factorizations, %zu events, "
                "cpu %.3f s, max constraint violation %.2e\n",
                js["type"].get<std::string>().c_str(), st.steps, st.residual_evals, st.linear_setups,
                st.event_times.size(), st.cpu_seconds, dae.state().statistics.max_position_violation);
}

json statistics_json(const IdaStats& st, const MultibodyDae& dae, const Sampler& s, long rows) {
  json stats;
  stats["steps"] = st.steps;
  stats["residual_evaluations"] = st.residual_evals;
  stats["jacobian_evaluations"] = st.jacobian_evals;
  stats["klu_factorizations"] = st.linear_setups;
  stats["klu_fresh_factorizations"] = st.fresh_factorizations;
  stats["error_test_failures"] = st.error_test_failures;
  stats["nonlinear_iterations"] = st.nonlinear_iterations;
  stats["nonlinear_failures"] = st.nonlinear_failures;
  stats["restarts"] = st.restarts;
  stats["cpu_seconds"] = st.cpu_seconds;
  stats["max_position_violation_steps"] = dae.state().statistics.max_position_violation;
  stats["max_position_violation_output_before_projection"] = s.max_output_violation;
  stats["max_euler_norm_drift"] = dae.state().statistics.max_norm_drift;
  stats["max_velocity_violation_steps"] = dae.state().statistics.max_velocity_violation;
  if (dae.state().output.track_condition) {
    // Closeness to a singular configuration along a kinematic run.
    stats["max_constraint_condition"] = dae.state().statistics.max_condition;
    stats["max_constraint_condition_time"] = dae.state().statistics.max_condition_time;
  }
  stats["output_rows"] = rows;
  stats["rounding_floor_fraction"] = dae.rounding_floor_fraction();
  return stats;
}

// The last configuration reached and, if the constraint Jacobian is singular there, why the run
// cannot go on (a drive past the mechanism's travel, a dead centre): after a failed step, and
// after a step budget spent in ever smaller steps.
void report_failure(RunContext& c, const IdaStats& st, MultibodyDae& dae, const std::vector<double>& y, json& js) {
  std::string message = st.message;
  if (st.status == "integration_failed" || st.status == "step_limit") {
    const System& sys = *c.system;
    const FailureDiagnosis d = diagnose_integration_failure(
        sys, dae.state().modes, c.column_sensors, c.q.data(), y.data() + sys.nq(), st.t_reached, dae.input_time(st.t_reached),
        dae.augmented().constraint_condition(c.q.data()), st.message, c.all_equations.get());
    for (const auto& [key, value] : d.details.items()) js[key] = value;
    if (d.singular || d.degraded_choice) {
      js["solver_message"] = st.message;
      message = d.message;
    }
  }
  fail(c, st.status, message, js);
}

}  // namespace

// A scene's own tolerances (its rtol and an atol of its own, the run giving neither) keep its
// formulation: the suspension's and the IFToMM scenes' were chosen with index3, and index2-ggl
// does not pass A02's singular configurations.
std::string step_formulation(const AnalysisStep& step, const RunOptions& options) {
  const std::string asked = !options.formulation.empty() ? options.formulation : step.formulation;
  const bool scene_tolerances = step.atol > 0 && options.atol <= 0 && options.rtol <= 0;
  if (scene_tolerances || step.type != AnalysisStep::Type::kDynamics) return asked;
  return formulation_at(asked, options.rtol > 0 ? options.rtol : step.rtol);
}

bool integration_stage(RunContext& c, const AnalysisStep& step, json& js) {
  const System& sys = *c.system;
  js["type"] = analysis_type(step.type).name;
  const double rtol = c.options.rtol > 0 ? c.options.rtol : step.rtol;
  const std::string name = run_formulation(c, step, rtol, js);
  const Formulation* f = find_formulation(name);
  if (!f) throw ModelError(step.where.file, step.where.line, "formulation",
                           "unknown formulation '" + name + "' (" + formulation_names() + ")");
  js["formulation"] = name;
  js["integrator"] = f->integrator_name;
  const StepTolerances tol = step_tolerances(sys, c.q.data(), step, rtol, c.options.atol);
  IdaOptions io = integration_options(c.options, step, tol, js);
  const FormulationParameters fp = formulation_parameters(sys, *f, step, tol, js);
  const std::unique_ptr<MultibodyDae> dae = make_dae(sys, *f, fp, tol);
  // The solve used: the reduced one only where the formulation has the kinematic rows.
  js["newton_solve"] = io.reduced_newton && dae->kinematic_rows() > 0 ? "reduced" : "full";
  std::vector<double> y, yp;
  if (!start(c, step, *dae, y, yp, js)) return false;
  const RunInfo info{&c.scene, &sys, &step, &c.result.columns, &c.result.units, &c.result};
  try {
    for (Sink* s : c.sinks) s->begin(info);
  } catch (const std::exception& e) {
    fail(c, "output_failed", e.what(), js);
    c.result.exit_code = 4;
    return false;
  }
  SetAsideWatch watch(c, tol, io.rtol);
  // With equations set aside, a Newton matrix whose pivots degraded may be the kept equations
  // going singular where the mechanism's are not: a degraded choice, which index3 can step
  // across with a wrong motion (TurningLoops, the world choice). The run stops there and
  // report_failure tells the choice's failure.
  if (c.all_equations)
    io.after_fresh_factorization = [&](double t, const double* yy) {
      return !check_equation_choice(*c.all_equations, sys, yy, dae->input_time(t), kNearlySingularRatio).degraded;
    };
  Sampler sampler(c, step, *dae, watch, io.output_step);
  const StepSensitivities sens = attach_sensitivities(c, step, *dae, *f, fp, tol, io, sampler, js);
  const TwinSensitivities* ts = sens.integrated.get();
  const size_t rows_before = c.result.rows();
  const IdaStats st = f->integrator(*dae, io, y, yp, [&](double t, const double* yy, const double* yyp) { return sampler(t, yy, yyp); });
  if (sampler.printed) std::fprintf(stderr, "\n");
  std::copy(y.begin(), y.begin() + sys.nq(), c.q.begin());
  c.turns = dae->state().turns;
  js["statistics"] = statistics_json(st, *dae, sampler, static_cast<long>(c.result.rows() - rows_before));
  if (ts) sensitivity_statistics(c, st, js["statistics"]);
  if (!st.sensitivity_failure.empty()) sensitivities_failed(c, "integration_failed", st.sensitivity_failure);
  note_rounding_floor(c, name, io.rtol, dae->rounding_floor_fraction(), js);
  follow_integration_stage(c);
  describe_step(c, step, st, *dae, sampler, js);
  if (!dae->state().output_failure.empty()) {
    fail(c, "output_solve_failed", dae->state().output_failure, js);
    return false;
  }
  if (watch.degraded) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "the equations set aside as redundant at the start no longer hold at t = %.10g (violated by "
                  "%.3g where the kept ones hold to %.3g): a degraded equation choice, the motion from there on "
                  "is not the mechanism's",
                  watch.t, watch.violation, watch.kept_violation);
    fail(c, "integration_failed", buf, js);
    return false;
  }
  if (!sampler.sink_error.empty()) {  // a file that cannot be written: exit code 4 (docs/errors.md)
    fail(c, "output_failed", sampler.sink_error, js);
    c.result.exit_code = 4;
    return false;
  }
  if (!st.ok) {
    report_failure(c, st, *dae, y, js);
    return false;
  }
  if (st.ok && c.options.stop && c.options.stop->load() && st.t_reached < step.t_end) {
    fail(c, "interrupted", "interrupted at t = " + std::to_string(st.t_reached), js);
    return false;
  }
  js["status"] = "ok";
  return true;
}

}  // namespace mbdae
