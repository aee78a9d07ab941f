// NaN and infinity in results: a run stops at the first non-finite value of its state, of an
// output sample or of a sensor, and names the quantity and the time (status "non_finite").
#pragma once

#include <string>

#include "core/errors.h"

namespace mbdae {

// IEEE maxNum and minNum, as std::fmax and std::fmin (a NaN argument is ignored), but inlined: std::fmax is a call into
// libm, and the tolerance and norm loops of every step call it about a million times a run.
inline double max_num(double a, double b) { return (a < b || a != a) ? b : a; }
inline double min_num(double a, double b) { return (b < a || a != a) ? b : a; }

// Index of the first NaN or infinite entry of x[0, n), or -1.
int first_non_finite(const double* x, int n);

// "<what> is <value> at t = <t>", status "non_finite".
SolveError non_finite_error(const std::string& what, double value, double t);

}  // namespace mbdae
