#include "core/reduced_linear_solver.h"

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>

#include "core/klu_linear_solver.h"
#include "core/klu_solver.h"
#include "core/sundials_compat.h"

namespace mbdae {

bool has_kinematic_rows(const CscPattern& p, int nq) {
  if (nq <= 0 || p.rows != p.cols || p.rows < 2 * nq || p.colptr.size() != size_t(p.cols) + 1)
    return false;
  std::vector<int> found(nq, 0);  // bit 1: (i, i), bit 2: (i, nq + i)
  for (int j = 0; j < p.cols; ++j)
    for (int k = p.colptr[j]; k < p.colptr[j + 1]; ++k) {
      const int r = p.rowind[k];
      if (r >= nq) continue;
      if (j == r) found[r] |= 1;
      else if (j == nq + r) found[r] |= 2;
      else return false;  // another entry in a kinematic row
    }
  return std::all_of(found.begin(), found.end(), [](int f) { return f == 3; });
}

namespace {

// Full column of reduced column c: q columns keep their index, later ones skip the v block.
int full_column(int c, int nq) { return c < nq ? c : c + nq; }

// The rows (shifted by -nq) of full column j below the kinematic rows.
void lower_rows(const CscPattern& p, int j, int nq, std::vector<int>& rows) {
  for (int k = p.colptr[j]; k < p.colptr[j + 1]; ++k)
    if (p.rowind[k] >= nq) rows.push_back(p.rowind[k] - nq);
}

// The reduced pattern: reduced column i < nq is the union of full columns i and nq + i.
CscPattern reduced_pattern(const CscPattern& p, int nq) {
  CscPattern rp;
  rp.rows = rp.cols = p.rows - nq;
  rp.colptr.push_back(0);
  std::vector<int> rows;
  for (int c = 0; c < rp.cols; ++c) {
    rows.clear();
    lower_rows(p, full_column(c, nq), nq, rows);
    if (c < nq) lower_rows(p, nq + c, nq, rows);
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    rp.rowind.insert(rp.rowind.end(), rows.begin(), rows.end());
    rp.colptr.push_back(static_cast<int>(rp.rowind.size()));
  }
  return rp;
}

// Position of (reduced) row r in reduced column c.
int reduced_entry(const CscPattern& rp, int c, int r) {
  const auto first = rp.rowind.begin() + rp.colptr[c], last = rp.rowind.begin() + rp.colptr[c + 1];
  return static_cast<int>(std::lower_bound(first, last, r) - rp.rowind.begin());
}

}  // namespace

KinematicReduction make_kinematic_reduction(const CscPattern& p, int nq) {
  KinematicReduction red;
  red.n = p.rows;
  red.nq = nq;
  red.pattern = reduced_pattern(p, nq);
  red.target.assign(p.nnz(), -1);
  red.diag.assign(nq, -1);
  red.off.assign(nq, -1);
  red.v.ptr.push_back(0);
  for (int j = 0; j < p.cols; ++j) {
    const int c = j < nq ? j : j - nq;  // q column i and v column nq + i go into reduced column i
    const bool v_column = j >= nq && j < 2 * nq;
    for (int k = p.colptr[j]; k < p.colptr[j + 1]; ++k) {
      const int r = p.rowind[k];
      if (r < nq) {
        (j < nq ? red.diag : red.off)[r] = k;
        continue;
      }
      const int t = reduced_entry(red.pattern, c, r - nq);
      if (!v_column) {
        red.target[k] = t;
        continue;
      }
      red.v.entry.push_back(k);
      red.v.row.push_back(r - nq);
      red.v.target.push_back(t);
    }
    if (v_column) red.v.ptr.push_back(static_cast<int>(red.v.entry.size()));
  }
  return red;
}

namespace {

struct Content {
  KinematicReduction red;
  KluSolver klu;
  std::vector<double> values;  // reduced matrix
  std::vector<double> a, b;    // kinematic row i: a_i dq_i + b_i dv_i (cj and -1 for q' - v)
  std::vector<double> vval;    // values of red.v
  std::vector<double> rhs;     // reduced right side, then solution
  int last_flag = 0;
};
Content* content(SUNLinearSolver s) { return static_cast<Content*>(s->content); }

// Reduced matrix: column i < nq is A_rq - A_rv a_i / b_i (A_rq + cj A_rv), the later columns as
// they are. False if some b_i is 0 (dv_i cannot be eliminated).
bool scatter(Content& c, const double* A) {
  const KinematicReduction& red = c.red;
  std::fill(c.values.begin(), c.values.end(), 0.0);
  for (int k = 0; k < static_cast<int>(red.target.size()); ++k)
    if (red.target[k] >= 0) c.values[red.target[k]] += A[k];
  for (int i = 0; i < red.nq; ++i) {
    c.a[i] = A[red.diag[i]];
    c.b[i] = A[red.off[i]];
    if (c.b[i] == 0.0) return false;
    const double s = -c.a[i] / c.b[i];
    for (int e = red.v.ptr[i]; e < red.v.ptr[i + 1]; ++e) {
      c.vval[e] = A[red.v.entry[e]];
      c.values[red.v.target[e]] += s * c.vval[e];
    }
  }
  return true;
}

int setup(SUNLinearSolver s, SUNMatrix a) {
  Content* c = content(s);
  const bool ok = scatter(*c, SUNSparseMatrix_Data(a)) && c->klu.factor(c->values.data());
  c->last_flag = ok ? 0 : 1;
  return ok ? kLinSolSuccess : SUNLS_LUFACT_FAIL;  // recoverable: IDA reduces the step
}

// x from b: the reduced right side b_r - A_rv diag(1 / b) b1, the reduced solve for dq and the
// later unknowns, then dv_i = (b1_i - a_i dq_i) / b_i. x may alias b (each b1_i is read before
// x_i is written).
int solve(SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector bv, sunrealtype) {
  Content* c = content(s);
  const KinematicBlock& v = c->red.v;
  const int nq = c->red.nq, n = c->red.n;
  const double* b = N_VGetArrayPointer(bv);
  double* y = N_VGetArrayPointer(x);
  std::copy(b + nq, b + n, c->rhs.begin());
  for (int i = 0; i < nq; ++i) {
    const double t = b[i] / c->b[i];
    for (int e = v.ptr[i]; e < v.ptr[i + 1]; ++e) c->rhs[v.row[e]] -= c->vval[e] * t;
  }
  const bool ok = c->klu.solve(c->rhs.data());
  c->last_flag = ok ? 0 : 1;
  if (!ok) return kLinSolFailUnrecoverable;
  for (int i = 0; i < nq; ++i) {
    y[nq + i] = (b[i] - c->a[i] * c->rhs[i]) / c->b[i];
    y[i] = c->rhs[i];
  }
  std::copy(c->rhs.begin() + nq, c->rhs.end(), y + 2 * nq);
  return kLinSolSuccess;
}

SUNLinearSolver make_reduced(const CscPattern& pattern, int nq, SUNContext ctx) {
  auto* c = new Content;
  c->red = make_kinematic_reduction(pattern, nq);
  c->values.assign(c->red.pattern.nnz(), 0.0);
  c->a.assign(nq, 0.0);
  c->b.assign(nq, 0.0);
  c->vval.assign(c->red.v.entry.size(), 0.0);
  c->rhs.assign(c->red.pattern.rows, 0.0);
  c->klu.analyze(c->red.pattern);  // symbolic analysis once per pattern
  return new_direct_linear_solver(ctx, setup, solve, c);
}

}  // namespace

SUNLinearSolver make_newton_linear_solver(const CscPattern& pattern, int nq, SUNContext ctx) {
  if (!has_kinematic_rows(pattern, nq)) return make_klu_linear_solver(pattern, ctx);
  return make_reduced(pattern, nq, ctx);
}

bool is_reduced_linear_solver(SUNLinearSolver s) { return s && s->ops->setup == setup; }

int newton_linear_solver_fresh_factorizations(SUNLinearSolver s) {
  if (is_reduced_linear_solver(s)) return content(s)->klu.full_factorizations();
  return klu_linear_solver_fresh_factorizations(s);
}

}  // namespace mbdae
