// Redundant constraint equations: rows of the constraint Jacobian that depend linearly on the
// rows before them. Found by a sparse rank-revealing QR (SuiteSparseQR, Heath's method, columns in
// their natural order) of Phi_q^T with every row scaled to unit norm, so that the equations
// reported are the last ones of each dependent set (cuts come after tree joints).
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
