// Velocity- and acceleration-level constraint quantities and their derivatives, for the
// formulations that differentiate the constraints (index-2 GGL, index-1 with Baumgarte).
//
// With Phi(q, t) the stacked constraint rows, H_i = d2Phi_i/dq2 (symmetric) and Phi_t a function
// of t alone (drivers f(t); Phi_qt = 0 for every constraint type):
//   velocity level      Phi_q v + Phi_t                       d/dq: row i = (H_i v)^T
//   acceleration level  Phi_q a - gamma,  gamma = -v^T H v - Phi_tt
//                                                              d/dq of Phi_q a: row i = (H_i a)^T
//                                                              d(gamma_i)/dv = -2 (H_i v)^T
// d(gamma_i)/dq = -d(v^T H_i(q) v)/dq needs third derivatives of the constraints, which the
// constraint library does not provide; it is available here only by central differences of the
// (exact) local Hessians.
#pragma once

#include <vector>

#include "core/sparse_assembler.h"
#include "formulation/body_point.h"
#include "formulation/system.h"

namespace mbdae {

// H_r = d2(Phi_r)/dq2 (local 14 x 14) of each of constraint c's rows r at s.
void row_hessians(const Constraint& c, const LocalState& s, Mat14* h);
// Phi_q v + Phi_t of constraint c's rows, its Jacobian rows given (v global).
void velocity_rows(const Constraint& c, const Row14* rows, const double* v, double t, double* out);
// The Hessian terms of constraint c's rows along x (local, like v): f1 += sum_r mu_r H_r x,
// f2 += sum_r lambda_r H_r x and g[r] = v^T H_r x. In closed form where the type has one
// (constraint_hessian_products, constraints.h), else from the row Hessians h[3]: computed at the
// first call for the constraint's state (have_h false, then set) and reused for the next x.
void constraint_hessian_terms(const Constraint& c, const LocalState& s, const Vec14& x, const Vec14& v,
                              const double* mu, const double* lambda, Vec14& f1, Vec14& f2, double* g, Mat14* h,
                              bool& have_h);

// Phi_q v + Phi_t (the velocity-level constraints).
void velocity_constraint_values(const System& sys, const std::vector<int>& offsets,
                                const double* q, const double* v, double t, double* out);
// The same with Phi_q from constraint_jacobian_rows() (mechanics.h) at the q of the residual.
void velocity_constraint_values(const System& sys, const std::vector<int>& offsets,
                                const std::vector<Row14>& rows, const double* v, double t, double* out);
// Baumgarte-stabilized acceleration-level constraints, in one pass over the constraints, Phi_q
// from constraint_jacobian_rows() at q:
//   out = Phi_q a - gamma(q, v, t) + 2 alpha (Phi_q v + Phi_t) + beta^2 Phi(q, t).
void stabilized_acceleration_constraints(const System& sys, const std::vector<int>& offsets,
                                         const std::vector<Row14>& rows, const double* q,
                                         const double* v, const double* a, double t, double alpha,
                                         double beta, double* out);

// --- Sparse assembly (the same add() sequence whatever the values) -------------------------
// Row i of  s1 (H_i w1)^T + s2 (H_i w2)^T  at (row0 + i, col0 + global column); w2 may be null
// (then s2 is ignored). This is s1 d(Phi_q w1)/dq + s2 d(Phi_q w2)/dq for w1, w2 held fixed.
void assemble_hessian_vector_rows(const System& sys, const std::vector<int>& offsets,
                                  const double* q, const double* w1, double s1, const double* w2,
                                  double s2, int row0, int col0, SparseAssembler& a);
// scale * d(v^T H_i(q) v)/dq (= -scale * d(gamma_i)/dq) by central differences of the local
// Hessians (step 1e-6 |q|-relative); the pattern is that of assemble_hessian_vector_rows.
void assemble_gamma_position_derivative_fd(const System& sys, const std::vector<int>& offsets,
                                           const double* q, const double* v, double scale,
                                           int row0, int col0, SparseAssembler& a);

}  // namespace mbdae
