// A scene: a model plus the analyses to run on it, as read from YAML (see docs/scene-format.md).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cases/output/animation_spec.h"
#include "formulation/model.h"

namespace mbdae {

struct AnalysisStep {
  enum class Type { kAssembly, kEquilibrium, kKinematics, kDynamics };
  Type type = Type::kAssembly;
  std::vector<std::string> hold, release, unknowns;  // unknowns: "force.parameter"
  double t0 = 0, t_end = 1, output_step = 0.01;
  // atol: absolute tolerance of positions [m]; 0: rtol times the model's length scale. Euler
  // parameters get atol / length_scale, velocities atol / time_scale unless atol_rotation [1] or
  // atol_velocity [m/s] are given; the scales are derived from the model unless given
  // (formulation/tolerance_scales.h).
  double rtol = 1e-6, atol = 0, max_step = 0;
  // The step budget (core/ida_driver.h, IdaOptions::max_total_steps): the run fails with status
  // step_limit after this many steps, or as soon as its rate projects more over [t0, t_end].
  double max_steps = 1e8;
  double length_scale = 0, time_scale = 0, atol_rotation = 0, atol_velocity = 0;
  bool error_estimate = false;  // estimate the run's global error (cases/run/error_estimate.h)
  // > 0: pick rtol and atol so that the estimated global error of error_sensors (default every
  // output sensor, error_target then relative to each one's scale) is at most this (cases/run/error_target.h).
  double error_target = 0;
  std::vector<std::string> error_sensors;
  double constraint_scale = 0;  // 0: automatic
  double newton_convergence = 0.33;  // IDA's Newton convergence coefficient (epcon)
  // "reduced": Newton solves with the velocity corrections eliminated through q' - v (index3
  // only; core/reduced_linear_solver.h); "full": KLU on the whole Newton matrix.
  std::string newton_solve = "full";
  bool output_projection = false;    // project output samples onto the constraints
  std::string formulation = "index3";  // index3, index3-positions, index2-ggl, index1 or penalty
  // index1, penalty: stabilization [1/s]; negative: the formulation's default over the model's
  // fast time scale (Formulation::baumgarte_rate: index1 1, penalty 5).
  double baumgarte_alpha = -1, baumgarte_beta = -1;
  double penalty = 1e7;  // penalty: p = penalty * largest body mass [kg] (formulation/index1_dae.h)
  // Report the largest change of these sensors before this time ("nothing moves before").
  double quiet_until = -1;
  std::vector<std::string> quiet_sensors;
  // Assembly: what to do when a free rotational coordinate ends more than mode_check_deg from its
  // guess (formulation/assembly_mode.h): "warn" (summary and stderr), "fail" (exit 3) or "off".
  std::string mode_check = "warn";
  double mode_check_deg = 90;
  // Dynamics: rates of free joint coordinates at t0 (rad/s or m/s), in scene order; the other
  // velocities follow from the constraints (formulation/initial_velocities.h).
  std::vector<std::pair<std::string, double>> initial_velocities;
  SourceLocation where;
};

struct SceneSource;  // cases/scene/scene_source.h: the texts it was read from, and its overrides

// One parameter of a scene as `mbdae params` lists it (cases/scene_overrides.h): the path
// set_parameter takes, its value as YAML text, its SI unit ("" if none or not known) and the
// file and line where the value is written.
struct ParameterEntry {
  std::string path, value, unit, file;
  int line = 0;
};

struct Scene {
  std::string file;
  Model model;
  std::vector<AnalysisStep> steps;
  std::vector<std::string> columns;  // sensors written to results.csv (empty: all)
  // "remove", "fail", or "remove_world" (the world components chosen at t = 0, the choice before
  // issue 23, which degrades where a loop's plane turns: for comparison)
  std::string redundant_constraints = "remove";
  AnimationSpec animation;  // cases/output/animation_spec.h
  // What the scene was read from (null for a scene built in code), for set_parameter.
  std::shared_ptr<const SceneSource> source;
};

// One message per problem found in the scene (file:line: field 'x': ...).
struct SceneError : std::runtime_error {
  std::vector<std::string> messages;
  explicit SceneError(std::vector<std::string> m);
};

// Reads a scene file (and the model file it names). Throws SceneError listing every problem.
Scene load_scene(const std::string& path);
// Parses a scene from text (for tests); `path` is used in messages and to resolve includes.
Scene load_scene_text(const std::string& text, const std::string& path);
// The scene read again from its source with `overrides` (parameter path, YAML value) added to
// the ones it has (cases/mbdae.h set_parameter). Throws SceneError as load_scene does.
Scene reload_scene(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& overrides);
// Every parameter path of the scene with its value and unit (cases/scene_overrides.h), its
// overrides applied: the paths reload_scene / set_parameter take.
std::vector<ParameterEntry> scene_parameters(const Scene& scene);

}  // namespace mbdae
