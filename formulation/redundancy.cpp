#include "formulation/redundancy.h"

#include <SuiteSparseQR.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

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
        report.redundant_constraint.push_back(static_cast<int>(k));
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

namespace mbdae {
namespace {

// The first dot-1 row of each cut (a revolute's or universal's axis1 on body i), by cut name.
using CutAxes = std::unordered_map<std::string, const Constraint*>;
CutAxes cut_axes(const System& sys) {
  CutAxes out;
  for (const Constraint& d : sys.constraints)
    if (d.owner == Constraint::Owner::kCut && d.type == Constraint::Type::kDot1) out.emplace(d.owner_name, &d);
  return out;
}

// The cut's frame for its point rows: on body i unless it is ground (then body j, sides
// swapped), z along the cut's dot-1 axis on that side (a revolute's or universal's axis1), else
// the body's own axes. `names` gets the rows' labels.
Constraint frame_side(const System& sys, const CutAxes& dot1, const Constraint& pt, Mat3& axes,
                      std::array<std::string, 3>& names) {
  Constraint c = pt;
  const bool swap = pt.bi < 0;
  if (swap) {
    std::swap(c.bi, c.bj);
    std::swap(c.si, c.sj);
  }
  axes = Mat3::Identity();
  for (int k = 0; k < 3; ++k) names[k] = sys.bodies[c.bi].name + " " + "xyz"[k];
  const auto it = dot1.find(pt.owner_name);
  if (swap || it == dot1.end() || it->second->bi != pt.bi) return c;
  const Vec3 z = it->second->ai.normalized(), x = z.unitOrthogonal();
  axes.col(0) = x;
  axes.col(1) = z.cross(x);
  axes.col(2) = z;
  names = {"across axis1 (1)", "across axis1 (2)", "along axis1"};
  return c;
}

}  // namespace

System with_body_frame_cut_points(const System& sys, const std::vector<std::string>& cuts) {
  const std::unordered_set<std::string> picked(cuts.begin(), cuts.end());
  const CutAxes dot1 = cut_axes(sys);
  System out = sys;
  out.constraints.clear();
  for (const Constraint& c : sys.constraints) {
    const bool pick = c.owner == Constraint::Owner::kCut && c.type == Constraint::Type::kPoint &&
                      picked.count(c.owner_name) && (c.bi >= 0 || c.bj >= 0);
    if (!pick) {
      out.constraints.push_back(c);
      continue;
    }
    Mat3 axes;
    std::array<std::string, 3> names;
    const Constraint side = frame_side(sys, dot1, c, axes, names);
    // One dot-2 row per frame axis (a cut's point constraint has all three components).
    for (int k = 0; k < 3; ++k) {
      Constraint r = side;
      r.type = Constraint::Type::kDot2;
      r.ai = axes.col(k);
      r.mask = 7;
      r.label = c.label + " [" + names[k] + "]";
      out.constraints.push_back(r);
    }
  }
  return out;
}

EquationChoice choose_independent_equations(const System& sys, const double* q, double t, double tolerance) {
  EquationChoice out;
  const RedundancyReport first = find_redundant_constraints(sys, q, t, tolerance);
  // Cuts whose point equations are partly redundant: which components are kept depends on the
  // frame they are written in. (All three redundant: the cut repeats a joint, in any frame.)
  std::unordered_set<std::string> seen;
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    if (c.owner != Constraint::Owner::kCut || c.type != Constraint::Type::kPoint) continue;
    if (first.keep[k] == 0 || first.keep[k] == c.mask) continue;
    if (seen.insert(c.owner_name).second) out.reexpressed.push_back(c.owner_name);
  }
  if (out.reexpressed.empty()) {
    out.system = without_redundant_constraints(sys, first);
    out.report = first;
    return out;
  }
  const System body_frame = with_body_frame_cut_points(sys, out.reexpressed);
  out.report = find_redundant_constraints(body_frame, q, t, tolerance);
  out.system = without_redundant_constraints(body_frame, out.report);
  return out;
}

}  // namespace mbdae
