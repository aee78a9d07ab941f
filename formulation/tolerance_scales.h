// The model's length and time scales and the tolerances and stabilization they give by default
// (issue 13: the same rtol gives about the same digits on a 1 m suspension and a 3 cm mechanism).
//
//   length L: the extent of the model in its initial configuration, the largest side of the
//     box around every body's centre of mass and every point a joint, cut, force or sensor uses;
//   time T (velocity scale L/T): sqrt(L/|g|) with gravity, else the span of the run (never more
//     than the span);
//   fast time T_f (stabilization): the smallest of T and sqrt(m/k) over the elastic elements
//     (spring-dampers, wheel contacts; m the smaller non-zero mass of the element's bodies).
//
// Absolute tolerances: positions a_q = rtol L (or the scene's atol), Euler parameters a_q / L,
// velocities a_q / T, Euler-parameter rates a_q / (L T). Baumgarte alpha = beta = 5 / T_f
// (docs/formulation.md, "Error control").
#pragma once

#include "formulation/multibody_dae.h"
#include "formulation/system.h"

namespace mbdae {

struct ModelScales {
  double length = 1.0;     // [m]
  double time = 1.0;       // [s]
  double fast_time = 1.0;  // [s]
  double span = 1.0;       // [s] the run's span t1 - t0 (error per unit of span)
};

// From the configuration q (7 per body) and the span [t0, t1] of the run.
ModelScales model_scales(const System& sys, const double* q, double t0, double t1);

// Default absolute tolerance of positions [m]: rtol times the length scale times
// kPositionAtolFactor (docs/formulation.md, "Error control", for the measurements behind it).
constexpr double kPositionAtolFactor = 1.0;
double default_position_atol(const ModelScales& s, double rtol);

// Absolute tolerances in model units from the position tolerance a_q [m] and the scales.
AbsoluteTolerances absolute_tolerances(const ModelScales& s, double position_atol);

// Default Baumgarte rate alpha = beta [1/s]: `per_fast_time` over the model's fast time scale
// (the formulation's own factor: Formulation::baumgarte_rate; index1 1, penalty 5).
double default_baumgarte_rate(const ModelScales& s, double per_fast_time);

}  // namespace mbdae
