// Runs a scene's analyses in order (assembly, equilibrium, kinematics or dynamics), writing
// DIR/results.csv (t and one column per sensor) and DIR/summary.json (statistics, solved
// coordinates and parameters, status). A failing step stops the run with what it computed so far.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/scene.h"

namespace mbdae {

struct RunOptions {
  std::string out_dir;        // empty: write nothing
  double rtol = 0, atol = 0;  // > 0: override the scene's tolerances
  double output_step = 0;     // > 0: overrides the dynamics steps' output_step (sample spacing)
  bool progress = true;       // progress line on stderr for runs over a second
  bool keep_rows = false;     // keep results in memory (tests)
  bool verbose = true;        // print assembly / equilibrium results on stdout
  std::string formulation;    // non-empty: overrides the steps' formulation (index3, index2-ggl, index1, penalty)
};

struct RunOutcome {
  int exit_code = 0;  // 0 ok, 3 solve failure
  nlohmann::ordered_json summary;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::vector<double> q;  // final positions
};

RunOutcome run_scene(const Scene& scene, const RunOptions& options);

}  // namespace mbdae
