// Sensitivities of a run's outputs to scene parameters (RunOptions::sensitivities;
// docs/sensitivities.md). Each parameter p gets two twin runs, the scene with p + d and with
// p - d, which follow the run through its stages (cases/run/run_stages.h):
//   - a static stage (assembly, equilibrium) is solved again by each twin; the step's
//     sensitivities are central differences of the twins' converged solutions;
//   - an integration stage integrates the sensitivities with the run (IDAS forward
//     sensitivities, formulation/twin_sensitivities.h), the twins' DAEs supplying every
//     derivative and the initial sensitivities (from the twins' own chain of stages); at its
//     end each twin's positions are the run's moved by +-d times their sensitivities.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/mbdae.h"
#include "core/ida_driver.h"  // IdaStats

namespace mbdae {

struct RunContext;
class TwinSensitivities;
class KinematicSensitivities;
struct CoordinateTurns;

struct TwinRun {
  Scene scene;
  RunOptions options;
  std::vector<Sink*> sinks;
  Result result;
  std::unique_ptr<RunContext> context;
};

struct SensitivityParameter {
  std::string path, unit;
  double value = 0;
  double scale = 1;  // |value|, not below the model's own size in its unit (parameter_scale)
  double delta = 0;  // the twins' step, kRelativeStep * scale
  std::unique_ptr<TwinRun> twin[2];  // p + d, p - d
  nlohmann::json moved_breakpoints;  // the breakpoints it moves inside an integrated step: t, dt/dp
};

struct RunSensitivities {
  std::vector<SensitivityParameter> parameters;
  bool active = true;  // false once they failed (the run itself goes on)
  std::string status = "ok", message;
  std::vector<double> event_times;  // events met by an integration with sensitivities
  std::vector<std::vector<double>> last_positions;  // per parameter, dq/dp at the last sample
  std::vector<std::vector<double>> sensor_work;     // a sample's d(sensor)/dp per parameter
  std::vector<std::vector<double>> position_work;   // a kinematic sample's dq/dp per parameter
  std::vector<const double*> position_pointers;     // their data, as record_sensitivity_row takes them
  std::vector<double> row_work;
};

// The twins' relative step: central differences are exact to about d^2 and lose to rounding
// about eps / d times the residual's cancellation (applied against constraint forces, the state
// moved by only d times its sensitivity); measured, 3e-5 balances the two (docs/sensitivities.md).
constexpr double kRelativeStep = 3e-5;

// Whether a formulation's sensitivities can be integrated: not index3's (index3-positions'):
// kIndex3SensitivityNote says why.
bool sensitivity_formulation(const std::string& formulation);
extern const char* const kIndex3SensitivityNote;

// Problems with the requested paths, each message starting with `option`: an unknown path (with
// a "did you mean"), a path that names no single number, an analysis setting (rtol, t_end, ...:
// not a parameter of the model), a path asked twice; and `formulation`, the one asked by name
// (empty: the scene's), if its sensitivities cannot be integrated.
std::vector<std::string> check_sensitivity_paths(const Scene& scene, const std::vector<std::string>& paths,
                                                 const std::string& formulation, const std::string& option);

// The parameters of c.options.sensitivities and their twins, built as the run's System was.
// Throws ModelError when a twin's model has other coordinates or equations (a parameter that
// changes the model's structure cannot be differentiated).
std::shared_ptr<RunSensitivities> open_sensitivities(RunContext& c);
// After static stage `step` of the run succeeded: the same stage for every twin, and the
// sensitivities of its sensors at the solution into js["sensitivities"].
void follow_static_stage(RunContext& c, int step, nlohmann::ordered_json& js);
// The twins' contexts for integration stage `step` (null when the sensitivities are off).
RunContext* twin_context(RunContext& c, size_t parameter, int side);
// One sample's row of sensitivities into c.result.sensitivities, if the run wrote that sample:
// from the integrated sensitivities s, s' (IDAS), or at a kinematic sample's consistent (q, v)
// by the implicit function theorem.
void record_sensitivity_sample(RunContext& c, TwinSensitivities& ts, double t, const double* y, const double* yp,
                               const double* const* s, const double* const* sp, bool project);
void record_kinematic_sample(RunContext& c, KinematicSensitivities& ks, const std::vector<char>& modes,
                             const CoordinateTurns* turns, double t, const double* q, const double* v);
// The row of rs.sensor_work at t, and the positions' sensitivities s[i] (nq each) kept for the
// twins (follow_integration_stage).
void record_sensitivity_row(RunContext& c, double t, const double* const* s);
// Whether the run's last row is the sample at t, with no sensitivity row yet.
bool wrote_row(const RunContext& c, double t);
// The sensitivity equations' work in the step's statistics; the events met.
void sensitivity_statistics(RunContext& c, const IdaStats& st, nlohmann::ordered_json& stats);
// After an integration stage: the twins' positions from the run's and the last sensitivities.
void follow_integration_stage(RunContext& c);
// The sensitivities stop (the run goes on): status and message for summary.json.
void sensitivities_failed(RunContext& c, const std::string& status, const std::string& message);
// summary.json "sensitivities": method, parameters, columns, status.
void close_sensitivities(RunContext& c);

}  // namespace mbdae
