// Which terms of the residual a scene parameter reaches, from the model it builds at p + d and
// p - d against the run's: the sensitivities' F_p then differences only those terms
// (formulation/twin_sensitivities.h) instead of two whole residuals of the twins.
#pragma once

#include <vector>

#include "formulation/system.h"

namespace mbdae {

struct ParameterReach {
  // True when the twins differ from the run's model only in the listed bodies' mass and inertia
  // (all bodies when gravity differs), the listed forces and the listed constraints' numbers:
  // F_p is then their terms alone. False: the model's structure differs, and F_p takes the
  // twins' whole residuals.
  bool local = false;
  std::vector<int> bodies, forces;
  // Constraints whose numbers differ (their points, axes, distances, drives), the structure
  // (type, bodies, rows) the same: their own terms, where the formulation gives them
  // (MultibodyDae::constraint_terms), else F_p takes the whole residuals.
  std::vector<int> constraints;
};

// Forces whose law reads more than their own numbers (expressions, user laws, sensors, a joint
// coordinate's frames) are listed whenever the reach is local: they are evaluated in both twins
// rather than compared.
ParameterReach parameter_reach(const System& run, const System& plus, const System& minus);

}  // namespace mbdae
