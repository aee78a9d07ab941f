// mbdae's kernels for SUNDIALS' serial N_Vector (issue 27), bit for bit SUNDIALS' own results:
// - a fused linear combination: IDA's predictor and its interpolation (IDAGetSolution, IDAGetDky:
//   the root functions and every output sample) combine up to six history vectors; without a
//   fused operation SUNDIALS makes one pass over memory per vector (N_VScale, then N_VLinearSum
//   per term), this one a single pass with the same operations per element in the same order,
//   and the same for IDAS's arrays of sensitivity vectors (SUNDIALS' generic vector-array
//   combination allocates at every call);
// - the serial kernels IDA and IDAS spend their vector work in (linear sum, scale, constant, the
//   weighted norms), SUNDIALS' own code compiled with this build's optimization: Debian builds
//   libsundials without optimization (docs/performance.md, "SUNDIALS' kernels compiled").
#pragma once

#include <sundials/sundials_nvector.h>

namespace mbdae {

// Installs these kernels in v's operation table; vectors cloned from v (IDA's own, IDAS's
// sensitivities) inherit them.
void use_vector_kernels(N_Vector v);

// z = sum_i c[i] X[i] in one pass (N_VLinearCombination's contract; SUNDIALS' sequence where z
// is one of X[1..]).
int fused_linear_combination(int nvec, double* c, N_Vector* X, N_Vector z);

// Z[i] = sum_j c[j] X[j][i], i < nvec (N_VLinearCombinationVectorArray's contract: IDAS's
// sensitivity vectors), the fused combination per vector, without allocating.
int linear_combination_vector_array(int nvec, int nsum, double* c, N_Vector** X, N_Vector* Z);

}  // namespace mbdae
