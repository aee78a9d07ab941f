// The static stages of a run: assembly and equilibrium (cases/run/run_stages.h).
#include <cmath>
#include <cstdio>
#include <sstream>

#include "cases/run/run_stages.h"
#include "core/errors.h"
#include "formulation/analyses.h"
#include "formulation/assembly_mode.h"
#include "formulation/forces.h"
#include "formulation/mechanics.h"
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
        type == SensorSpec::Type::kCoordinateRate || type == SensorSpec::Type::kAngularVelocity ||
        type == SensorSpec::Type::kAngularMomentum)
      continue;
    std::printf("    %-12s = %.12f\n", sys.sensors[k].name.c_str(), out[k]);
  }
}

// Another assembly mode? (formulation/assembly_mode.h) Returns false if the step fails on it.
bool check_assembly_mode(RunContext& c, const AnalysisStep& step, const std::vector<int>& held, json& js) {
  const std::vector<CoordinateMove> moved =
      coordinates_far_from_guess(*c.system, c.q.data(), held, step.mode_check_deg * M_PI / 180.0);
  json list = json::array();
  std::ostringstream names, detail;
  for (size_t i = 0; i < moved.size(); ++i) {
    const CoordinateMove& m = moved[i];
    list.push_back({{"coordinate", m.name}, {"guess_deg", m.guess * 180 / M_PI},
                    {"converged_deg", m.converged * 180 / M_PI}, {"change_deg", m.change * 180 / M_PI}});
    names << (i ? ", " : "") << m.name;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s%s %.1f -> %.1f deg", i ? ", " : "", m.name.c_str(), m.guess * 180 / M_PI,
                  m.converged * 180 / M_PI);
    detail << buf;
  }
  js["assembly_mode"] = {{"policy", step.mode_check},
                         {"limit_deg", step.mode_check_deg},
                         {"same_as_guess", moved.empty()},
                         {"far_from_guess", list}};
  if (moved.empty()) return true;
  char limit[32];
  std::snprintf(limit, sizeof limit, "%g", step.mode_check_deg);
  const std::string message =
      "assembly converged far from the guess, probably to another assembly mode: coordinate" +
      std::string(moved.size() > 1 ? "s " : " ") + names.str() + " moved by more than " + limit +
      " degrees from the guess (" + detail.str() + "); check the guess (mode_check: " + step.mode_check + ")";
  if (step.mode_check == "fail") {
    fail(c, "assembly_mode_changed", message, js);
    return false;
  }
  js["warnings"] = json::array({message});
  c.warnings.push_back(message);
  std::fprintf(stderr, "mbdae: warning: %s\n", message.c_str());
  return true;
}

EquilibriumOptions equilibrium_options(const System& sys, const AnalysisStep& step) {
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
    throw ModelError(step.where.file, step.where.line, "release", "one released coordinate is needed per unknown parameter");
  return eo;
}

}  // namespace

bool assembly_stage(RunContext& c, const AnalysisStep& step, json& js) {
  const System& sys = *c.system;
  js["type"] = "assembly";
  const std::vector<int> held = coordinate_indices(sys, step.hold, step, "hold");
  const AssemblyResult r = assemble_positions(sys, held, step.t0, c.q);
  js["iterations"] = r.iterations;
  js["max_constraint_violation"] = r.residual;
  js["coordinates"] = coordinates_json(sys, c.q.data());
  if (!r.converged) {
    fail(c, "assembly_failed", r.message, js);
    return false;
  }
  js["sensors"] = sensors_json(sys, initial_modes(sys, c.q.data(), step.t0), c.q.data(), step.t0);
  if (step.mode_check != "off" && !check_assembly_mode(c, step, held, js)) return false;
  js["status"] = "ok";
  if (c.options.verbose) {
    std::printf("assembly: converged in %d iterations, max constraint violation %.3g\n", r.iterations, r.residual);
    print_configuration(sys, c.q.data(), step.t0);
  }
  return true;
}

// The solved parameters go into a new System that later stages use.
bool equilibrium_stage(RunContext& c, const AnalysisStep& step, json& js) {
  js["type"] = "equilibrium";
  const EquilibriumOptions eo = equilibrium_options(*c.system, step);
  const EquilibriumResult r = solve_equilibrium(*c.system, c.q, eo);
  c.system = std::make_shared<const System>(with_force_parameters(*c.system, eo.parameters, r.parameter_values));
  const System& sys = *c.system;
  js["iterations"] = r.iterations;
  js["relative_force_residual"] = r.force_residual;
  js["constraint_residual"] = r.constraint_residual;
  json params = json::object();
  for (size_t p = 0; p < eo.parameters.size(); ++p) {
    const std::string key = sys.forces[eo.parameters[p].first].name + "." + eo.parameters[p].second;
    params[key] = r.parameter_values[p];
    if (eo.parameters[p].second == "free_length") {
      js["spring_free_length"] = r.parameter_values[p];
      c.result.summary["spring_free_length"] = r.parameter_values[p];
    }
  }
  js["parameters"] = params;
  json reactions = json::object();
  for (size_t h = 0; h < eo.hold.size(); ++h) reactions[step.hold[h]] = r.hold_reactions[h];
  js["hold_reactions"] = reactions;
  js["coordinates"] = coordinates_json(sys, c.q.data());
  if (!r.converged) {
    fail(c, "equilibrium_failed", r.message, js);
    return false;
  }
  js["sensors"] = sensors_json(sys, initial_modes(sys, c.q.data(), step.t0), c.q.data(), step.t0);
  js["status"] = "ok";
  c.result.summary["equilibrium_coordinates"] = js["coordinates"];
  if (c.options.verbose) {
    std::printf("equilibrium: converged in %d iterations\n", r.iterations);
    for (auto& [k, v] : params.items()) std::printf("  %s = %.12f\n", k.c_str(), v.get<double>());
    print_configuration(sys, c.q.data(), step.t0);
  }
  return true;
}

}  // namespace mbdae
