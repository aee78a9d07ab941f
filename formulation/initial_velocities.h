// Initial velocities from rates of joint coordinates (a dynamics step's `initial_velocities`).
//
// The velocity v at (q, t0) solves the system's velocity constraints together with one row per
// given rate:
//   Phi_q v = -Phi_t,      (d theta_k / dq) v = rate_k,
// as the minimum weighted change of the velocity passed in (the augmented solver's velocity
// projection, formulation/augmented_solver.h). The rows of the rates are the system's own
// coordinate functions (those of hold and drive constraints), so a rate means the same as a drive
// of that coordinate with that slope. Where the given rates do not fix every degree of freedom,
// the others take the velocity closest to the one passed in (rest, for a step that starts at
// rest); where they over-determine the motion (more rates than degrees of freedom, or rates the
// constraints forbid), the solution cannot meet all rows and an error names the rows.
#pragma once

#include <string>
#include <vector>

#include "formulation/system.h"

namespace mbdae {

struct CoordinateRate {
  int coordinate = -1;  // index into System::coordinates
  double rate = 0;      // rad/s or m/s
};

// Sets v (nq values, in: the velocity to change least; out: the solution). Throws SolveError
// ("inconsistent_initial_velocities") if the rows cannot all hold to 1e-9 of the rates' scale.
void solve_initial_velocities(const System& sys, const double* q, double t,
                              const std::vector<CoordinateRate>& rates, double* v);

}  // namespace mbdae
