// Diagnosis of a singular configuration: the constraint equations that become linearly dependent
// at a configuration where the constraint Jacobian Phi_q (nearly) loses rank, for example a
// kinematic drive pushed to the end of the mechanism's travel.
//
// With the rows of Phi_q scaled to unit norm (D Phi_q), the smallest singular value s_min and its
// left singular vector y (one weight per equation, y^T D Phi_q = s_min u^T) are found by inverse
// iteration on (D Phi_q Phi_q^T D)^-1 with a sparse QR of (D Phi_q)^T (SuiteSparseQR, as the
// redundancy check). y is the combination of equations that stops constraining anything: the
// equations with a large |y_i| are those that lose rank (physically, the joints that carry a
// self-stressed reaction, a "dead centre"). Equations left out of the combination (|y_i| = 0)
// are untouched by the singularity. Euler-parameter norm rows take part whenever a loaded point
// constraint does (A s is quadratic in p: its rows have a component along p that the norm's
// multiplier balances); they are the bodies' own equations, not joints.
#pragma once

#include <string>
#include <vector>

#include "formulation/system.h"

namespace mbdae {

struct DependentEquation {
  std::string label;  // the constraint's label ("<label> [x]" for one row of a point constraint)
  double weight = 0;  // |y_i| / max_j |y_j|
  std::string group;  // what it belongs to (constraint_group: "joint rod2_mount", "drive q4")
  Constraint::Owner owner = Constraint::Owner::kJoint;  // the kind of that owner
};

struct SingularityReport {
  int equations = 0;
  int rank = 0;                       // numerical rank of D Phi_q (SuiteSparseQR's default tolerance)
  double smallest_singular_value = 0;  // s_min of D Phi_q (0 if rank < equations)
  double largest_singular_value = 0;   // estimate (power iteration), for the ratio
  std::vector<DependentEquation> dependent;  // weight >= min_weight, largest first
  // The joints, cuts, drives and bodies those equations belong to ("joint rod2_mount",
  // "cut ball2", "drive q4", "body rod3"), in order of their largest weight.
  std::vector<std::string> constraints;
};

// Analyzes Phi_q at (q, t). Exact dependencies (rank < equations) are named like the redundancy
// check does (the last equation of each dependent set, weight 1).
SingularityReport diagnose_singularity(const System& sys, const double* q, double t,
                                       double min_weight = 0.05);

// Whether a singular Jacobian of the kept equations is the mechanism's or the choice of equations
// set aside: `all` is the system with every equation (as built), `kept` the one integrated. At q
// the equations of `all` are chosen again (choose_independent_equations); the choice has
// degraded where the kept equations are (nearly) singular, s_min / s_max below `singular_ratio`,
// while the new choice sets aside as many equations and is not (made at looser rank tolerances
// where the default one sets aside fewer: a row nearly dependent near that instant).
struct EquationChoiceCheck {
  bool degraded = false;
  double kept_ratio = 0;      // s_min / s_max of the kept equations' row-normalized Jacobian
  double rechosen_ratio = 0;  // the same for the equations chosen again at q
  int set_aside = 0, set_aside_again = 0;  // how many equations each choice sets aside
  std::vector<std::string> rechosen;       // the equations the new choice sets aside
};
EquationChoiceCheck check_equation_choice(const System& all, const System& kept, const double* q, double t,
                                          double singular_ratio);

}  // namespace mbdae
