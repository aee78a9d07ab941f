#include "core/finite_check.h"

#include <cmath>
#include <sstream>

namespace mbdae {

int first_non_finite(const double* x, int n) {
  // x * 0 is NaN exactly where x is infinite or NaN, and 0 elsewhere: four sums of them, which
  // the compiler packs, say whether to look for the entry at all (almost never).
  double s[4] = {0, 0, 0, 0};
  int i = 0;
  for (; i + 4 <= n; i += 4)
    for (int k = 0; k < 4; ++k) s[k] += x[i + k] * 0.0;
  if (s[0] == 0 && s[1] == 0 && s[2] == 0 && s[3] == 0) {
    for (; i < n; ++i)
      if (!std::isfinite(x[i])) return i;
    return -1;
  }
  for (int j = 0; j < n; ++j)
    if (!std::isfinite(x[j])) return j;
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
