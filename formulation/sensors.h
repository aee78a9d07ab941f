// Output quantities evaluated from a consistent state (q, v, a): body points' position,
// velocity and acceleration, body-fixed axes, joint coordinates and rates, force element
// lengths and tensions, and expressions of earlier sensors.
//   point velocity      = r' + B(p, s) p'
//   point acceleration  = r'' + B(p, s) p'' + B(p', s) p'
#pragma once

#include <vector>

#include "formulation/forces.h"
#include "formulation/system.h"

namespace mbdae {

// Rotation coordinate sensors (unless `wrap`) are continuous: each value is shifted by the
// multiple of 2 pi that brings it nearest to `previous` (the sensors of the previous output
// sample, which may alias `out`), or without it nearest to the coordinate's initial value.
void evaluate_sensors(const System& sys, const std::vector<char>& modes, const double* q,
                      const double* v, const double* a, double t, double* out,
                      const double* previous = nullptr);

// Values of the expression components of load `f` (and, if asked, their gradients with respect
// to the bodies in f.reads): each sensor the expressions read is evaluated from (q, v) and
// differentiated (exactly for points, axes and coordinates, by central differences for force
// lengths and values), then combined by the chain rule with the expression's exact gradient.
LoadInput load_input(const System& sys, const Force& f, const std::vector<char>& modes,
                     const double* q, const double* v, double t, bool with_gradient);

}  // namespace mbdae
