// Index-1 (acceleration-level) formulation of a multibody system in absolute coordinates,
// with Baumgarte stabilization, for IDA:
//   y = [q, v, lambda],  y' = [q', v', -] (lambda' unused)
//   F1 = q' - v                                                       = 0
//   F2 = M(q) v' + Phi_q^T lambda - Q(q, v, t)                        = 0
//   F3 = s [Phi_q v' - gamma + 2 alpha (Phi_q v + Phi_t) + beta^2 Phi] = 0
// gamma = -v^T (d2Phi/dq2) v - Phi_tt, so F3 is Phi'' + 2 alpha Phi' + beta^2 Phi = 0 along
// the solution: the constraints and their rates are not enforced, only their second derivative,
// and a violation (initial error, each step's local error) decays like exp(-alpha t) (critically
// damped when alpha = beta) instead of growing linearly (velocity drift) and quadratically
// (position drift) as it does with alpha = beta = 0.
//
// Baumgarte rather than projection after steps: the stabilization lives inside the residual, so
// IDA's step history, interpolation and error estimates stay those of one smooth DAE (a
// projection after each step would change the solution behind IDA's back and invalidate its
// history). The exact solution does not depend on alpha and beta.
//
// alpha, beta [1/s] (defaults 20, 20, critically damped): the steady drift is about the
// per-unit-time local error divided by beta^2, and the stabilization adds eigenvalues
// -alpha +- sqrt(alpha^2 - beta^2) to the constraint directions. BDF is stable for them, but q
// and v are in the error test, so a fast violation mode must still be resolved: measured on the
// compound pendulum over 30 s at rtol 1e-6 (formulations_test ConstraintDrift and a sweep):
//   alpha = beta = 0: max |Phi| 2.7e-3 and growing;  1: 2e-5;  5: 2e-6;  20: 6e-7;
//   100: 4e-7 (steps +7 %);  1000: 4e-7 but 1.8x the steps;  1e4: 100x the steps.
// On the suspension (dynamics I, 1.5 s) 0..500 /s change steps by < 2 %. 20/s damps a
// violation within ~0.25 s and stays far below 1/h of typical steps.
//
// Error test: q and v (both differential at index 1); lambda is algebraic and left out.
//
// The Jacobian dF/dy + cj dF/dy' is exact except for one block: d(gamma)/dq = -d(v^T H_k(q) v)/dq
// needs third derivatives of the constraints, which are not available. By default
// (exact_gamma_q = false) it is left out of the Newton matrix: this changes the Newton
// iteration matrix only, never the residual (so not the solution), and is small next to the
// cj^2 Phi_q the F3 rows carry effectively (relative size ~ h^2 |v|^2 |d3Phi| / |Phi_q|).
// formulations_test measures its size (random state, |v| ~ 1, cj = 37: 16 % of the F3 q-column
// block, 3e-3 of cj |F3 v-columns|). With exact_gamma_q = true it is computed by central
// differences of the local Hessians; on the suspension (dynamics I) both take the same Newton
// iterations to within 1 % (3246 vs 3236 at rtol 1e-8, 4577 vs 4531 at 1e-10), no failures.
// (Point and norm rows have constant Hessians: their block is exactly zero.)
// All other blocks are exact: F3 in q columns: s [(H_k v')^T + 2 alpha (H_k v)^T + beta^2 Phi_q],
// in v columns: s [2 (H_k v)^T + (cj + 2 alpha) Phi_q].
//
// Penalty (formulation "penalty"; Bayo, Garcia de Jalon and Serna 1988, the penalty form the
// augmented-Lagrangian ALI3-P of Bayo and Ledesma 1996 builds on): with penalty > 0,
//   F3 = s [Phi_q v' - gamma + 2 alpha Phi' + beta^2 Phi - lambda / p],   p = penalty m_ref,
// i.e. lambda = p (Phi'' + 2 alpha Phi' + beta^2 Phi): the constraint forces are penalty forces
// on the stabilized constraint dynamics. The multipliers stay unknowns (and outputs); in the
// Newton matrix, whose F2 and F3 rows are [cj M .. , Phi_q^T; s cj Phi_q .. , -s/p I],
// eliminating lambda leaves cj M + p cj Phi_q^T Phi_q (+ derivatives): positive definite also
// where Phi_q loses rank (singular configurations), where the index-3, GGL and plain index-1
// matrices are singular (M + p Phi_q^T Phi_q is definite when every direction of zero kinetic
// energy is constrained: Euler-parameter norms, the axial rotation of a slender rod). Initial
// values: a and lambda of the exact constraints (their F3 residual, s |lambda| / p, is removed
// by the first Newton iteration). The price: the constraints hold up to the penalty's bias,
// Phi'' + 2 alpha Phi' + beta^2 Phi = lambda / p, so |Phi| ~ |lambda| / (p beta^2) in steady
// state (A02: p = 1e7 kg, beta = 1000/s, |lambda| ~ 1e2 N: 1e-11 m). Near a singular
// configuration a violation Phi_u along the row direction u being lost becomes a motion
// Phi_u / sigma of the mode that u stops constraining (sigma the vanishing singular value of
// Phi_q), so the bias must be small: large p beta^2 (A02 measurements in docs/formulation.md).
// penalty = 0: the exact index-1 equations (no term, no pattern entry).
#pragma once

#include "core/sparse_assembler.h"
#include "formulation/multibody_dae.h"

namespace mbdae {

struct BaumgarteParameters {
  double alpha = 20.0;  // [1/s] velocity feedback: 2 alpha (Phi_q v + Phi_t)
  double beta = 20.0;   // [1/s] position feedback: beta^2 Phi
};

class Index1Dae : public MultibodyDae {
 public:
  // penalty: the factor of the largest body mass giving p (0: exact index-1 equations).
  explicit Index1Dae(const System& sys, double constraint_scale = 1.0,
                     BaumgarteParameters baumgarte = {}, bool exact_gamma_q = false, double penalty = 0.0);

  int size() const override { return 2 * nq_ + nc_; }
  int residual(double t, const double* y, const double* yp, double* r) override;
  void error_test_mask(double* id) const override;
  // Positions rtol|q| + atol, velocities rtol|v| + atol (atol floored at ten roundings of the
  // largest |q|, |v|), both per unit of the run's span (error_per_unit_span: times h / S, when
  // the model's tolerances are set); the index-1 multipliers follow the accelerations, whose error is that
  // of v over h: rtol|lambda| + m_ref (atol + noise)/h.
  void error_weights(double h, const double* y, double rtol, double atol, double* w) const override;

  // Positions and velocities projected onto the constraints, v' and lambda from the
  // accelerations; y' = [v, v', 0].
  void consistent_initial_values(double t, std::vector<double>& y, std::vector<double>& yp) override;

  bool velocities_error_tested() const override { return true; }
  const BaumgarteParameters& baumgarte() const { return bg_; }
  // 1/p of the penalty term (0 without penalty).
  double inverse_penalty() const { return inverse_penalty_; }

 private:
  void assemble(double t, double cj, const double* y, const double* yp) override;
  double scale_;
  BaumgarteParameters bg_;
  bool exact_gamma_q_;
  double inverse_penalty_ = 0.0;
};

}  // namespace mbdae
