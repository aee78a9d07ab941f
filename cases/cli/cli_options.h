// The command line of mbdae (cases/cli/main.cpp):
//   mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--output-step DT] [--quiet] [--error-estimate]
//                         [--error-target E] [--error-sensors a,b]
//                         [--formulation index3|index2-ggl|index1|penalty]
//                         [--animation] [--animation-rate HZ]
//   mbdae check SCENE.yaml
//   mbdae params SCENE.yaml     (every parameter path with its value and unit)
//   mbdae --version
// Overrides are checked with the scene fields' own range checks (cases/scene/field_ranges.h): the
// tolerances as soon as they are read, the output step against each integration step's time
// span once the scene is loaded.
#pragma once

#include <string>
#include <vector>

#include "cases/run/error_target.h"
#include "cases/mbdae.h"

namespace mbdae {

struct CommandLine {
  bool check_only = false;
  bool list_params = false;  // mbdae params: the scene's parameter paths (mbdae::parameters)
  bool version = false;      // mbdae --version
  std::string scene_path;
  std::string out_dir;  // --out: results.csv and summary.json go there
  RunOptions options;
  bool show_usage = false;  // after an error: the usage text helps
  ErrorControl error;  // --error-estimate, --error-target, --error-sensors (cases/run/error_target.h)
  bool animation = false;     // --animation: DIR/animation.pvd (cases/output/animation_sink.h)
  double animation_rate = 0;  // --animation-rate HZ (implies --animation)
  bool normalized_sensitivities = false;  // --normalized-sensitivities: also sensitivities_normalized.csv
};

// Reads the arguments after the program name; returns "" or the usage error (exit code 1).
std::string parse_command_line(const std::vector<std::string>& args, CommandLine& cl);
// The command-line overrides checked against the scene's integration steps and sensors; empty if fine.
std::vector<std::string> check_overrides(const Scene& scene, const RunOptions& options);
// The same with the command line's error sensors (--error-sensors) checked against the scene.
std::vector<std::string> check_overrides(const Scene& scene, const CommandLine& cl);
void print_usage();

}  // namespace mbdae
