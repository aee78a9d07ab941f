// The stages of run() (cases/mbdae.h), in the order data flows through them:
//   build_checked_system   scene.model -> System (built, redundant equations found and removed)
//   output_columns         the sensors written as Result columns, with their units
//   assembly_stage         positions satisfying the constraints, held coordinates kept
//   equilibrium_stage      a configuration at rest, and unknown force parameters
//   integration_stage      the DAE of the step's formulation integrated; samples to Result and sinks
// Each stage reads the current System and positions from the RunContext and, when it changes
// them, puts a new System there (a built System is never changed). A stage that fails records
// the failure (fail()) and returns false; the run then ends with what it computed.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/mbdae.h"
#include "formulation/system.h"

namespace mbdae {

struct RunSensitivities;

struct RunContext {
  const Scene& scene;
  const RunOptions& options;
  const std::vector<Sink*>& sinks;
  Result& result;
  std::shared_ptr<const System> system;  // replaced (never changed) by the stages
  std::shared_ptr<const System> all_equations;  // as built, before redundant equations were set aside
  std::vector<double> q;                 // current positions
  std::vector<int> column_sensors;       // sensor index of each Result column after "t"
  nlohmann::ordered_json steps = nlohmann::ordered_json::array();
  nlohmann::ordered_json warnings = nlohmann::ordered_json::array();
  // Whole turns of the rotation coordinates at the end of the last integration step, so that the
  // next one starts with the same count (formulation/system.h, CoordinateTurns).
  std::optional<CoordinateTurns> turns = std::nullopt;
  // The twins that carry the sensitivities through the stages (cases/run/sensitivities.h), or null.
  std::shared_ptr<RunSensitivities> sensitivities = nullptr;
};

std::shared_ptr<const System> build_checked_system(const Scene& scene, const RunOptions& options,
                                                   nlohmann::ordered_json& summary,
                                                   std::shared_ptr<const System>* all_equations = nullptr);
void output_columns(RunContext& c);
bool assembly_stage(RunContext& c, const AnalysisStep& step, nlohmann::ordered_json& js);
bool equilibrium_stage(RunContext& c, const AnalysisStep& step, nlohmann::ordered_json& js);
bool integration_stage(RunContext& c, const AnalysisStep& step, nlohmann::ordered_json& js);
// The formulation a step integrates with under `options` (sensitivities aside): the asked one, or
// index2-ggl for a dynamics step's index3 below rtol 1e-6 that does not run at the tolerances its
// scene fixes (formulation/formulation_registry.h, docs/formulation.md).
std::string step_formulation(const AnalysisStep& step, const RunOptions& options);

// Records a failed step: its status and message in the step and the summary, exit code 3.
void fail(RunContext& c, const std::string& status, const std::string& message, nlohmann::ordered_json step);
// An output (a sink) that failed after the run: status output_failed, exit code 4.
void output_failed(RunContext& c, const std::string& message);
// The summary's closing entries (warnings, steps), once the run ends.
void close_summary(RunContext& c);
// Joint coordinates and (non-acceleration) sensors at q, for the summary.
nlohmann::ordered_json coordinates_json(const System& sys, const double* q);
nlohmann::ordered_json sensors_json(const System& sys, const std::vector<char>& modes, const double* q, double t);

}  // namespace mbdae
