// Assembly-mode check: did the assembly land on the branch of its guess?
//
// A closed loop generally assembles in several ways (assembly modes: elbow up or down, a rod
// flipped through its anchor) at the same values of the held coordinates, and Newton's method
// from a poor guess can converge to any of them without complaint. The guess is the user's
// statement of which mode is meant, so the check compares the converged joint coordinates with
// the guess: a free rotational coordinate that ended more than `limit` away from its guessed value
// (the difference wrapped to (-180, 180] degrees) is on another branch of that joint, or the guess
// was worse than the limit allows. Held, locked, driven and merged coordinates are skipped (they
// cannot move), and so are translations (no length scale is common to every model).
#pragma once

#include <string>
#include <vector>

#include "formulation/system.h"

namespace mbdae {

struct CoordinateMove {
  std::string name;
  double guess = 0, converged = 0;  // rad
  double change = 0;                // converged - guess wrapped to (-pi, pi]
};

// The free rotational coordinates that moved by more than limit (rad) from their guess
// (sys.coordinates[k].spec.initial), largest move first.
std::vector<CoordinateMove> coordinates_far_from_guess(const System& sys, const double* q,
                                                       const std::vector<int>& held, double limit);

}  // namespace mbdae
