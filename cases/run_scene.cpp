#include "cases/run_scene.h"
#include "cases/step_tolerances.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <type_traits>

#include "cases/failure_diagnosis.h"
#include "core/errors.h"
#include "core/finite_check.h"
#include "core/ida_driver.h"
#include "core/output.h"
#include "formulation/analyses.h"
#include "formulation/assembly_mode.h"
#include "formulation/ggl_dae.h"
#include "formulation/index1_dae.h"
#include "formulation/index3_dae.h"
#include "formulation/initial_velocities.h"
#include "formulation/mechanics.h"
#include "formulation/augmented_solver.h"
#include "formulation/redundancy.h"
#include "formulation/sensors.h"

namespace mbdae {
namespace {

using json = nlohmann::ordered_json;

std::vector<int> coordinate_indices(const System& sys, const std::vector<std::string>& names,
                                    const AnalysisStep& step, const std::string& field) {
  std::vector<int> out;
  for (const auto& n : names) {
    const int k = sys.coordinate_index(n);
    if (k < 0) throw ModelError(step.where.file, step.where.line, field, "no coordinate named '" + n + "'");
    if (sys.coordinates[k].merged)
      throw ModelError(step.where.file, step.where.line, field,
                       "coordinate '" + n + "' is locked (its joint is merged); it cannot be held or solved for");
    out.push_back(k);
  }
  return out;
}

json coordinates_json(const System& sys, const double* q) {
  json j;
  for (int k = 0; k < static_cast<int>(sys.coordinates.size()); ++k)
    j[sys.coordinates[k].name] = coordinate_value(sys, k, q);
  return j;
}

json sensors_json(const System& sys, const std::vector<char>& modes, const double* q, double t) {
  std::vector<double> v(sys.nq(), 0.0), out(sys.sensors.size());
  evaluate_sensors(sys, modes, q, v.data(), nullptr, t, out.data());
  json j;
  for (size_t k = 0; k < sys.sensors.size(); ++k)
    if (sys.sensors[k].type != SensorSpec::Type::kAcceleration) j[sys.sensors[k].name] = out[k];
  return j;
}

void print_configuration(const System& sys, const double* q, double t) {
  std::printf("  joint coordinates:\n");
  for (int k = 0; k < static_cast<int>(sys.coordinates.size()); ++k) {
    const double v = coordinate_value(sys, k, q);
    const bool rot = sys.coordinates[k].function.rotation;
    std::printf("    %-8s = %.12f %s", sys.coordinates[k].name.c_str(), v, rot ? "rad" : "m");
    if (rot) std::printf("  (%.9f deg)", v * 180.0 / M_PI);
    std::printf("%s\n", sys.coordinates[k].merged ? "  [locked]" : "");
  }
  const std::vector<char> modes = initial_modes(sys, q, t);
  std::vector<double> v(sys.nq(), 0.0), out(sys.sensors.size());
  evaluate_sensors(sys, modes, q, v.data(), nullptr, t, out.data());
  std::printf("  sensors:\n");
  for (size_t k = 0; k < sys.sensors.size(); ++k) {
    const auto type = sys.sensors[k].type;
    if (type == SensorSpec::Type::kAcceleration || type == SensorSpec::Type::kVelocity ||
        type == SensorSpec::Type::kCoordinateRate)
      continue;
    std::printf("    %-12s = %.12f\n", sys.sensors[k].name.c_str(), out[k]);
  }
}

double automatic_constraint_scale(const System& sys, const AnalysisStep& step) {
  // Scale the constraint rows like cj^2 M at a typical step (the output step or 1e-3 s).
  double m = 0;
  for (const auto& b : sys.bodies) m += b.mass;
  m = sys.bodies.empty() ? 1.0 : std::max(1e-6, m / sys.bodies.size());
  const double h = std::min(step.output_step > 0 ? step.output_step : 1e-3, 1e-3);
  return m / (h * h);
}

std::string sensor_unit(const System& sys, const Sensor& s) {
  using T = SensorSpec::Type;
  switch (s.type) {
    case T::kPosition: return "m";
    case T::kVelocity: return "m/s";
    case T::kAcceleration: return "m/s^2";
    case T::kAxis: return "1";
    case T::kCoordinate: return sys.coordinates[s.target].function.rotation ? "rad" : "m";
    case T::kCoordinateRate: return sys.coordinates[s.target].function.rotation ? "rad/s" : "m/s";
    case T::kForceLength:
    case T::kForceValue: {  // torques and rotational joint springs measure angles and moments
      const Force& f = sys.forces[s.target];
      const bool rotational = f.type == ForceSpec::Type::kTorque ||
                              (f.type == ForceSpec::Type::kJointSpringDamper && f.coordinate.rotation);
      if (s.type == T::kForceLength) return rotational ? (f.type == ForceSpec::Type::kTorque ? "1" : "rad") : "m";
      return rotational ? "N m" : "N";
    }
    case T::kKineticEnergy:
    case T::kPotentialEnergy: return "J";
    case T::kExpression: return "";
  }
  return "";
}

}  // namespace

RunOutcome run_scene(const Scene& scene, const RunOptions& opt, const std::vector<Sink*>& sinks) {
  RunOutcome out;
  json& summary = out.summary;
  summary["scene"] = scene.file;
  summary["model"] = scene.model.name;
  summary["status"] = "running";
  json steps = json::array();
  json warnings = json::array();
  auto write_summary = [&] {
    if (!warnings.empty()) summary["warnings"] = warnings;
    summary["steps"] = steps;
    if (!opt.out_dir.empty()) write_json_file(opt.out_dir + "/summary.json", summary);
  };
  if (!opt.out_dir.empty()) prepare_output_folder(opt.out_dir);

  System sys = build_system(scene.model);
  summary["bodies"] = sys.num_bodies();
  summary["coordinates"] = sys.nq();
  summary["constraint_equations"] = sys.num_constraint_rows();
  {
    json merged = json::object();
    for (const auto& b : sys.bodies)
      if (!b.merged.empty()) merged[b.name] = b.merged;
    json ground = json::array();
    for (const auto& [name, f] : sys.frames)
      if (f.body < 0 && name != kGround) ground.push_back(name);
    summary["merged_into_body"] = merged;
    summary["merged_into_ground"] = ground;
  }
  // Redundant constraint equations, found at a configuration that satisfies the constraints
  // (a regularized projection of the guess), then removed or reported as an error.
  {
    std::vector<double> qc = sys.q0;
    AugmentedSolver projector(sys);
    projector.positions(qc.data(), 0.0, 1e-12, 100, 1e-10);
    const bool remove = scene.redundant_constraints != "fail";
    const RedundancyReport rr = find_redundant_constraints(sys, qc.data(), 0.0, remove);
    summary["redundant_constraints"] = {{"policy", scene.redundant_constraints},
                                        {"equations", rr.equations},
                                        {"rank", rr.rank},
                                        {"redundant", rr.redundant}};
    if (!rr.redundant.empty()) {
      std::string list;
      for (const auto& r : rr.redundant) list += "\n  " + r;
      if (!remove)
        throw ModelError(scene.file, 0, "redundant_constraints",
                         std::to_string(rr.redundant.size()) + " redundant constraint equations:" + list);
      if (opt.verbose)
        std::fprintf(stderr, "mbdae: removed %zu redundant constraint equations:%s\n", rr.redundant.size(),
                     list.c_str());
    }
    summary["constraint_equations"] = sys.num_constraint_rows();
  }
  std::vector<double> q = sys.q0;
  // Output columns.
  std::vector<int> column_sensors;
  if (scene.columns.empty()) {
    for (size_t k = 0; k < sys.sensors.size(); ++k) column_sensors.push_back(static_cast<int>(k));
  } else {
    for (const auto& c : scene.columns) {
      int idx = -1;
      for (size_t k = 0; k < sys.sensors.size(); ++k)
        if (sys.sensors[k].name == c) idx = static_cast<int>(k);
      if (idx < 0) throw ModelError(scene.file, 0, "output", "no sensor named '" + c + "'");
      column_sensors.push_back(idx);
    }
  }
  out.columns = {"t"};
  out.units = {"s"};
  for (int k : column_sensors) {
    out.columns.push_back(sys.sensors[k].name);
    out.units.push_back(sensor_unit(sys, sys.sensors[k]));
  }

  auto fail = [&](const std::string& status, const std::string& message, json step) {
    step["status"] = status;
    step["message"] = message;
    steps.push_back(step);
    summary["status"] = status;
    summary["message"] = message;
    out.exit_code = 3;
    out.q = q;
    std::fprintf(stderr, "mbdae: %s\n", message.c_str());  // also under --quiet: a failure is always said
    write_summary();  // last: it may fail too (a full disk), and the message above is said first
  };

  for (const AnalysisStep& step : scene.steps) {
    json js;
    switch (step.type) {
      case AnalysisStep::Type::kAssembly: {
        js["type"] = "assembly";
        const std::vector<int> held = coordinate_indices(sys, step.hold, step, "hold");
        const AssemblyResult r = assemble_positions(sys, held, step.t0, q);
        js["iterations"] = r.iterations;
        js["max_constraint_violation"] = r.residual;
        js["coordinates"] = coordinates_json(sys, q.data());
        if (!r.converged) {
          fail("assembly_failed", r.message, js);
          return out;
        }
        js["sensors"] = sensors_json(sys, initial_modes(sys, q.data(), step.t0), q.data(), step.t0);
        if (step.mode_check != "off") {
          // Another assembly mode? (formulation/assembly_mode.h)
          const std::vector<CoordinateMove> moved =
              coordinates_far_from_guess(sys, q.data(), held, step.mode_check_deg * M_PI / 180.0);
          json list = json::array();
          std::ostringstream names, detail;
          for (size_t i = 0; i < moved.size(); ++i) {
            const CoordinateMove& m = moved[i];
            list.push_back({{"coordinate", m.name}, {"guess_deg", m.guess * 180 / M_PI},
                            {"converged_deg", m.converged * 180 / M_PI}, {"change_deg", m.change * 180 / M_PI}});
            names << (i ? ", " : "") << m.name;
            char buf[160];
            std::snprintf(buf, sizeof buf, "%s%s %.1f -> %.1f deg", i ? ", " : "", m.name.c_str(),
                          m.guess * 180 / M_PI, m.converged * 180 / M_PI);
            detail << buf;
          }
          js["assembly_mode"] = {{"policy", step.mode_check},
                                 {"limit_deg", step.mode_check_deg},
                                 {"same_as_guess", moved.empty()},
                                 {"far_from_guess", list}};
          if (!moved.empty()) {
            char limit[32];
            std::snprintf(limit, sizeof limit, "%g", step.mode_check_deg);
            const std::string message =
                "assembly converged far from the guess, probably to another assembly mode: coordinate" +
                std::string(moved.size() > 1 ? "s " : " ") + names.str() + " moved by more than " + limit +
                " degrees from the guess (" + detail.str() + "); check the guess (mode_check: " + step.mode_check + ")";
            if (step.mode_check == "fail") {
              fail("assembly_mode_changed", message, js);
              return out;
            }
            js["warnings"] = json::array({message});
            warnings.push_back(message);
            std::fprintf(stderr, "mbdae: warning: %s\n", message.c_str());
          }
        }
        js["status"] = "ok";
        if (opt.verbose) {
          std::printf("assembly: converged in %d iterations, max constraint violation %.3g\n", r.iterations, r.residual);
          print_configuration(sys, q.data(), step.t0);
        }
        break;
      }
      case AnalysisStep::Type::kEquilibrium: {
        js["type"] = "equilibrium";
        EquilibriumOptions eo;
        eo.t = step.t0;
        eo.hold = coordinate_indices(sys, step.hold, step, "hold");
        eo.release = coordinate_indices(sys, step.release, step, "release");
        for (const auto& u : step.unknowns) {
          const size_t dot = u.rfind('.');
          const int f = dot == std::string::npos ? -1 : sys.force_index(u.substr(0, dot));
          Force probe = f >= 0 ? sys.forces[f] : Force{};
          if (f < 0 || !force_parameter(probe, u.substr(dot + 1)))
            throw ModelError(step.where.file, step.where.line, "unknowns",
                             "'" + u + "' is not a force parameter (force.free_length, .stiffness, .damping)");
          eo.parameters.push_back({f, u.substr(dot + 1)});
        }
        if (eo.release.size() != eo.parameters.size())
          throw ModelError(step.where.file, step.where.line, "release",
                           "one released coordinate is needed per unknown parameter");
        const EquilibriumResult r = solve_equilibrium(sys, q, eo);
        js["iterations"] = r.iterations;
        js["relative_force_residual"] = r.force_residual;
        js["constraint_residual"] = r.constraint_residual;
        json params = json::object();
        for (size_t p = 0; p < eo.parameters.size(); ++p) {
          const std::string key = sys.forces[eo.parameters[p].first].name + "." + eo.parameters[p].second;
          params[key] = r.parameter_values[p];
          if (eo.parameters[p].second == "free_length") {
            js["spring_free_length"] = r.parameter_values[p];
            summary["spring_free_length"] = r.parameter_values[p];
          }
        }
        js["parameters"] = params;
        json reactions = json::object();
        for (size_t h = 0; h < eo.hold.size(); ++h) reactions[step.hold[h]] = r.hold_reactions[h];
        js["hold_reactions"] = reactions;
        js["coordinates"] = coordinates_json(sys, q.data());
        if (!r.converged) {
          fail("equilibrium_failed", r.message, js);
          return out;
        }
        js["sensors"] = sensors_json(sys, initial_modes(sys, q.data(), step.t0), q.data(), step.t0);
        js["status"] = "ok";
        summary["equilibrium_coordinates"] = js["coordinates"];
        if (opt.verbose) {
          std::printf("equilibrium: converged in %d iterations\n", r.iterations);
          for (auto& [k, v] : params.items()) std::printf("  %s = %.12f\n", k.c_str(), v.get<double>());
          print_configuration(sys, q.data(), step.t0);
        }
        break;
      }
      case AnalysisStep::Type::kKinematics:
      case AnalysisStep::Type::kDynamics: {
        js["type"] = step.type == AnalysisStep::Type::kKinematics ? "kinematics" : "dynamics";
        const std::string formulation = !opt.formulation.empty() ? opt.formulation : step.formulation;
        js["formulation"] = formulation;
        IdaOptions io;
        io.t0 = step.t0;
        io.t1 = step.t_end;
        io.rtol = opt.rtol > 0 ? opt.rtol : step.rtol;
        const StepTolerances tolerances = step_tolerances(sys, q.data(), step, io.rtol, opt.atol);
        io.atol = tolerances.absolute.position;
        io.output_step = opt.output_step > 0 ? opt.output_step : step.output_step;
        io.max_step = step.max_step;
        io.stop = opt.stop;
        io.nonlinear_convergence = step.newton_convergence;
        js["newton_convergence"] = io.nonlinear_convergence;
        js["rtol"] = io.rtol;
        js["output_projection"] = step.output_projection;
        js["atol"] = io.atol;
        js["tolerances"] = to_json(tolerances);
        js["output_step"] = io.output_step;
        // Index 3 scales its constraint rows like cj^2 M; the GGL and index-1 rows are scaled by
        // KLU's row scaling well enough (measured: no difference), so 1 unless the scene sets one.
        const double scale = step.constraint_scale > 0 ? step.constraint_scale
                             : formulation.rfind("index3", 0) == 0 ? automatic_constraint_scale(sys, step) : 1.0;
        js["constraint_scale"] = scale;
        // The integration is the same for every formulation: run it on whichever DAE was made.
        auto integrate_dae = [&](MultibodyDae& dae) -> bool {
        dae.modes = initial_modes(sys, q.data(), step.t0);
        dae.set_absolute_tolerances(tolerances.absolute);
        // A kinematic run reports how close it comes to a singular configuration.
        dae.track_condition = step.type == AnalysisStep::Type::kKinematics;
          // Output samples solve for accelerations only if a sensor reports one.
          dae.output_accelerations = false;
          for (const auto& s : sys.sensors)
            if (s.type == SensorSpec::Type::kAcceleration) dae.output_accelerations = true;
        std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
        std::copy(q.begin(), q.end(), y.begin());
        try {
          if (!step.initial_velocities.empty()) {
            // Given rates of joint coordinates; the rest of v from the constraints.
            std::vector<CoordinateRate> rates;
            for (const auto& [name, rate] : step.initial_velocities)
              rates.push_back({sys.coordinate_index(name), rate});
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
          fail(e.status, e.what(), js);
          return false;
        }
        CsvWriter csv;
        if (!opt.out_dir.empty()) csv.open(opt.out_dir + "/results.csv", out.columns);
        const RunInfo info{&scene, &sys, &step, &out.columns, &out.units};
        for (Sink* s : sinks) s->begin(info);
        std::vector<double> qo, vo, ao, sensors(sys.sensors.size()), row(out.columns.size());
        double max_output_violation = 0;
        std::vector<int> quiet;
        for (const auto& name : step.quiet_sensors)
          for (size_t k = 0; k < sys.sensors.size(); ++k)
            if (sys.sensors[k].name == name) quiet.push_back(static_cast<int>(k));
        std::vector<double> quiet_ref, quiet_max(quiet.size(), 0.0);
        const auto wall0 = std::chrono::steady_clock::now();
        auto last_print = wall0;
        bool printed = false;
        long rows = 0;
        bool first_sample = true;
        std::string output_error;  // a failed write stops the run (status output_failed, exit 4)
        auto output = [&](double t, const double* yy, const double* yyp) {
          max_output_violation = std::fmax(max_output_violation, dae.consistent_output(t, yy, yyp, qo, vo, ao, step.output_projection));
          // Coordinate sensors unwrap against the previous sample (formulation/sensors.h).
          evaluate_sensors(sys, dae.modes, qo.data(), vo.data(), ao.data(), dae.input_time(t), sensors.data(),
                           first_sample ? nullptr : sensors.data());
          first_sample = false;
          row[0] = t;
          for (size_t c = 0; c < column_sensors.size(); ++c) row[c + 1] = sensors[column_sensors[c]];
          if (const int k = first_non_finite(row.data(), static_cast<int>(row.size())); k >= 0)
            throw non_finite_error("sensor " + out.columns[k], row[k], t);  // the driver stops the run
          if (!opt.out_dir.empty()) {
            try {
              csv.row(row.data());
              if (++rows % 256 == 0) csv.flush();  // whole rows on disk as the run goes
            } catch (const OutputError& e) {
              output_error = e.what();
              return false;
            }
          }
          if (opt.keep_rows) out.rows.push_back(row);
          if (!sinks.empty()) {
            const Sample sample{t, row.data(), qo.data(), vo.data(), ao.empty() ? nullptr : ao.data(), &dae.modes,
                                dae.input_time(t)};
            for (Sink* s : sinks) s->sample(sample);
          }
          if (opt.stop && opt.stop->load(std::memory_order_relaxed)) return false;
          if (quiet_ref.empty()) for (int k : quiet) quiet_ref.push_back(sensors[k]);
          if (t < step.quiet_until)
            for (size_t k = 0; k < quiet.size(); ++k)
              quiet_max[k] = std::fmax(quiet_max[k], std::fabs(sensors[quiet[k]] - quiet_ref[k]));
          if (opt.progress) {
            const auto now = std::chrono::steady_clock::now();
            if (now - wall0 > std::chrono::seconds(1) && now - last_print > std::chrono::milliseconds(500)) {
              std::fprintf(stderr, "\r  t = %.4f of %.4f (%3.0f%%)", t, step.t_end,
                           100.0 * (t - step.t0) / (step.t_end - step.t0));
              last_print = now;
              printed = true;
            }
          }
          return true;
        };
        const IdaStats st = integrate(dae, io, y, yp, output);
        if (printed) std::fprintf(stderr, "\n");
        if (output_error.empty()) try {
            csv.close();
          } catch (const OutputError& e) {
            output_error = e.what();
          }
        std::copy(y.begin(), y.begin() + sys.nq(), q.begin());
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
        stats["max_position_violation_steps"] = dae.max_position_violation;
        stats["max_position_violation_output_before_projection"] = max_output_violation;
        stats["max_euler_norm_drift"] = dae.max_norm_drift;
        stats["max_velocity_violation_steps"] = dae.max_velocity_violation;
        if (dae.track_condition) {
          // Closeness to a singular configuration along a kinematic run.
          stats["max_constraint_condition"] = dae.max_condition;
          stats["max_constraint_condition_time"] = dae.max_condition_time;
        }
        stats["output_rows"] = out.rows.size() ? static_cast<long>(out.rows.size()) : csv.rows();
        js["statistics"] = stats;
        js["event_times"] = st.event_times;
        js["breakpoint_times"] = st.breakpoint_times;
        js["t_reached"] = st.t_reached;
        if (!quiet.empty()) {
          json qj;
          for (size_t k = 0; k < quiet.size(); ++k) qj[sys.sensors[quiet[k]].name] = quiet_max[k];
          js["max_change_before"] = {{"time", step.quiet_until}, {"sensors", qj}};
        }
        if (opt.verbose)
          std::printf("%s: %ld steps, %ld residual evaluations, %ld KLU factorizations, %zu events, "
                      "cpu %.3f s, max constraint violation %.2e\n",
                      js["type"].get<std::string>().c_str(), st.steps, st.residual_evals, st.linear_setups,
                      st.event_times.size(), st.cpu_seconds, dae.max_position_violation);
        if (!output_error.empty()) {
          fail("output_failed", output_error, js);
          out.exit_code = 4;
          return false;
        }
        if (st.ok && opt.stop && opt.stop->load() && st.t_reached < step.t_end) {
          fail("interrupted", "interrupted at t = " + std::to_string(st.t_reached), js);
          return false;
        }
        if (!st.ok) {
          // The last configuration reached and, if the constraint Jacobian is singular there,
          // why the run cannot go on (a drive past the mechanism's travel, a dead centre).
          std::string message = st.message;
          if (st.status == "integration_failed") {
            const FailureDiagnosis d = diagnose_integration_failure(
                sys, dae.modes, column_sensors, q.data(), y.data() + sys.nq(), st.t_reached,
                dae.input_time(st.t_reached), dae.augmented().constraint_condition(q.data()), st.message);
            for (const auto& [key, value] : d.details.items()) js[key] = value;
            if (d.singular) {
              js["solver_message"] = st.message;
              message = d.message;
            }
          }
          fail(st.status, message, js);
          return false;
        }
        return true;
        };
        bool integrated = false;
        if (formulation == "index2-ggl") {
          GglDae dae(sys, scale);
          integrated = integrate_dae(dae);
        } else if (formulation == "index1" || formulation == "penalty") {
          const double penalty = formulation == "penalty" ? step.penalty : 0.0;
          if (penalty > 0) js["penalty"] = penalty;
          js["baumgarte_alpha"] = tolerances.baumgarte_alpha;
          js["baumgarte_beta"] = tolerances.baumgarte_beta;
          Index1Dae dae(sys, scale, BaumgarteParameters{tolerances.baumgarte_alpha, tolerances.baumgarte_beta}, false, penalty);
          integrated = integrate_dae(dae);
        } else {
          Index3Dae dae(sys, scale, formulation != "index3-positions");
          integrated = integrate_dae(dae);
        }
        if (!integrated) return out;
        js["status"] = "ok";
        break;
      }
    }
    steps.push_back(js);
  }
  summary["status"] = "ok";
  write_summary();
  out.q = q;
  return out;
}

}  // namespace mbdae
