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
  std::vector<int> redundant_constraint;  // for each of them, its constraint's index in sys.constraints
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

// The equations to keep, chosen so that the choice stays valid as the mechanism moves. A cut's
// coincident-point equations are written in world components; in a loop whose plane turns (a
// four-bar on a turntable, a governor's pinned links) the dependent combination is a body-fixed
// direction (the loop's normal), so a choice of world components made at one configuration goes
// singular a quarter turn later. Here the point equations of every cut with some (not all) of
// its point components redundant are first re-expressed as three point-on-plane (dot-2) rows
// along a frame fixed in one of the cut's bodies (z along the cut's axis1 where it has one), then
// the redundancy analysis runs again: the rows set aside are then the loop's own out-of-plane
// rows in every configuration of a planar loop. Other cuts are left exactly as built.
struct EquationChoice {
  System system;                         // the equations kept
  RedundancyReport report;               // the analysis of the re-expressed system
  std::vector<std::string> reexpressed;  // the cuts whose point equations were re-expressed
};
EquationChoice choose_independent_equations(const System& sys, const double* q, double t,
                                            double tolerance = 1e-9);

// `sys` with the coincident-point equations of the named cuts re-expressed in a body frame, as
// choose_independent_equations does (the same solutions, other rows).
System with_body_frame_cut_points(const System& sys, const std::vector<std::string>& cuts);

}  // namespace mbdae
