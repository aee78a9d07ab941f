// A SUNDIALS linear solver (SUNLinearSolver, direct) on mbdae's KluSolver, for IDA's Newton
// iteration. Unlike SUNLinSol_KLU, which refactors from scratch whenever KLU's pivot ratio falls
// below eps^(2/3) (the suspension's index-3 Newton matrix sits at 1e-15 by nature), it reuses the
// pivot order until the ratio degrades relative to the last fresh factorization: no fresh
// factorization and no allocation in the step loop.
#pragma once

#include <sundials/sundials_linearsolver.h>

#include "core/sparse_assembler.h"
#include "core/sundials_compat.h"

namespace mbdae {

class KluSolver;

// The operations that differ between mbdae's direct solvers (this one and
// core/reduced_linear_solver.h).
struct DirectSolverOps {
  int (*setup)(SUNLinearSolver, SUNMatrix);
  int (*solve)(SUNLinearSolver, SUNMatrix, N_Vector, N_Vector, sunrealtype);
  sunindextype (*last_flag)(SUNLinearSolver);
  int (*free)(SUNLinearSolver);
};
// A direct SUNLinearSolver (custom id, nothing to initialize) with those operations and content.
SUNLinearSolver new_direct_linear_solver(SUNContext ctx, const DirectSolverOps& ops, void* content);
// The same for a content C made with new and holding the last flag in `last_flag`: lastflag reads
// it, free deletes the content.
template <class C>
SUNLinearSolver new_direct_linear_solver(SUNContext ctx, decltype(DirectSolverOps::setup) setup,
                                         decltype(DirectSolverOps::solve) solve, C* content) {
  const auto last_flag = [](SUNLinearSolver s) -> sunindextype { return static_cast<C*>(s->content)->last_flag; };
  const auto free_solver = [](SUNLinearSolver s) -> int {
    if (!s) return kLinSolSuccess;
    delete static_cast<C*>(s->content);
    s->content = nullptr;
    SUNLinSolFreeEmpty(s);
    return kLinSolSuccess;
  };
  return new_direct_linear_solver(ctx, {setup, solve, last_flag, free_solver}, content);
}

// The matrix given to setup must be a CSC SUNSparseMatrix with `pattern`.
SUNLinearSolver make_klu_linear_solver(const CscPattern& pattern, SUNContext ctx);
// The right-hand sides rhs[0..count) that IDAS's staggered sensitivity corrector is about to
// solve one after the other (idaNlsLSolveSensStg: the sensitivities' residuals of one Newton
// iteration, negated in place, then a solve for each in order). The first of those solves solves
// them all in one pass over the factors (klu_solve_many: the factors' indices and values read
// once for up to four; bit for bit the single solves); the others then only copy. A solve of
// any other vector, or out of that order, ends the batch and solves alone. No effect for count
// < 2 or on another solver.
void klu_linear_solver_expect_batch(SUNLinearSolver s, double* const* rhs, int count);
// Factorization counts of a solver made by make_klu_linear_solver.
int klu_linear_solver_fresh_factorizations(SUNLinearSolver s);

}  // namespace mbdae
