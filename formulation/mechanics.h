// The pieces every formulation shares: mass matrix, gyroscopic and applied generalized forces,
// constraint values and Jacobians, and their assembly into sparse matrices.
//
// Equations of motion of body b (centre-of-mass reference, Euler parameters; Haug ch. 11):
//   m r''                                   + Phi_r^T lambda = m g + Q_r
//   4 L^T J L p'' + 8 L(p')^T J L(p) p'     + Phi_p^T lambda = Q_p
// with L = L(p) (omega_body = 2 L p'), J the body-axes inertia about the centre of mass. The
// Euler-parameter normalization p.p = 1 is one of the constraints, so the rank-3 rotational mass
// matrix 4 L^T J L is completed by its multiplier.
#pragma once

#include <vector>

#include "core/sparse_assembler.h"
#include "formulation/constraints.h"
#include "formulation/forces.h"
#include "formulation/system.h"

namespace mbdae {

// Row offsets of each constraint in the stacked constraint vector.
std::vector<int> constraint_offsets(const System& sys);

// Modes of switching forces (wheel contact: in contact) from the current state.
std::vector<char> initial_modes(const System& sys, const double* q, double t);

// out = M(q) a.
void mass_times(const System& sys, const double* q, const double* a, double* out);
// Q = gravity + applied forces - gyroscopic terms (the right side of M q'' + Phi_q^T l = Q).
// `turns`: the run's whole turns of rotation coordinates (system.h; null: nearest to the initial values).
void generalized_forces(const System& sys, const std::vector<char>& modes, const double* q,
                        const double* v, double t, double* out, const CoordinateTurns* turns = nullptr);
// Force k's generalized force on its two bodies' local coordinates [ri, pi, rj, pj] (the term
// generalized_forces() adds for it).
Vec14 force_local(const System& sys, size_t k, const std::vector<char>& modes, const double* q, const double* v,
                  double t, const CoordinateTurns* turns = nullptr);
// Body b's own rows of M(q) acc - Q: its inertia times acc, minus its weight and gyroscopic
// terms (7 values; the applied forces and constraint forces left out).
void body_momentum(const System& sys, int b, const double* q, const double* v, const double* acc, double* out);
// Stacked constraint values Phi(q, t).
void constraint_values(const System& sys, const std::vector<int>& offsets, const double* q,
                       double t, double* phi);
// Phi_t and the acceleration right side gamma = -qdot^T Phi_qq qdot - Phi_tt.
void constraint_rates(const System& sys, const std::vector<int>& offsets, const double* q,
                      const double* v, double t, double* phi_t, double* gamma);
// out += Phi_q^T lambda.
void add_constraint_forces(const System& sys, const std::vector<int>& offsets, const double* q,
                           const double* lambda, double* out);
// The local Jacobian rows of every constraint at q, constraint k's at rows[3 k ..] (rows holds
// 3 per constraint): computed once per residual evaluation (RunState's cache) and shared by the
// rows that need Phi_q (Phi_q^T lambda, GGL's Phi_q^T mu, Phi_q v).
void constraint_jacobian_rows(const System& sys, const double* q, std::vector<Row14>& rows);
// Phi_q's structural entries row by row (those assemble_constraint_jacobian adds), for products
// with the rows of constraint_jacobian_rows() without assembling Phi_q: stacked row i's entries
// are e in [rowptr[i], rowptr[i + 1]), the value rows[source[i]](local[e]) at global column col[e].
struct ConstraintRowsPattern {
  std::vector<int> rowptr, source, col;
  std::vector<unsigned char> local;
};
ConstraintRowsPattern constraint_rows_pattern(const System& sys);
// out += Phi_q^T lambda, Phi_q from constraint_jacobian_rows(), over the structural entries only
// (the entries left out are zeros): the same sums, in the same order, as over all 14 columns.
void add_constraint_forces(const ConstraintRowsPattern& p, const std::vector<Row14>& rows, const double* lambda,
                           double* out);
// out_q += Phi_q^T lambda and out_c = Phi_q a, in one pass over the rows.
void constraint_rows_products(const ConstraintRowsPattern& p, const std::vector<Row14>& rows, const double* a,
                              const double* lambda, double* out_q, double* out_c);
// out = Phi_q v.
void constraint_jacobian_times(const System& sys, const std::vector<int>& offsets,
                               const double* q, const double* v, double* out);
double max_abs(const double* x, int n);

// --- Sparse assembly (each call makes the same add() sequence whatever the values) ---------
// scale * M(q) at (row0 + i, col0 + i).
void assemble_mass(const System& sys, const double* q, double scale, int row0, int col0,
                   SparseAssembler& a);
// diag(wr, wr, wr, wp, wp, wp, wp) per body: a weighting matrix with the mass-matrix pattern.
void assemble_weights(const System& sys, double wr, double wp, int row0, int col0,
                      SparseAssembler& a);
// d(M(q) acc)/dq + d(gyro)/dq at (row0, colq) and d(gyro)/dv at (row0, colv) (scaled by `scale`).
void assemble_inertia_derivatives(const System& sys, const double* q, const double* v,
                                  const double* acc, int row0, int colq, int colv,
                                  SparseAssembler& a);
// The same derivatives times vectors without their blocks: out[i][row0 + k] += the row k of
// d(M(q) acc)/dq x_q + d(gyro)/dq x_q + d(gyro)/dv x_v, x_q and x_v at colq and colv of x[i]
// (MultibodyDae::jacobian_times).
void inertia_derivatives_times(const System& sys, const double* q, const double* v, const double* acc, int row0,
                               int colq, int colv, int count, const double* const* x, double* const* out);
// -dQ/dq at (row0, colq) and -dQ/dv at (row0, colv) for the applied forces.
void assemble_force_derivatives(const System& sys, const std::vector<char>& modes,
                                const double* q, const double* v, double t, int row0, int colq,
                                int colv, SparseAssembler& a, const CoordinateTurns* turns = nullptr);
// The same derivatives times vectors without their blocks: out[i][row0 + k] -= row k of
// dQ/dq x_q + dQ/dv x_v, x_q and x_v at colq and colv of x[i] (MultibodyDae::jacobian_times).
void force_derivatives_times(const System& sys, const std::vector<char>& modes, const double* q, const double* v,
                             double t, int row0, int colq, int colv, int count, const double* const* x,
                             double* const* out, const CoordinateTurns* turns = nullptr);
// scale * Phi_q at (row0, col0), and/or its transpose at (row0t, col0t) (negative: skip).
void assemble_constraint_jacobian(const System& sys, const std::vector<int>& offsets,
                                  const double* q, double scale, int row0, int col0, int row0t,
                                  int col0t, SparseAssembler& a);
// sum_k lambda_k d2Phi_k/dq2 at (row0, col0).
void assemble_constraint_hessian(const System& sys, const std::vector<int>& offsets,
                                 const double* q, const double* lambda, int row0, int col0,
                                 SparseAssembler& a);

}  // namespace mbdae
