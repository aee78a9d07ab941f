// Output quantities evaluated from a consistent state (q, v, a): body points' position,
// velocity and acceleration, body-fixed axes, joint coordinates and rates, force element
// lengths and tensions, and expressions of earlier sensors.
//   point velocity      = r' + B(p, s) p'
//   point acceleration  = r'' + B(p, s) p'' + B(p', s) p'
#pragma once

#include <vector>

#include "formulation/system.h"

namespace mbdae {

void evaluate_sensors(const System& sys, const std::vector<char>& modes, const double* q,
                      const double* v, const double* a, double t, double* out);

}  // namespace mbdae
