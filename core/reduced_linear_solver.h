// A SUNDIALS linear solver for Newton matrices whose first nq rows are the kinematic rows
// q'_i - v_i (entries only at (i, i) and (i, nq + i): cj and -1): the velocity corrections are
// eliminated with them (dv = cj dq - b1), KluSolver factors the remaining (n - nq) rows over the
// q columns and those after the v block, and dv is recovered in O(nq). Math and accuracy:
// docs/formulation.md, "The reduced Newton solve". Same pivot-reuse policy as
// make_klu_linear_solver; no allocation after construction.
#pragma once

#include <sundials/sundials_linearsolver.h>

#include <vector>

#include "core/sparse_assembler.h"

namespace mbdae {

// The entries of the v columns below the kinematic rows, by column i < nq:
// [ptr[i], ptr[i+1]) index entry (in the full matrix), row and target (in the reduced one).
struct KinematicBlock {
  std::vector<int> ptr, entry, row, target;
};

// The reduced system's pattern and where each entry of the full matrix goes in it.
struct KinematicReduction {
  int n = 0, nq = 0;           // full size and number of kinematic rows
  CscPattern pattern;          // (n - nq) x (n - nq): columns q, then those after the v block
  std::vector<int> target;     // per full entry outside the kinematic rows and the v block:
                               // reduced entry (-1 for the others)
  std::vector<int> diag, off;  // per kinematic row i: full entries (i, i) and (i, nq + i)
  KinematicBlock v;
};

// Whether rows 0..nq-1 of the square `pattern` hold exactly the entries (i, i) and (i, nq + i),
// with n >= 2 nq and nq > 0.
bool has_kinematic_rows(const CscPattern& pattern, int nq);
// The reduction of a pattern for which has_kinematic_rows holds.
KinematicReduction make_kinematic_reduction(const CscPattern& pattern, int nq);

// The reduced solver when has_kinematic_rows(pattern, nq), else make_klu_linear_solver(pattern).
// The matrix given to setup must be a CSC SUNSparseMatrix with `pattern`.
SUNLinearSolver make_newton_linear_solver(const CscPattern& pattern, int nq, SUNContext ctx);
// Whether s is the reduced solver (false for the full one).
bool is_reduced_linear_solver(SUNLinearSolver s);
// Fresh KLU factorizations (new pivot order) of a solver made by make_newton_linear_solver.
int newton_linear_solver_fresh_factorizations(SUNLinearSolver s);

}  // namespace mbdae
