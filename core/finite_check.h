// NaN and infinity in results: a run stops at the first non-finite value of its state, of an
// output sample or of a sensor, and names the quantity and the time (status "non_finite").
#pragma once

#include <string>

#include "core/errors.h"

namespace mbdae {

// Index of the first NaN or infinite entry of x[0, n), or -1.
int first_non_finite(const double* x, int n);

// "<what> is <value> at t = <t>", status "non_finite".
SolveError non_finite_error(const std::string& what, double value, double t);

}  // namespace mbdae
