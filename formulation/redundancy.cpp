#include "formulation/redundancy.h"

#include <SuiteSparseQR.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "formulation/mechanics.h"

namespace mbdae {

RedundancyReport find_redundant_constraints(System& sys, const double* q, double t, bool remove,
                                            double tolerance) {
  RedundancyReport report;
  const std::vector<int> off = constraint_offsets(sys);
  const int nc = off.back(), nq = sys.nq();
  report.equations = nc;
  if (nc == 0) return report;

  // A = Phi_q^T (nq x nc), one column per equation, normalized.
  cholmod_common cc;
  cholmod_l_start(&cc);
  std::vector<std::vector<std::pair<int, double>>> cols(nc);
  Row14 rows[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows);
    for (int r = 0; r < c.rows(); ++r) {
      double norm = rows[r].norm();
      for (int l = 0; l < 14; ++l) {
        const int b = l < 7 ? c.bi : c.bj;
        if (b < 0 || rows[r](l) == 0.0) continue;
        cols[off[k] + r].push_back({7 * b + l % 7, norm > 0 ? rows[r](l) / norm : 0.0});
      }
    }
  }
  size_t nnz = 0;
  for (auto& col : cols) nnz += col.size();
  cholmod_sparse* a = cholmod_l_allocate_sparse(nq, nc, nnz, 1, 1, 0, CHOLMOD_REAL, &cc);
  auto* ap = static_cast<SuiteSparse_long*>(a->p);
  auto* ai = static_cast<SuiteSparse_long*>(a->i);
  auto* ax = static_cast<double*>(a->x);
  size_t pos = 0;
  for (int j = 0; j < nc; ++j) {
    ap[j] = pos;
    std::sort(cols[j].begin(), cols[j].end());
    for (auto& [i, v] : cols[j]) {
      ai[pos] = i;
      ax[pos++] = v;
    }
  }
  ap[nc] = pos;

  // QR in the natural column order; dead columns (norm below tol when reached) are redundant.
  cholmod_sparse* r_factor = nullptr;
  SuiteSparse_long* perm = nullptr;
  const SuiteSparse_long rank =
      SuiteSparseQR<double>(SPQR_ORDERING_FIXED, tolerance, nc, a, &r_factor, &perm, &cc);
  report.rank = static_cast<int>(rank);
  std::vector<char> dead(nc, 0);
  if (rank < nc && r_factor) {
    // In the squeezed R, a live column j (the k-th live one) has its last entry in row k.
    const auto* rp = static_cast<SuiteSparse_long*>(r_factor->p);
    const auto* ri = static_cast<SuiteSparse_long*>(r_factor->i);
    SuiteSparse_long live = 0;
    for (int jj = 0; jj < nc; ++jj) {
      const int j = perm ? static_cast<int>(perm[jj]) : jj;
      SuiteSparse_long last = -1;
      for (SuiteSparse_long p = rp[jj]; p < rp[jj + 1]; ++p)
        if (ri[p] > last) last = ri[p];
      if (last == live && live < rank) {
        ++live;
      } else {
        dead[j] = 1;
      }
    }
  }
  if (r_factor) cholmod_l_free_sparse(&r_factor, &cc);
  if (perm) cholmod_l_free(nc, sizeof(SuiteSparse_long), perm, &cc);
  cholmod_l_free_sparse(&a, &cc);
  cholmod_l_finish(&cc);

  // Report, and drop what is asked.
  std::vector<Constraint> kept;
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    Constraint c = sys.constraints[k];
    int keep_mask = 0, row = 0;
    for (int comp = 0; comp < 3; ++comp) {
      if (c.type == Constraint::Type::kPoint ? !(c.mask & (1 << comp)) : comp > 0) continue;
      if (dead[off[k] + row]) {
        report.redundant.push_back(c.label + (c.rows() > 1 ? std::string(" [") + "xyz"[comp] + "]" : ""));
      } else {
        keep_mask |= 1 << comp;
      }
      ++row;
    }
    if (!remove) continue;
    if (keep_mask == 0) continue;
    if (c.type == Constraint::Type::kPoint) c.mask = keep_mask;
    kept.push_back(c);
  }
  if (remove) sys.constraints = kept;
  return report;
}

}  // namespace mbdae
