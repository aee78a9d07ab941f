// Errors of a run of the fast mechanism (slider_crank_fast.yaml) against its Lagrange reference:
// per sensor, the largest |x - x_ref| over the output samples, and the same relative to the
// quantity's scale (its largest |x_ref|), grouped into positions and velocities.
#pragma once

#include <string>
#include <vector>

#include "cases/mbdae.h"

namespace mbdae {

struct FastMechanismErrors {
  std::vector<std::string> sensors;
  std::vector<double> error, scale;  // per sensor
  double position = 0, velocity = 0;  // largest relative error of the position / velocity sensors
  double final_rate = 0;              // reference crank rate at the end [rad/s]
};

// The scene verification/fast_mechanism/slider_crank_fast.yaml.
Scene load_fast_mechanism();
// Compares r (a run of the scene) with the reference at the same sample times.
FastMechanismErrors fast_mechanism_errors(const Result& r, double reference_tol = 1e-13);

}  // namespace mbdae
