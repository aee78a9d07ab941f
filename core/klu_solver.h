// Sparse LU by SuiteSparse KLU: symbolic analysis once per pattern, numeric factorization
// (klu_factor) the first time and klu_refactor (same pivot order) afterwards, falling back to a
// fresh factorization when the reused pivots degrade (pivot ratio below 1e-14 and below 1e-3 of
// the fresh one's). A fresh factorization whose fill exceeds 1.5 times the ordering's prediction
// redoes the analysis without BTF once (KluSolver::factor_fresh).
#pragma once

#include <klu.h>

#include <vector>

#include "core/sparse_assembler.h"

namespace mbdae {

class KluSolver {
 public:
  KluSolver();
  ~KluSolver();
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  // Symbolic analysis of the pattern (kept until analyze is called again).
  bool analyze(const CscPattern& pattern);
  // Numeric factorization of values on the analyzed pattern. False if singular.
  bool factor(const double* values);
  // Solves A x = b in place.
  bool solve(double* b);
  // Solves A x = b[r] in place for r < count, up to four in one pass over the factors.
  bool solve_many(double* const* b, int count);
  // Whether a factorization is held (solve can be called).
  bool factored() const { return numeric_ != nullptr; }
  // Reciprocal condition estimate of the last factorization.
  double rcond();
  // 1-norm condition number estimate of the last factorized matrix (klu_condest).
  double condest();
  int factorizations() const { return factorizations_; }
  int full_factorizations() const { return full_factorizations_; }
  // Nonzeros of L + U (including the off-diagonal blocks of BTF) of the last factorization, and
  // the flop count of the last factorization (klu_flops); for the scaling benchmark.
  long factor_nnz() const;
  double flops();

 private:
  void free_numeric();
  bool analyze_pattern();
  bool factor_fresh();
  klu_common common_;
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
  CscPattern pattern_;
  std::vector<double> values_;
  int factorizations_ = 0, full_factorizations_ = 0;
  double fresh_rcond_ = 0;  // pivot ratio of the last fresh factorization
};

}  // namespace mbdae
