// KLU's solve for one right-hand side and its refactorization with row scaling (klu_solve with
// nrhs = 1, klu_refactor with scale > 0), with the same operations in the same order, so bit for
// bit their results (core/tests/klu_kernels_test.cpp). Hand-written for speed (docs/formulation.md,
// "Hand-written pieces"): KLU's own decode each packed column's pointers through a general nrhs
// switch, check the matrix's indices at every refactorization and divide one entry at a time.
// They read KLU's factor objects (klu.h) and its packed columns (KLU's GET_POINTER layout).
#pragma once

#include <klu.h>

namespace mbdae {

// Solves A x = b in place for the factorization (symbolic, numeric) of A; uses numeric's Xwork
// as klu_solve does.
void klu_solve_one(const klu_symbolic& symbolic, const klu_numeric& numeric, double* b);
// The same for nrhs right-hand sides b[0..nrhs), up to four in one pass over L and U (klu_solve's
// layout, numeric's Xwork holding 4 n entries): bit for bit klu_solve_one on each.
void klu_solve_many(const klu_symbolic& symbolic, const klu_numeric& numeric, double* const* b, int nrhs);

// klu_refactor of A (colptr, rowind, values: the analyzed pattern) into numeric, for common.scale
// > 0, numeric's row scale present and common.halt_if_singular (KLU's defaults; else it calls
// klu_refactor). False, as klu_refactor, at an exactly zero pivot (common.status KLU_SINGULAR).
bool klu_refactor_scaled(int* colptr, int* rowind, double* values, klu_symbolic& symbolic, klu_numeric& numeric,
                         klu_common& common);

}  // namespace mbdae
