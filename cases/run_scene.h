// Runs a scene's analyses in order (assembly, equilibrium, kinematics or dynamics), writing
// DIR/results.csv (t and one column per sensor) and DIR/summary.json (statistics, solved
// coordinates and parameters, status). A failing step stops the run with what it computed so far.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/mbdae.h"

namespace mbdae {

struct RunOutcome {
  int exit_code = 0;  // 0 ok, 3 solve failure
  nlohmann::ordered_json summary;
  std::vector<std::string> columns, units;
  std::vector<std::vector<double>> rows;
  std::vector<double> q;  // final positions
};

RunOutcome run_scene(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks = {});

}  // namespace mbdae
