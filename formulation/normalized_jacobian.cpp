#include "formulation/normalized_jacobian.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "formulation/mechanics.h"

namespace mbdae {

cholmod_sparse* normalized_constraint_jacobian_transpose(const System& sys, const double* q, cholmod_common* cc) {
  const std::vector<int> off = constraint_offsets(sys);
  const int nc = off.back(), nq = sys.nq();
  std::vector<std::vector<std::pair<int, double>>> cols(nc);
  Row14 rows[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows);
    for (int r = 0; r < c.rows(); ++r) {
      const double norm = rows[r].norm();
      std::vector<std::pair<int, double>>& col = cols[off[k] + r];
      for (int l = 0; l < 14; ++l) {
        const int b = l < 7 ? c.bi : c.bj;
        if (b < 0 || rows[r](l) == 0.0 || norm == 0.0) continue;
        col.push_back({7 * b + l % 7, rows[r](l) / norm});
      }
      // The same body on both sides (never in a built system) would give duplicate rows.
      std::sort(col.begin(), col.end());
    }
  }
  size_t nnz = 0;
  for (auto& col : cols) nnz += col.size();
  cholmod_sparse* a = cholmod_l_allocate_sparse(nq, nc, nnz, 1, 1, 0, CHOLMOD_REAL, cc);
  auto* ap = static_cast<SuiteSparse_long*>(a->p);
  auto* ai = static_cast<SuiteSparse_long*>(a->i);
  auto* ax = static_cast<double*>(a->x);
  size_t pos = 0;
  for (int j = 0; j < nc; ++j) {
    ap[j] = pos;
    for (auto& [i, v] : cols[j]) {
      ai[pos] = i;
      ax[pos++] = v;
    }
  }
  ap[nc] = pos;
  return a;
}

}  // namespace mbdae
