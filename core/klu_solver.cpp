#include "core/klu_solver.h"

#include <algorithm>
#include <cmath>

namespace mbdae {

KluSolver::KluSolver() { klu_defaults(&common_); }

KluSolver::~KluSolver() {
  free_numeric();
  if (symbolic_) klu_free_symbolic(&symbolic_, &common_);
}

void KluSolver::free_numeric() {
  if (numeric_) klu_free_numeric(&numeric_, &common_);
  numeric_ = nullptr;
}

bool KluSolver::analyze(const CscPattern& p) {
  free_numeric();
  if (symbolic_) klu_free_symbolic(&symbolic_, &common_);
  pattern_ = p;
  symbolic_ = klu_analyze(p.rows, pattern_.colptr.data(), pattern_.rowind.data(), &common_);
  return symbolic_ != nullptr;
}

bool KluSolver::factor(const double* values) {
  values_.assign(values, values + pattern_.nnz());
  ++factorizations_;
  if (numeric_) {
    // Reuse the pivot order. A fresh factorization only when the pivot ratio is both small and
    // degraded relative to the last fresh one: the absolute ratio of a multibody saddle-point
    // matrix can be tiny by nature (massless links, mixed units: 1e-15 for the suspension's
    // Newton matrix), so an absolute test alone would refactor from scratch every time.
    if (klu_refactor(pattern_.colptr.data(), pattern_.rowind.data(), values_.data(), symbolic_,
                     numeric_, &common_) &&
        klu_rcond(symbolic_, numeric_, &common_) &&
        (common_.rcond > 1e-14 || common_.rcond > 1e-3 * fresh_rcond_))
      return true;
    free_numeric();
  }
  ++full_factorizations_;
  numeric_ = klu_factor(pattern_.colptr.data(), pattern_.rowind.data(), values_.data(), symbolic_,
                        &common_);
  if (numeric_ == nullptr || common_.status != KLU_OK) return false;
  klu_rcond(symbolic_, numeric_, &common_);
  fresh_rcond_ = common_.rcond;
  return true;
}

bool KluSolver::solve(double* b) {
  if (!numeric_) return false;
  return klu_solve(symbolic_, numeric_, pattern_.rows, 1, b, &common_) != 0;
}

double KluSolver::condest() {
  if (!numeric_) return INFINITY;
  klu_condest(pattern_.colptr.data(), values_.data(), symbolic_, numeric_, &common_);
  return common_.condest;
}

double KluSolver::rcond() {
  if (!numeric_) return 0.0;
  klu_rcond(symbolic_, numeric_, &common_);
  return common_.rcond;
}

}  // namespace mbdae
