// KLU's solve for one right-hand side (klu_solve with nrhs = 1), with the same operations in the
// same order, so bit for bit its result: core/tests/klu_solve_one_test.cpp. Hand-written for
// speed (docs/formulation.md, "Hand-written pieces"): KLU's own decodes each packed column's
// pointers through a general nrhs switch and divides by the row scale one entry at a time.
#pragma once

#include <klu.h>

namespace mbdae {

// Solves A x = b in place for the factorization (symbolic, numeric) of A; uses numeric's Xwork
// as klu_solve does.
void klu_solve_one(const klu_symbolic& symbolic, const klu_numeric& numeric, double* b);

}  // namespace mbdae
