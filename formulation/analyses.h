// Static analyses on the absolute-coordinate system.
//
// Assembly: positions q with Phi(q, t) = 0 from the joint-coordinate guess, with chosen joint
// coordinates held at their initial values (Gauss-Newton, minimum-norm steps, line search).
//
// Equilibrium: a configuration at rest where the constraint forces balance the applied ones,
//   Phi_q^T lambda - Q(q, 0, t; params) = 0,   Phi(q, t) = 0,   lambda_released = 0,
// solved by Newton on the sparse square system in (q, lambda, params). Held coordinates are
// kept by constraints; a "released" held coordinate must carry no reaction, which is the extra
// equation that determines one unknown parameter (for example a spring's free length).
#pragma once

#include <string>
#include <vector>

#include "formulation/system.h"

namespace mbdae {

struct AssemblyResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0;
  std::string message;
};

// Adds hold constraints for `held` coordinates (at their value in q0's guess) and solves.
AssemblyResult assemble_positions(const System& sys, const std::vector<int>& held, double t,
                                  std::vector<double>& q);

struct EquilibriumOptions {
  std::vector<int> hold;     // coordinates kept at their current value
  std::vector<int> release;  // subset of hold: reaction must vanish (one per parameter)
  std::vector<std::pair<int, std::string>> parameters;  // (force index, parameter name) unknowns
  double t = 0;
  int max_iterations = 50;
};

struct EquilibriumResult {
  bool converged = false;
  int iterations = 0;
  double force_residual = 0, constraint_residual = 0;
  std::vector<double> parameter_values;
  std::vector<double> hold_reactions;  // multipliers of the hold constraints
  std::string message;
};

// Solves for q (updated in place) and the unknown parameters (returned in parameter_values;
// `sys` is not changed: with_force_parameters() builds the system that has them).
EquilibriumResult solve_equilibrium(const System& sys, std::vector<double>& q,
                                    const EquilibriumOptions& options);

// A new System: `sys` with force parameters (force index, name) set to `values`.
System with_force_parameters(const System& sys, const std::vector<std::pair<int, std::string>>& parameters,
                             const std::vector<double>& values);

}  // namespace mbdae
