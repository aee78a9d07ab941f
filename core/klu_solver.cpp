#include "core/klu_solver.h"

#include <algorithm>
#include <cmath>

#include "core/klu_kernels.h"

namespace mbdae {

namespace {
constexpr double kMaxTransversalWork = 100;  // times nnz(A): KLU's maxwork for btf_maxtrans
}  // namespace

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
  pattern_ = p;
  common_.btf = 1;  // KLU's default, until a fill fallback (factor_fresh) turns it off
  return analyze_pattern();
}

// Symbolic analysis; with BTF requested, also without it, keeping the analysis without BTF when
// BTF's maximum transversal gave up at kMaxTransversalWork x nnz(A) work (its cost is not linear
// in general: 2.1 s on a 200000-unknown binary tree's Newton matrix, docs/scaling.md; an
// incomplete transversal is never factored), or when it predicts at least 20 % less fill (within that margin the orders cost the same, and the pivot
// order of every mechanism that does not gain stays as it was). BTF's maximum transversal can pair
// constraint rows with columns far from them, and partial pivoting on AMD's order of that permuted
// matrix then fills like N^2 on serial chains (docs/scaling.md).
bool KluSolver::analyze_pattern() {
  free_numeric();
  if (symbolic_) klu_free_symbolic(&symbolic_, &common_);
  common_.maxwork = kMaxTransversalWork;
  symbolic_ = klu_analyze(pattern_.rows, pattern_.colptr.data(), pattern_.rowind.data(), &common_);
  if (symbolic_ == nullptr || !common_.btf) return symbolic_ != nullptr;
  const bool transversal_cut = common_.work < 0;  // BTF's maximum transversal hit maxwork
  common_.btf = 0;
  klu_symbolic* plain = klu_analyze(pattern_.rows, pattern_.colptr.data(), pattern_.rowind.data(), &common_);
  if (plain && (transversal_cut || 1.2 * (plain->lnz + plain->unz) <= symbolic_->lnz + symbolic_->unz)) {
    klu_free_symbolic(&symbolic_, &common_);
    symbolic_ = plain;
    return true;
  }
  if (plain) klu_free_symbolic(&plain, &common_);
  common_.btf = 1;
  return true;
}

// Fresh klu_factor. If partial pivoting filled L + U to more than 1.5 times the fill that the
// ordering predicted, the pivots have left the ordering's diagonal (BTF's maximum transversal
// matched rows to columns that the fill-reducing order does not respect; docs/scaling.md): the
// pattern is analyzed again without BTF, as AMD on the matrix's own diagonal, and factored again.
bool KluSolver::factor_fresh() {
  ++full_factorizations_;
  numeric_ = klu_factor(pattern_.colptr.data(), pattern_.rowind.data(), values_.data(), symbolic_,
                        &common_);
  if (numeric_ == nullptr || common_.status != KLU_OK) return false;
  const double predicted = symbolic_->lnz + symbolic_->unz;
  if (common_.btf && numeric_->lnz + numeric_->unz > 1.5 * predicted) {
    common_.btf = 0;
    if (!analyze_pattern()) return false;
    return factor_fresh();
  }
  return true;
}

bool KluSolver::factor(const double* values) {
  values_.assign(values, values + pattern_.nnz());
  ++factorizations_;
  if (numeric_) {
    // Reuse the pivot order. A fresh factorization only when the pivot ratio is both small and
    // degraded relative to the last fresh one: the absolute ratio of a multibody saddle-point
    // matrix can be tiny by nature (massless links, mixed units: 1e-15 for the suspension's
    // Newton matrix), so an absolute test alone would refactor from scratch every time.
    if (klu_refactor_scaled(pattern_.colptr.data(), pattern_.rowind.data(), values_.data(), *symbolic_,
                            *numeric_, common_) &&
        klu_rcond(symbolic_, numeric_, &common_) &&
        (common_.rcond > 1e-14 || common_.rcond > 1e-3 * fresh_rcond_))
      return true;
    free_numeric();
  }
  if (!factor_fresh()) return false;
  klu_rcond(symbolic_, numeric_, &common_);
  fresh_rcond_ = common_.rcond;
  return true;
}

bool KluSolver::solve(double* b) {
  if (!numeric_) return false;
  klu_solve_one(*symbolic_, *numeric_, b);
  return true;
}

bool KluSolver::solve_many(double* const* b, int count) {
  if (!numeric_) return false;
  klu_solve_many(*symbolic_, *numeric_, b, count);
  return true;
}

double KluSolver::condest() {
  if (!numeric_) return INFINITY;
  klu_condest(pattern_.colptr.data(), values_.data(), symbolic_, numeric_, &common_);
  return common_.condest;
}

long KluSolver::factor_nnz() const {
  if (!numeric_) return 0;
  return static_cast<long>(numeric_->lnz) + numeric_->unz + numeric_->nzoff;
}

double KluSolver::flops() {
  if (!numeric_) return 0;
  klu_flops(symbolic_, numeric_, &common_);
  return common_.flops;
}

double KluSolver::rcond() {
  if (!numeric_) return 0.0;
  klu_rcond(symbolic_, numeric_, &common_);
  return common_.rcond;
}

}  // namespace mbdae
