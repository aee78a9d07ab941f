#include "formulation/redundancy.h"

#include <SuiteSparseQR.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "formulation/mechanics.h"
#include "formulation/normalized_jacobian.h"

namespace mbdae {

namespace {

// The column order of the QR: the tree's own equations (Euler norms, tree joints, their locks and
// drives) first, in CCOLAMD's fill-reducing order of Phi_q Phi_q^T (on a tree the equations of
// each body form a clique, and a natural parent-first order fills R quadratically); then every
// other equation (cuts, holds) in its natural order, each in a constraint set of its own, so that
// of a dependent set the last cut equation is the one reported.
std::vector<SuiteSparse_long> analysis_order(const System& sys, const std::vector<int>& off,
                                             cholmod_sparse* a, cholmod_common* cc) {
  const int nc = off.back();
  std::vector<SuiteSparse_long> member(nc, 0), order(nc);
  SuiteSparse_long next_set = 1;
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint::Owner o = sys.constraints[k].owner;
    const bool tree = o == Constraint::Owner::kNorm || o == Constraint::Owner::kJoint ||
                      o == Constraint::Owner::kDrive || o == Constraint::Owner::kLock;
    for (int r = off[k]; r < off[k + 1]; ++r) member[r] = tree ? 0 : next_set++;
  }
  cholmod_sparse* phi = cholmod_l_transpose(a, 0, cc);  // pattern of Phi_q (nc x nq)
  const int ok = phi && cholmod_l_ccolamd(phi, nullptr, 0, member.data(), order.data(), cc);
  if (phi) cholmod_l_free_sparse(&phi, cc);
  if (!ok) throw std::runtime_error("redundancy analysis: CCOLAMD ordering failed");
  // The sets in their order whatever CHOLMOD's postordering did (a stable sort keeps set 0's order).
  std::stable_sort(order.begin(), order.end(),
                   [&](SuiteSparse_long x, SuiteSparse_long y) { return member[x] < member[y]; });
  return order;
}

}  // namespace

RedundancyReport find_redundant_constraints(const System& sys, const double* q, double t,
                                            double tolerance) {
  RedundancyReport report;
  const std::vector<int> off = constraint_offsets(sys);
  const int nc = off.back();
  report.equations = nc;
  report.keep.assign(sys.constraints.size(), 1);
  if (nc == 0) return report;

  // A = Phi_q^T (nq x nc), one column per equation, normalized, in the analysis order.
  cholmod_common cc;
  cholmod_l_start(&cc);
  cholmod_sparse* a_natural = normalized_constraint_jacobian_transpose(sys, q, &cc);
  const std::vector<SuiteSparse_long> order = analysis_order(sys, off, a_natural, &cc);
  cholmod_sparse* a = cholmod_l_submatrix(a_natural, nullptr, -1, const_cast<SuiteSparse_long*>(order.data()),
                                          nc, 1, 1, &cc);
  cholmod_l_free_sparse(&a_natural, &cc);

  // QR in that fixed column order; dead columns (norm below tol when reached) are redundant.
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
      const int j = static_cast<int>(order[perm ? perm[jj] : jj]);
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

  // Report, and say what to keep.
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    int keep_mask = 0, row = 0;
    for (int comp = 0; comp < 3; ++comp) {
      if (c.type == Constraint::Type::kPoint ? !(c.mask & (1 << comp)) : comp > 0) continue;
      if (dead[off[k] + row]) {
        report.redundant.push_back(row_label(c, row));
      } else {
        keep_mask |= 1 << comp;
      }
      ++row;
    }
    report.keep[k] = c.type == Constraint::Type::kPoint ? keep_mask : keep_mask != 0;
  }
  return report;
}

System without_redundant_constraints(const System& sys, const RedundancyReport& report) {
  if (report.keep.size() != sys.constraints.size())
    throw std::logic_error("without_redundant_constraints: the report is of another system");
  System out = sys;
  out.constraints.clear();
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    if (report.keep[k] == 0) continue;
    Constraint c = sys.constraints[k];
    if (c.type == Constraint::Type::kPoint) c.mask = report.keep[k];
    out.constraints.push_back(c);
  }
  return out;
}

}  // namespace mbdae
