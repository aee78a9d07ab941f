// Output quantities evaluated from a consistent state (q, v, a): body points' position,
// velocity and acceleration, body-fixed axes, joint coordinates and rates, force element
// lengths and tensions, energies, angular velocity and angular momentum, and expressions of
// earlier sensors.
//   point velocity      = r' + B(p, s) p'
//   point acceleration  = r'' + B(p, s) p'' + B(p', s) p'
#pragma once

#include <string>
#include <vector>

#include "formulation/forces.h"
#include "formulation/system.h"

namespace mbdae {

// Rotation coordinate sensors (unless `wrap`) are continuous: each value is shifted by the
// multiple of 2 pi that brings it nearest to `previous` (the sensors of the previous output
// sample, which may alias `out`), or without it nearest to the coordinate's initial value.
// With `turns` (the run's CoordinateTurns), rotation coordinates count whole turns from it
// instead, like the loads that read them, and `previous` is not used.
void evaluate_sensors(const System& sys, const std::vector<char>& modes, const double* q,
                      const double* v, const double* a, double t, double* out,
                      const double* previous = nullptr, const CoordinateTurns* turns = nullptr);

// Values of the expression components of load `f` (and, if asked, their gradients with respect
// to the bodies in f.reads): each sensor the expressions read is evaluated from (q, v) and
// differentiated (exactly for points, axes and coordinates, by central differences for force
// lengths and values), then combined by the chain rule with the expression's exact gradient.
// Also the whole turns of a joint spring-damper (LoadInput::turns), from `turns` (null: nearest
// to the coordinate's initial value; system.h, CoordinateTurns).
LoadInput load_input(const System& sys, const Force& f, const std::vector<char>& modes,
                     const double* q, const double* v, double t, bool with_gradient,
                     const CoordinateTurns* turns = nullptr);
// The scene field of expression component c of load f: "torque", "fx", "fy" or "fz".
std::string load_field(const Force& f, int c);
// 2 pi times the whole turns of the coordinate of a load on a joint coordinate (ForceAttach::
// kCoordinate: joint spring-damper, ...); 0 for other loads and with `wrap`.
double joint_turns(const System& sys, const Force& f, const double* q, double t, const CoordinateTurns* turns);

}  // namespace mbdae
