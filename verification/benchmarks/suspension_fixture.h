// A five-point suspension system at its equilibrium with the wheel in contact (dynamics I's
// start), shared by the kernel benchmarks and the allocation test.
#pragma once

#include <string>
#include <vector>

#include "cases/scene/scene.h"
#include "formulation/analyses.h"
#include "formulation/system.h"

namespace mbdae::bench {

struct SuspensionFixture {
  System sys;
  std::vector<double> q;
};

inline SuspensionFixture suspension_at_equilibrium(const std::string& scene_file) {
  Scene scene = load_scene(scene_file);
  SuspensionFixture f{build_system(scene.model), {}};
  f.q = f.sys.q0;
  assemble_positions(f.sys, {f.sys.coordinate_index("q4")}, 0.0, f.q);
  EquilibriumOptions eo;
  eo.hold = {f.sys.coordinate_index("q4"), f.sys.coordinate_index("q15")};
  eo.release = {f.sys.coordinate_index("q4")};
  eo.parameters = {{f.sys.force_index("suspension"), "free_length"}};
  const EquilibriumResult r = solve_equilibrium(f.sys, f.q, eo);
  f.sys = with_force_parameters(f.sys, eo.parameters, r.parameter_values);
  return f;
}

}  // namespace mbdae::bench
