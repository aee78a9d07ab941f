// Redundant constraint equations: rows of the constraint Jacobian that depend linearly on the
// rows before them. Found by a sparse rank-revealing QR (SuiteSparseQR, Heath's method, columns in
// a fixed order) of Phi_q^T with every row scaled to unit norm. The order: the tree's equations
// (Euler norms, tree joints, locks, drives) in a fill-reducing order (CCOLAMD; linear on trees),
// then cuts and holds in their natural order, so that the equations reported are the last cut
// equations of each dependent set.
#pragma once

#include <string>
#include <vector>

#include "formulation/system.h"

namespace mbdae {

struct RedundancyReport {
  int equations = 0, rank = 0;
  std::vector<std::string> redundant;  // labels of the redundant equations ("<label> [row k]")
  // Per constraint of the analysed system, the rows to keep: a point constraint's component
  // mask (bit k: component k), 1 for other constraints; 0 drops the constraint.
  std::vector<int> keep;
};

// Analyzes Phi_q at q (t for drivers). The system is not changed: what to remove is returned.
RedundancyReport find_redundant_constraints(const System& sys, const double* q, double t,
                                            double tolerance = 1e-9);

// The former (System&, q, t, bool remove) form: refused at compile time (a bool would silently
// become the tolerance).
RedundancyReport find_redundant_constraints(const System& sys, const double* q, double t, bool remove) = delete;

// A new System: `sys` without the redundant equations of `report` (found on `sys`); a point
// constraint keeps its independent components.
System without_redundant_constraints(const System& sys, const RedundancyReport& report);

}  // namespace mbdae
