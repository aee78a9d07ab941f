#include "formulation/singularity.h"

#include <SuiteSparseQR.hpp>

#include <algorithm>
#include <cmath>

#include "formulation/mechanics.h"
#include "formulation/normalized_jacobian.h"
#include "formulation/redundancy.h"

namespace mbdae {
namespace {

// Label and group of each scalar equation (row) of Phi_q.
struct RowNames {
  std::vector<std::string> label, group;
};
RowNames row_names(const System& sys) {
  RowNames out;
  for (const Constraint& c : sys.constraints)
    for (int r = 0; r < c.rows(); ++r) {
      out.label.push_back(row_label(c, r));
      out.group.push_back(constraint_group(c));
    }
  return out;
}

double norm2(const double* x, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += x[i] * x[i];
  return std::sqrt(s);
}

}  // namespace

SingularityReport diagnose_singularity(const System& sys, const double* q, double t, double min_weight) {
  SingularityReport report;
  const int nc = sys.num_constraint_rows();
  report.equations = nc;
  if (nc == 0) return report;
  const RowNames names = row_names(sys);
  std::vector<double> weight(nc, 0.0);

  cholmod_common cc;
  cholmod_l_start(&cc);
  cholmod_sparse* a = normalized_constraint_jacobian_transpose(sys, q, &cc);
  SuiteSparseQR_factorization<double>* qr =
      SuiteSparseQR_factorize<double>(SPQR_ORDERING_DEFAULT, SPQR_DEFAULT_TOL, a, &cc);
  report.rank = qr ? static_cast<int>(qr->rank) : 0;
  if (qr && report.rank == nc) {
    // Inverse iteration: x <- (A^T A)^-1 x = E R^-1 R^-T E^T x (A E = Q R).
    cholmod_dense* x = cholmod_l_allocate_dense(nc, 1, nc, CHOLMOD_REAL, &cc);
    auto* xv = static_cast<double*>(x->x);
    for (int i = 0; i < nc; ++i) xv[i] = 1.0 + 0.01 * (i % 7);  // not orthogonal to anything simple
    double lambda = 0;
    for (int it = 0; it < 50; ++it) {
      const double n0 = norm2(xv, nc);
      for (int i = 0; i < nc; ++i) xv[i] /= n0;
      cholmod_dense* b = SuiteSparseQR_solve<double>(SPQR_RTX_EQUALS_ETB, qr, x, &cc);
      cholmod_dense* z = b ? SuiteSparseQR_solve<double>(SPQR_RETX_EQUALS_B, qr, b, &cc) : nullptr;
      if (b) cholmod_l_free_dense(&b, &cc);
      if (!z) break;
      const auto* zv = static_cast<const double*>(z->x);
      const double lambda_new = norm2(zv, nc);
      std::copy(zv, zv + nc, xv);
      cholmod_l_free_dense(&z, &cc);
      const bool settled = std::fabs(lambda_new - lambda) <= 1e-10 * lambda_new;
      lambda = lambda_new;
      if (settled && it > 2) break;
    }
    const double n0 = norm2(xv, nc);
    double ymax = 0;
    for (int i = 0; i < nc; ++i) ymax = std::fmax(ymax, std::fabs(xv[i]));
    for (int i = 0; i < nc; ++i) weight[i] = ymax > 0 ? std::fabs(xv[i]) / ymax : 0.0;
    report.smallest_singular_value = lambda > 0 && n0 > 0 ? 1.0 / std::sqrt(lambda) : 0.0;
    cholmod_l_free_dense(&x, &cc);
  }
  // Largest singular value: power iteration on A^T A.
  {
    cholmod_dense* x = cholmod_l_allocate_dense(nc, 1, nc, CHOLMOD_REAL, &cc);
    cholmod_dense* w = cholmod_l_allocate_dense(a->nrow, 1, a->nrow, CHOLMOD_REAL, &cc);
    auto* xv = static_cast<double*>(x->x);
    std::fill(xv, xv + nc, 1.0);
    double one[2] = {1, 0}, zero[2] = {0, 0}, s2 = 0;
    for (int it = 0; it < 30; ++it) {
      const double n0 = norm2(xv, nc);
      for (int i = 0; i < nc; ++i) xv[i] /= n0;
      cholmod_l_sdmult(a, 0, one, zero, x, w, &cc);  // w = A x
      cholmod_l_sdmult(a, 1, one, zero, w, x, &cc);  // x = A^T w
      s2 = norm2(xv, nc);
    }
    report.largest_singular_value = std::sqrt(s2);
    cholmod_l_free_dense(&x, &cc);
    cholmod_l_free_dense(&w, &cc);
  }
  if (qr) SuiteSparseQR_free<double>(&qr, &cc);
  cholmod_l_free_sparse(&a, &cc);
  cholmod_l_finish(&cc);

  if (report.rank < nc) {
    // Exactly dependent: name the equations the redundancy check would remove.
    System copy = sys;
    const RedundancyReport rr = find_redundant_constraints(copy, q, t);
    // (the report names rows by row_label, as names.label does)
    for (const auto& r : rr.redundant) {
      const auto it = std::find(names.label.begin(), names.label.end(), r);
      report.dependent.push_back({r, 1.0, it == names.label.end() ? r : names.group[it - names.label.begin()]});
    }
  } else {
    std::vector<int> idx;
    for (int i = 0; i < nc; ++i)
      if (weight[i] >= min_weight) idx.push_back(i);
    std::stable_sort(idx.begin(), idx.end(), [&](int i, int j) { return weight[i] > weight[j]; });
    for (int i : idx) report.dependent.push_back({names.label[i], weight[i], names.group[i]});
  }
  for (const auto& d : report.dependent) {
    if (std::find(report.constraints.begin(), report.constraints.end(), d.group) == report.constraints.end())
      report.constraints.push_back(d.group);
  }
  return report;
}

}  // namespace mbdae
