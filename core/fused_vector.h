// Fused operations for SUNDIALS' serial N_Vector (issue 27): IDA's predictor and its
// interpolation (IDAGetSolution, IDAGetDky: the root functions and every output sample) form
// linear combinations of up to six history vectors. Without a fused operation SUNDIALS does one
// pass over memory per vector (N_VScale, then N_VLinearSum per term); this one does a single pass,
// with the same operations per element in the same order, so the results are bit for bit those
// of SUNDIALS' own sequence (docs/performance.md).
#pragma once

#include <sundials/sundials_nvector.h>

namespace mbdae {

// Installs the fused operations in v's operation table; vectors cloned from v (IDA's own) inherit
// them.
void use_fused_operations(N_Vector v);

// z = sum_i c[i] X[i] in one pass (N_VLinearCombination's contract; SUNDIALS' sequence where z
// is one of X[1..]).
int fused_linear_combination(int nvec, double* c, N_Vector* X, N_Vector z);

}  // namespace mbdae
