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
};

// Analyzes Phi_q at q (t for drivers); with `remove`, drops the redundant equations from sys
// (a point constraint keeps its independent components).
RedundancyReport find_redundant_constraints(System& sys, const double* q, double t, bool remove,
                                            double tolerance = 1e-9);

}  // namespace mbdae
