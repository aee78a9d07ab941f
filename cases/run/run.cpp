// run() (cases/mbdae.h): the scene's analyses in order, over the stages of cases/run/run_stages.h.
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cases/scene/analysis_types.h"
#include "cases/run/run_stages.h"
#include "cases/run/sensitivities.h"
#include "core/errors.h"
#include "core/output.h"
#include "formulation/augmented_solver.h"
#include "formulation/force_types.h"
#include "formulation/formulation_registry.h"
#include "formulation/redundancy.h"
#include "formulation/sensors.h"

namespace mbdae {
namespace {

using json = nlohmann::ordered_json;

void describe_system(const System& sys, json& summary) {
  summary["bodies"] = sys.num_bodies();
  summary["coordinates"] = sys.nq();
  summary["constraint_equations"] = sys.num_constraint_rows();
  json merged = json::object();
  for (const auto& b : sys.bodies)
    if (!b.merged.empty()) merged[b.name] = b.merged;
  json ground = json::array();
  for (const auto& [name, f] : sys.frames)
    if (f.body < 0 && name != kGround) ground.push_back(name);
  summary["merged_into_body"] = merged;
  summary["merged_into_ground"] = ground;
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
    case T::kForceValue:  // the force type's row: angles and moments on rotations
      return force_sensor_unit(sys.forces[s.target], s.type == T::kForceLength);
    case T::kKineticEnergy:
    case T::kPotentialEnergy: return "J";
    case T::kAngularVelocity: return "rad/s";
    case T::kAngularMomentum: return "N m s";
    case T::kExpression: return "";
  }
  return "";
}

}  // namespace

// Redundant constraint equations, found at a configuration that satisfies the constraints
// (a regularized projection of the guess), then removed (a new System) or reported as an error.
// The choice is one that stays valid as the mechanism moves (choose_independent_equations: a
// cut's point rows in a frame of its body); summary.json says what was set aside and when.
std::shared_ptr<const System> build_checked_system(const Scene& scene, const RunOptions& opt, json& summary,
                                                   std::shared_ptr<const System>* all_equations) {
  auto sys = std::make_shared<const System>(build_system(scene.model));
  if (all_equations) *all_equations = sys;
  describe_system(*sys, summary);
  std::vector<double> qc = sys->q0;
  AugmentedSolver projector(*sys);
  projector.positions(qc.data(), 0.0, 1e-12, 100, 1e-10);
  const bool remove = scene.redundant_constraints != "fail";
  EquationChoice choice;
  if (scene.redundant_constraints == "remove_world") {
    choice.report = find_redundant_constraints(*sys, qc.data(), 0.0);
    choice.system = without_redundant_constraints(*sys, choice.report);
  } else {
    choice = choose_independent_equations(*sys, qc.data(), 0.0);
  }
  const RedundancyReport& rr = choice.report;
  summary["redundant_constraints"] = {{"policy", scene.redundant_constraints},
                                      {"equations", rr.equations},
                                      {"rank", rr.rank},
                                      {"redundant", rr.redundant},
                                      {"set_aside", {{{"t", 0.0}, {"equations", rr.redundant}}}},
                                      {"in_body_frame", choice.reexpressed}};
  if (!rr.redundant.empty()) {
    std::string list;
    for (const auto& r : rr.redundant) list += "\n  " + r;
    if (!remove)
      throw ModelError(scene.file, 0, "redundant_constraints",
                       std::to_string(rr.redundant.size()) + " redundant constraint equations:" + list);
    if (opt.verbose)
      std::fprintf(stderr, "mbdae: removed %zu redundant constraint equations:%s\n", rr.redundant.size(),
                   list.c_str());
    sys = std::make_shared<const System>(std::move(choice.system));
  }
  summary["constraint_equations"] = sys->num_constraint_rows();
  return sys;
}

// The sensors written as columns: all, or the scene's `output` list.
std::vector<int> column_sensors(const Scene& scene, const System& sys) {
  std::vector<int> out;
  if (scene.columns.empty()) {
    for (size_t k = 0; k < sys.sensors.size(); ++k) out.push_back(static_cast<int>(k));
    return out;
  }
  for (const auto& name : scene.columns) {
    int idx = -1;
    for (size_t k = 0; k < sys.sensors.size(); ++k)
      if (sys.sensors[k].name == name) idx = static_cast<int>(k);
    if (idx < 0) throw ModelError(scene.file, 0, "output", "no sensor named '" + name + "'");
    out.push_back(idx);
  }
  return out;
}

void output_columns(RunContext& c) {
  const System& sys = *c.system;
  c.column_sensors = column_sensors(c.scene, sys);
  c.result.columns = {"t"};
  c.result.units = {"s"};
  for (int k : c.column_sensors) {
    c.result.columns.push_back(sys.sensors[k].name);
    c.result.units.push_back(sensor_unit(sys, sys.sensors[k]));
  }
  c.result.data.assign(c.result.columns.size(), {});
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

void close_summary(RunContext& c) {
  close_sensitivities(c);
  if (!c.warnings.empty()) c.result.summary["warnings"] = c.warnings;
  c.result.summary["steps"] = c.steps;
}

namespace {

// The run's status and message in the summary and the result, exit code 3.
void end_failed(RunContext& c, const std::string& status, const std::string& message) {
  c.result.summary["status"] = status;
  c.result.summary["message"] = message;
  close_summary(c);
  c.result.status = status;
  c.result.message = message;
  c.result.exit_code = 3;
  c.result.q = c.q;
  c.result.system = c.system;
}

}  // namespace

void fail(RunContext& c, const std::string& status, const std::string& message, json step) {
  step["status"] = status;
  step["message"] = message;
  c.steps.push_back(step);
  end_failed(c, status, message);
  if (c.options.report_failures)  // also under --quiet: a failure is always said
    std::fprintf(stderr, "mbdae: %s\n", message.c_str());
}

void output_failed(RunContext& c, const std::string& message) {
  std::fprintf(stderr, "mbdae: %s\n", message.c_str());
  c.result.summary["status"] = c.result.status = "output_failed";
  c.result.summary["message"] = c.result.message = message;
  c.result.exit_code = 4;
}

std::vector<std::pair<std::string, std::string>> output_columns(const Scene& scene) {
  const System sys = build_system(scene.model);
  std::vector<std::pair<std::string, std::string>> out = {{"t", "s"}};
  for (int k : column_sensors(scene, sys)) out.emplace_back(sys.sensors[k].name, sensor_unit(sys, sys.sensors[k]));
  return out;
}

std::vector<std::string> formulations() {
  std::vector<std::string> names;
  for (const Formulation& f : formulation_registry()) names.push_back(f.name);
  return names;
}

int Result::column_index(const std::string& name) const {
  for (size_t k = 0; k < columns.size(); ++k)
    if (columns[k] == name) return static_cast<int>(k);
  return -1;
}

const std::vector<double>& Result::column(const std::string& name) const {
  const int k = column_index(name);
  if (k < 0) throw std::out_of_range("no column named '" + name + "'");
  return data[k];
}

std::vector<double> Result::row(size_t i) const {
  std::vector<double> r(data.size());
  for (size_t c = 0; c < data.size(); ++c) r[c] = data[c][i];
  return r;
}

std::vector<std::vector<double>> Result::row_major() const {
  std::vector<std::vector<double>> out(rows());
  for (size_t i = 0; i < out.size(); ++i) out[i] = row(i);
  return out;
}

namespace {

bool run_step(RunContext& c, int k) {
  const AnalysisStep& step = c.scene.steps[k];
  json js;
  const bool ok = analysis_type(step.type).stage(c, step, js);
  if (ok && !integrates(step)) follow_static_stage(c, k, js);  // integration stages carry their own
  if (ok) c.steps.push_back(js);
  return ok;
}

}  // namespace

void check_runnable(const Scene& scene, const RunOptions& options) {
  json summary;
  RunOptions quiet = options;  // run() reports what it removes
  quiet.verbose = false;
  build_checked_system(scene, quiet, summary);
}

Result run(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks) {
  Result result;
  json& summary = result.summary;
  summary["scene"] = scene.file;
  summary["model"] = scene.model.name;
  summary["status"] = "running";
  std::shared_ptr<const System> all_equations;
  RunContext c{scene, options, sinks, result, build_checked_system(scene, options, summary, &all_equations),
               all_equations, {}, {}};
  c.q = c.system->q0;
  output_columns(c);
  c.sensitivities = open_sensitivities(c);
  const int last = options.analysis >= 0 ? options.analysis : static_cast<int>(scene.steps.size()) - 1;
  for (int k = 0; k <= last && k < static_cast<int>(scene.steps.size()); ++k)
    if (!run_step(c, k)) break;
  // Sensitivities that stopped while the run went on leave sensitivities.csv short of
  // results.csv: not a whole run (status sensitivities_failed, exit code 3).
  // (Their failure was said on stderr when it happened: sensitivities_failed.)
  if (result.exit_code == 0 && c.sensitivities && c.sensitivities->status != "ok")
    end_failed(c, "sensitivities_failed",
               "the sensitivities stopped (" + c.sensitivities->status + "): " + c.sensitivities->message +
                   "; results.csv is whole, sensitivities.csv ends there");
  if (result.exit_code == 0) {
    summary["status"] = "ok";
    close_summary(c);
    result.status = "ok";
    result.q = c.q;
  }
  result.system = c.system;
  for (Sink* s : sinks) {
    try {
      s->end(result);
    } catch (const OutputError& e) {  // results.csv could not be completed: say so in the summary
      if (s == sinks.back()) throw;
      if (result.exit_code == 0) output_failed(c, e.what());  // else the first failure stands
    }
  }
  return result;
}

}  // namespace mbdae
