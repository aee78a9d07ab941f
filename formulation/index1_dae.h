// Index-1 (acceleration-level) formulation of a multibody system in absolute coordinates,
// with Baumgarte stabilization, for IDA:
//   y = [q, v, lambda],  y' = [q', v', -] (lambda' unused)
//   F1 = q' - v                                                       = 0
//   F2 = M(q) v' + Phi_q^T lambda - Q(q, v, t)                        = 0
//   F3 = s [Phi_q v' - gamma + 2 alpha (Phi_q v + Phi_t) + beta^2 Phi] = 0
// gamma = -v^T (d2Phi/dq2) v - Phi_tt, so F3 is Phi'' + 2 alpha Phi' + beta^2 Phi = 0 along the
// solution: a violation decays like exp(-alpha t) instead of drifting. The stabilization lives
// inside the residual (not a projection after steps), so IDA's history and error estimates stay
// those of one smooth DAE; the exact solution does not depend on alpha and beta.
// Error test: q and v; lambda is algebraic and left out.
//
// The Newton matrix is exact except d(gamma)/dq = -d(v^T H_k(q) v)/dq (third derivatives of the
// constraints): left out by default (exact_gamma_q = false), which changes the Newton matrix only,
// never the residual; with exact_gamma_q = true it comes from central differences of the local
// Hessians. F3 in q columns: s [(H_k v')^T + 2 alpha (H_k v)^T + beta^2 Phi_q], in v columns:
// s [2 (H_k v)^T + (cj + 2 alpha) Phi_q].
//
// Penalty (formulation "penalty"; Bayo, Garcia de Jalon and Serna 1988): with penalty > 0,
//   F3 = s [Phi_q v' - gamma + 2 alpha Phi' + beta^2 Phi - lambda / p],   p = penalty m_ref,
// i.e. lambda = p (Phi'' + 2 alpha Phi' + beta^2 Phi). Eliminating lambda from the Newton matrix
// leaves cj M + p cj Phi_q^T Phi_q (+ derivatives), definite also where Phi_q loses rank
// (singular configurations); the constraints then hold up to the bias |Phi| ~ |lambda| / (p beta^2).
// penalty = 0: the exact index-1 equations (no term, no pattern entry).
// Measurements of alpha, beta, exact_gamma_q and the penalty: docs/formulation.md, "The index-1
// and penalty formulations".
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


  bool velocities_error_tested() const override { return true; }
  // F_y' x with this formulation's rows, s Phi_q x_v (their v' term).
  void derivative_times(const double* y, const double* x, double* out) override;
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
