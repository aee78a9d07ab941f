#include "formulation/assembly_mode.h"

#include <algorithm>
#include <cmath>

namespace mbdae {

std::vector<CoordinateMove> coordinates_far_from_guess(const System& sys, const double* q,
                                                       const std::vector<int>& held, double limit) {
  std::vector<CoordinateMove> out;
  for (int k = 0; k < static_cast<int>(sys.coordinates.size()); ++k) {
    const JointCoordinate& c = sys.coordinates[k];
    if (c.merged || !c.function.rotation || c.spec.mode != CoordinateSpec::Mode::kFree) continue;
    if (std::find(held.begin(), held.end(), k) != held.end()) continue;
    CoordinateMove m;
    m.name = c.name;
    m.guess = c.spec.initial;
    m.converged = coordinate_value(sys, k, q);
    m.change = std::remainder(m.converged - m.guess, 2 * M_PI);
    if (std::fabs(m.change) > limit) out.push_back(m);
  }
  std::stable_sort(out.begin(), out.end(), [](const CoordinateMove& a, const CoordinateMove& b) {
    return std::fabs(a.change) > std::fabs(b.change);
  });
  return out;
}

}  // namespace mbdae
