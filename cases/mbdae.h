// mbdae's public C++ API: load a scene, override its parameters by path, run its analyses and
// get the results in memory. Writers (CSV, summary JSON, animation, ...) are sinks that see the
// output samples as they come and the Result at the end. The command-line program
// (cases/cli/main.cpp) and the Python package (cases/python/) are thin users of this header.
//
//   mbdae::Scene scene = mbdae::load_scene("cases/five_point_suspension/dynamics_step.yaml");
//   mbdae::set_parameter(scene, "forces.tyre.stiffness", "3.0e5");
//   mbdae::RunOptions opt;
//   opt.rtol = 1e-8;
//   mbdae::Result r = mbdae::run(scene, opt);
//   if (r.ok()) use(r.column("wheel_z"));
//
// No global mutable state: scenes can be loaded and run in several threads at once.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/scene/scene.h"  // Scene, AnalysisStep, SceneError, load_scene, load_scene_text

namespace mbdae {

struct System;  // formulation/system.h: the mechanism in absolute coordinates

// ---- Scenes ---------------------------------------------------------------------------------
// load_scene(path) and load_scene_text(text, path) are declared in cases/scene/scene.h.

// Overrides one scene parameter by its path and reloads the scene with the scene file's own
// validation (a bad value throws SceneError naming the file, the line of the overridden item
// and the path). Paths name items by their name in lists and by key in mappings:
//   forces.suspension.stiffness, coordinates.q4.initial, bodies.wheel.mass, gravity,
//   analysis.dynamics.rtol (the step of that type), analysis.2.t_end (the step by index).
// `yaml_value` is YAML text: "2.0e5", "[0, 0, -9.81]", "{type: step, time: 0.2}".
void set_parameter(Scene& scene, const std::string& path, const std::string& yaml_value);
// A copy of `scene` with every (path, value) override applied in order.
Scene with_parameters(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& overrides);
// Every parameter path of `scene` (and its model file) with its value and SI unit, from the
// resolver set_parameter uses (what `mbdae params SCENE` prints). List elements are paths too:
// bodies.chassis.points.bp1.2 is the z of point bp1.
std::vector<ParameterEntry> parameters(const Scene& scene);
// The columns a run of `scene` writes ("t", then the output sensors) with their SI units,
// without running it (the model is built; ModelError as in run()).
std::vector<std::pair<std::string, std::string>> output_columns(const Scene& scene);

// ---- Running --------------------------------------------------------------------------------
struct RunOptions {
  double rtol = 0, atol = 0;  // > 0: override the scene's tolerances
  double output_step = 0;     // > 0: overrides the integration steps' output_step (sample spacing)
  std::string formulation;    // non-empty: overrides the steps' formulation (see formulations())
  int analysis = -1;          // >= 0: run the steps up to and including this one only
  bool verbose = false;       // print assembly / equilibrium results on stdout
  bool progress = false;      // progress line on stderr for runs over a second
  bool report_failures = true;  // a failure's message on stderr (off for the error estimate's own runs)
  // Set from another thread (or a signal handler) to stop at the next step; the run then ends
  // with status "interrupted" and keeps what it computed.
  const std::atomic<bool>* stop = nullptr;
  // Parameter paths (as set_parameter takes them) to differentiate every output sensor by:
  // forward sensitivities integrated with the run (IDAS), Result::sensitivities
  // (docs/sensitivities.md). A path that names no number of the model is refused before the run.
  std::vector<std::string> sensitivities;
};

// The names of the registered formulations (index3, index2-ggl, index1, penalty, ...).
std::vector<std::string> formulations();

// Everything a run produced, held in memory. On a failure, everything computed up to it.
struct Result {
  std::string status = "running";  // "ok", or the failure ("integration_failed", "interrupted", ...)
  std::string message;             // empty when ok
  int exit_code = 0;               // the CLI's: 0 ok, 3 solve failure (docs/errors.md)
  std::vector<std::string> columns;  // "t", then the output sensors
  std::vector<std::string> units;    // SI unit of each column ("s", "m", "rad", "N", "1", ...)
  // The samples, one vector per column (column-major: each column contiguous; reserved for the
  // expected sample count when the integration starts).
  std::vector<std::vector<double>> data;
  nlohmann::ordered_json summary;  // the content of summary.json (statistics, coordinates, status)
  std::vector<double> q;           // final positions (7 per body)
  // The model as the run left it (an equilibrium that solves force parameters replaces the
  // System with one holding their values; a built System is never changed), for what draws or
  // evaluates the final configuration (the animation of a static run).
  std::shared_ptr<const System> system;
  // With RunOptions::sensitivities: "t", then "d(SENSOR)/d(PATH)" for each output sensor and
  // each parameter (sensor by sensor, the parameters in the order asked), with their units, at
  // the samples of `data` (column-major). Fewer rows than `data` where they failed
  // (summary.json "sensitivities": status and message).
  std::vector<std::string> sensitivity_columns, sensitivity_units;
  std::vector<std::vector<double>> sensitivities;

  bool ok() const { return status == "ok"; }
  size_t rows() const { return data.empty() ? 0 : data[0].size(); }
  int column_index(const std::string& name) const;  // -1 if none
  const std::vector<double>& column(const std::string& name) const;  // throws std::out_of_range
  std::vector<double> row(size_t i) const;                 // sample i, one value per column (a copy)
  std::vector<std::vector<double>> row_major() const;      // every sample as a row (a copy)
};

// The sensitivities relative to the parameters' values and the sensors' scales,
// (p / max|y|) dy/dp, max|y| each sensor's largest magnitude over the run (a pointwise (p / y)
// dy/dp is unbounded where y crosses zero): "t", then "d(SENSOR)/d(PATH)*p/max|SENSOR|" for each
// column of Result::sensitivities whose sensor is not zero throughout (column-major); a run
// without samples (static steps only) keeps every column, with no rows. Empty without
// sensitivities.
struct NormalizedSensitivities {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> data;
};
NormalizedSensitivities normalized_sensitivities(const Result& result);

// What a sink is told before the first sample of an integration step.
struct RunInfo {
  const Scene* scene = nullptr;
  const System* system = nullptr;
  const AnalysisStep* step = nullptr;
  const std::vector<std::string>* columns = nullptr;
  const std::vector<std::string>* units = nullptr;
  const Result* result = nullptr;  // the run's result as it grows (sensitivity rows: SensitivityCsvSink)
};

// One output sample: the row of column values and the consistent state it came from, for sinks
// that draw the mechanism (q: 7 per body, v and a: 7 per body, a may be null).
struct Sample {
  double t = 0;
  const double* row = nullptr;  // columns->size() values, row[0] = t
  const double* q = nullptr;
  const double* v = nullptr;
  const double* a = nullptr;
  const std::vector<char>* modes = nullptr;  // per force: wheel in contact
  double input_time = 0;  // time at which inputs (ground, drives) were evaluated
};

// An output writer (cases/output/sinks.h: CsvSink, SummarySink). begin() and sample() may throw (std::runtime_error with the file named):
// the run then stops with status "output_failed" and end() is still called.
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void begin(const RunInfo& info) {}
  virtual void sample(const Sample& s) {}
  virtual void end(const Result& result) {}
};

// The checks run() makes before solving, without solving or writing anything: the system is
// built (load expressions compiled, ModelError on failure) and its redundant constraints found
// (ModelError with `redundant_constraints: fail`). Callers run it before they claim an output
// folder, so that a rejected scene leaves the folder as it was.
void check_runnable(const Scene& scene, const RunOptions& options);
// The range checks of the command line's overrides (cases/cli_options.cpp) on RunOptions, for
// callers that set them otherwise (the Python API): "rtol: out of range [1e-14, 0.5], got 1e-300",
// one message per bad option, each starting with the option's name.
std::vector<std::string> run_option_errors(const Scene& scene, const RunOptions& options);

// Runs the scene's analyses in order (assembly, equilibrium, kinematics, dynamics). Scene and
// model errors found while building the system throw ModelError (core/errors.h); a failing
// solve does not throw: the Result says so and keeps what was computed.
Result run(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks = {});

}  // namespace mbdae
