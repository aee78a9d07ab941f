#include "core/finite_check.h"

#include <cmath>
#include <sstream>

namespace mbdae {

int first_non_finite(const double* x, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) return i;
  return -1;
}

SolveError non_finite_error(const std::string& what, double value, double t) {
  std::ostringstream os;
  os.precision(10);
  os << what << " is " << (std::isnan(value) ? "NaN" : value > 0 ? "+inf" : "-inf") << " at t = " << t
     << " (overflow or an invalid operation; the run stops there)";
  return SolveError("non_finite", os.str());
}

}  // namespace mbdae
