// The run state of a multibody DAE, kept apart from the model (System), which is built once and
// never changed: in the manner of MuJoCo's mjModel / mjData and Drake's System / Context. A
// formulation (MultibodyDae) owns one RunState; the integration stage sets the start of a run
// through it (modes, turns, output settings) and reads its statistics; sinks receive the state of
// each sample (Sample in cases/mbdae.h: t, q, v, a and the modes).
#pragma once

#include <string>
#include <vector>

#include "formulation/constraints.h"
#include "formulation/system.h"

namespace mbdae {

// What the output samples compute (set before a run).
struct OutputSettings {
  // Solve accelerations for output samples (only needed by acceleration sensors).
  bool accelerations = true;
  // Relative error allowed in the output accelerations' linear solve (run(): min(1e-10, 1e-3
  // rtol), below the integration error they carry at any rtol; AugmentedSolver::output_accelerations).
  double acceleration_tolerance = 1e-12;
  // Conditioning of the constraints along the run (one extra factorization every tenth sample).
  bool track_condition = false;
};

// Per-step statistics of the integrator's own solution (accepted steps) and of the outputs.
struct StepStatistics {
  double max_position_violation = 0;  // max |Phi| over accepted steps
  double max_velocity_violation = 0;  // max |Phi_q v + Phi_t| over accepted steps
  double max_norm_drift = 0;          // max | |p| - 1 | over accepted steps
  double max_condition = 0, max_condition_time = 0;  // with OutputSettings::track_condition
};

// Values computed once per residual evaluation at its q and shared by the rows that need them.
struct EvaluationCache {
  // Local constraint Jacobian rows (up to 3 per constraint, 14 columns: the two bodies' local
  // coordinates) at the q of the last residual; constraint k's rows start at 3 k.
  std::vector<Row14> constraint_rows;
};

struct RunState {
  std::vector<char> modes;  // per force: wheel in contact (switched at events)
  CoordinateTurns turns;    // whole turns of rotation coordinates, after each accepted step
  OutputSettings output;
  StepStatistics statistics;
  // Empty, or why the last consistent output state could not be formed (a projection or the
  // acceleration solve failed, or y was not finite): its numbers must not be used.
  std::string output_failure;
  EvaluationCache cache;
};

}  // namespace mbdae
