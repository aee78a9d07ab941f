#include "formulation/initial_velocities.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "formulation/augmented_solver.h"
#include "formulation/constraint_rates.h"
#include "formulation/mechanics.h"

namespace mbdae {

void solve_initial_velocities(const System& sys, const double* q, double t,
                              const std::vector<CoordinateRate>& rates, double* v) {
  // The system with one driven-coordinate row per rate: theta_k(q) = theta_k(q0) + rate (t - t0).
  System with_rates = sys;
  for (const CoordinateRate& r : rates) {
    Constraint c = hold_constraint(sys, r.coordinate, 0.0);
    c.target.kind = TimeFunction::Kind::kPolynomial;
    const double value = coordinate_value(sys, r.coordinate, q);
    c.target.ys = {value - r.rate * t, r.rate};
    c.label = "initial rate of " + sys.coordinates[r.coordinate].name;
    with_rates.constraints.push_back(c);
  }
  AugmentedSolver aug(with_rates);
  const bool solved = aug.velocities(q, t, v);
  // Check every row: a singular or inconsistent set leaves some unmet.
  const std::vector<int> offsets = constraint_offsets(with_rates);
  std::vector<double> residual(offsets.back());
  velocity_constraint_values(with_rates, offsets, q, v, t, residual.data());
  double scale = 1.0;
  for (const CoordinateRate& r : rates) scale = std::max(scale, std::fabs(r.rate));
  std::ostringstream unmet;
  int count = 0;
  for (size_t c = 0; c < with_rates.constraints.size(); ++c)
    for (int row = offsets[c]; row < offsets[c + 1]; ++row)
      if (!(std::fabs(residual[row]) <= 1e-9 * scale)) {
        if (count++ < 4) unmet << (count > 1 ? "; " : "") << with_rates.constraints[c].label << " off by " << residual[row];
        break;
      }
  if (solved && count == 0) return;
  std::ostringstream os;
  os << "the initial velocities cannot all hold (" << rates.size()
     << " rates given; they exceed the mechanism's degrees of freedom or contradict its constraints)";
  if (count > 0) os << ": " << unmet.str();
  throw SolveError("inconsistent_initial_velocities", os.str());
}

}  // namespace mbdae
