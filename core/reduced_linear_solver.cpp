#include "core/reduced_linear_solver.h"

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>

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

// Sorted rows (shifted by -nq) below the kinematic rows of full column j.
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

// Reduced entry of full entry k (full column j, row r >= nq) in reduced column c.
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
  red.q.ptr.push_back(0);
  red.v.ptr.push_back(0);
  for (int j = 0; j < p.cols; ++j) {
    const int c = j < nq ? j : j - nq;  // q column i and v column nq + i go into reduced column i
    KinematicBlock* block = j < nq ? &red.q : j < 2 * nq ? &red.v : nullptr;
    for (int k = p.colptr[j]; k < p.colptr[j + 1]; ++k) {
      const int r = p.rowind[k];
      if (r < nq) {
        (j < nq ? red.diag : red.off)[r] = k;
        continue;
      }
      const int t = reduced_entry(red.pattern, c, r - nq);
      if (!block) {
        red.target[k] = t;
        continue;
      }
      block->entry.push_back(k);
      block->row.push_back(r - nq);
      block->target.push_back(t);
    }
    if (block) block->ptr.push_back(static_cast<int>(block->entry.size()));
  }
  return red;
}

namespace {

struct Content {
  KinematicReduction red;
  KluSolver klu;
  std::vector<double> values;      // reduced matrix
  std::vector<double> a, b;        // kinematic row i: a_i dq_i + b_i dv_i (cj and -1 for q' - v)
  std::vector<char> keeps_v;       // per i: reduced unknown i is dv_i (dq_i eliminated), else dq_i
  std::vector<double> qval, vval;  // values of red.q and red.v
  std::vector<double> rhs;         // reduced right side, then solution
  int last_flag = 0;
};
Content* content(SUNLinearSolver s) { return static_cast<Content*>(s->content); }

SUNLinearSolver_Type get_type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID get_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return kLinSolSuccess; }

// Kinematic row i as p u + r e = b1_i: u the kept unknown (reduced column i), e the eliminated one.
struct RowSplit {
  const KinematicBlock* kept;
  const KinematicBlock* eliminated;
  const double *kept_values, *eliminated_values;
  double p, r;
};
RowSplit split(const Content& c, int i) {
  if (c.keeps_v[i]) return {&c.red.v, &c.red.q, c.vval.data(), c.qval.data(), c.b[i], c.a[i]};
  return {&c.red.q, &c.red.v, c.qval.data(), c.vval.data(), c.a[i], c.b[i]};
}

// Largest |value| of column i of a block.
double column_max(const KinematicBlock& block, const std::vector<double>& values, int i) {
  double m = 0;
  for (int e = block.ptr[i]; e < block.ptr[i + 1]; ++e) m = std::max(m, std::fabs(values[e]));
  return m;
}

// Whether dq_i is eliminated (dv_i kept): when the term that elimination adds to the kept column,
// A_rq b / a, is smaller than that column, A_rv, i.e. |a| max|A_rv| >= |b| max|A_rq| (cj^2 M
// against the stiffness); else dv_i is eliminated, adding A_rv a / b to A_rq. Either way the
// reduced column is A_rq + cj A_rv up to a factor; the choice decides which right-side term,
// A_rv b1 or A_rq b1 / cj, is added, and is the smaller one.
bool eliminates_q(const Content& c, int i) {
  return std::fabs(c.a[i]) * column_max(c.red.v, c.vval, i) >=
         std::fabs(c.b[i]) * column_max(c.red.q, c.qval, i);
}

// Reduced matrix: column i is A_r,kept - A_r,eliminated p / r (A_rq + cj A_rv when dv_i is
// eliminated, A_rv + A_rq / cj when dq_i is), the later columns as they are. False if a_i and b_i are
// both 0.
bool scatter(Content& c, const double* A) {
  const KinematicReduction& red = c.red;
  std::fill(c.values.begin(), c.values.end(), 0.0);
  for (int k = 0; k < static_cast<int>(red.target.size()); ++k)
    if (red.target[k] >= 0) c.values[red.target[k]] += A[k];
  for (size_t e = 0; e < red.q.entry.size(); ++e) c.qval[e] = A[red.q.entry[e]];
  for (size_t e = 0; e < red.v.entry.size(); ++e) c.vval[e] = A[red.v.entry[e]];
  for (int i = 0; i < red.nq; ++i) {
    c.a[i] = A[red.diag[i]];
    c.b[i] = A[red.off[i]];
    c.keeps_v[i] = eliminates_q(c, i);
    if ((c.keeps_v[i] ? c.a[i] : c.b[i]) == 0.0) return false;
    const RowSplit rs = split(c, i);
    const double s = -rs.p / rs.r;
    for (int e = rs.kept->ptr[i]; e < rs.kept->ptr[i + 1]; ++e)
      c.values[rs.kept->target[e]] += rs.kept_values[e];
    for (int e = rs.eliminated->ptr[i]; e < rs.eliminated->ptr[i + 1]; ++e)
      c.values[rs.eliminated->target[e]] += s * rs.eliminated_values[e];
  }
  return true;
}

int setup(SUNLinearSolver s, SUNMatrix a) {
  Content* c = content(s);
  const bool ok = scatter(*c, SUNSparseMatrix_Data(a)) && c->klu.factor(c->values.data());
  c->last_flag = ok ? 0 : 1;
  return ok ? kLinSolSuccess : SUNLS_LUFACT_FAIL;  // recoverable: IDA reduces the step
}

// x from b: the reduced right side b_r - A_r,eliminated b1 / r, the reduced solve for the kept
// unknowns, then e_i = (b1_i - p u_i) / r. x may alias b (each b1_i is read before x_i is written).
int solve(SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector bv, sunrealtype) {
  Content* c = content(s);
  const int nq = c->red.nq, n = c->red.n;
  const double* b = N_VGetArrayPointer(bv);
  double* y = N_VGetArrayPointer(x);
  std::copy(b + nq, b + n, c->rhs.begin());
  for (int i = 0; i < nq; ++i) {
    const RowSplit rs = split(*c, i);
    const double t = b[i] / rs.r;
    for (int e = rs.eliminated->ptr[i]; e < rs.eliminated->ptr[i + 1]; ++e)
      c->rhs[rs.eliminated->row[e]] -= rs.eliminated_values[e] * t;
  }
  const bool ok = c->klu.solve(c->rhs.data());
  c->last_flag = ok ? 0 : 1;
  if (!ok) return kLinSolFailUnrecoverable;
  for (int i = 0; i < nq; ++i) {
    const RowSplit rs = split(*c, i);
    const double u = c->rhs[i], e = (b[i] - rs.p * u) / rs.r;
    y[i] = c->keeps_v[i] ? e : u;
    y[nq + i] = c->keeps_v[i] ? u : e;
  }
  std::copy(c->rhs.begin() + nq, c->rhs.end(), y + 2 * nq);
  return kLinSolSuccess;
}

sunindextype last_flag(SUNLinearSolver s) { return content(s)->last_flag; }

int free_solver(SUNLinearSolver s) {
  if (!s) return kLinSolSuccess;
  delete content(s);
  s->content = nullptr;
  SUNLinSolFreeEmpty(s);
  return kLinSolSuccess;
}

SUNLinearSolver make_reduced(const CscPattern& pattern, int nq, SUNContext ctx) {
  SUNLinearSolver s = SUNLinSolNewEmpty(ctx);
  s->ops->gettype = get_type;
  s->ops->getid = get_id;
  s->ops->initialize = initialize;
  s->ops->setup = setup;
  s->ops->solve = solve;
  s->ops->lastflag = last_flag;
  s->ops->free = free_solver;
  auto* c = new Content;
  c->red = make_kinematic_reduction(pattern, nq);
  c->values.assign(c->red.pattern.nnz(), 0.0);
  c->a.assign(nq, 0.0);
  c->b.assign(nq, 0.0);
  c->keeps_v.assign(nq, 0);
  c->qval.assign(c->red.q.entry.size(), 0.0);
  c->vval.assign(c->red.v.entry.size(), 0.0);
  c->rhs.assign(c->red.pattern.rows, 0.0);
  c->klu.analyze(c->red.pattern);  // symbolic analysis once per pattern
  s->content = c;
  return s;
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
