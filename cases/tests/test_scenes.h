// Scenes more than one test file uses, as YAML text.
#pragma once

#include <string>

namespace mbdae::test_scenes {

// A slider (mass 2) on a prismatic joint along z, pushed by fz = -K z - C vz given as an
// expression of a position and a velocity sensor: a damped oscillator, K = 50, C = 2
// (omega = 5, zeta = 0.1), z0 = 0.2 from rest, over 4 s at rtol 1e-10. `dynamics_fields` adds
// fields to its dynamics step ("formulation: index1", ...).
inline std::string damped_slider(const std::string& dynamics_fields) {
  return R"(name: slider
gravity: [0, 0, 0]
bodies:
  - {name: slider, mass: 2.0, inertia: {xx: 0.1, yy: 0.1, zz: 0.1}}
joints:
  - {name: rail, parent: ground, child: slider, anchor: [0, 0, 0], chain: [T3], coordinates: [s]}
coordinates:
  s: {initial: 0.2}
forces:
  - {name: push, type: point_force, body: slider, point: com, fz: "-K * z - C * vz", parameters: {K: 50, C: 2}}
sensors:
  - {name: z, type: position, body: slider, point: [0, 0, 0], component: z}
  - {name: vz, type: velocity, body: slider, component: z}
analysis:
  - {type: assembly, hold: [s]}
  - {type: dynamics, t_end: 4, output_step: 0.05, rtol: 1.0e-10, )" +
         dynamics_fields + "}\n";
}

}  // namespace mbdae::test_scenes
