#include "formulation/index1_dae.h"

#include <cmath>

#include "formulation/constraint_rates.h"
#include "formulation/mechanics.h"

namespace mbdae {

Index1Dae::Index1Dae(const System& sys, double constraint_scale, BaumgarteParameters baumgarte,
                     bool exact_gamma_q, double penalty)
    : MultibodyDae(sys), scale_(constraint_scale), bg_(baumgarte), exact_gamma_q_(exact_gamma_q) {
  if (penalty > 0) inverse_penalty_ = 1.0 / (penalty * mass_scale_);
  record_pattern();
}

int Index1Dae::residual(double t_in, const double* y, const double* yp, double* r) {
  const double t = input_time(t_in);
  kinematic_and_momentum_residual(t, y, yp, r, work_.data());
  double* f3 = r + 2 * nq_;
  stabilized_acceleration_constraints(sys_, offsets_, constraint_rows(), y, y + nq_, yp + nq_, t, bg_.alpha, bg_.beta, f3);
  // Penalty (when set): F3 = s (stabilized acceleration constraints - lambda / p).
  const double* lambda = y + 2 * nq_;
  for (int i = 0; i < nc_; ++i) f3[i] = scale_ * (f3[i] - inverse_penalty_ * lambda[i]);
  return finite_or_retry(r, size());
}

void Index1Dae::assemble(double t, double cj, const double* y, const double* yp) {
  const double* q = y;
  const double* v = y + nq_;
  const double* acc = yp + nq_;
  const int rv = nq_, ra = 2 * nq_;  // row blocks F2, F3
  const int cq = 0, cv = nq_, cl = 2 * nq_;  // column blocks q, v, lambda
  assemble_kinematic_and_momentum(t, cj, y, yp, asm_);
  // F3, q columns: s [beta^2 Phi_q + (H_k v')^T + 2 alpha (H_k v)^T (+ d(v^T H_k v)/dq)],
  // with Phi_q^T into F2's lambda columns.
  const double a = bg_.alpha, b2 = bg_.beta * bg_.beta;
  assemble_constraint_jacobian(sys_, offsets_, q, scale_ * b2, ra, cq, rv, cl, asm_);
  assemble_hessian_vector_rows(sys_, offsets_, q, acc, scale_, v, 2.0 * a * scale_, ra, cq, asm_);
  if (exact_gamma_q_)
    assemble_gamma_position_derivative_fd(sys_, offsets_, q, v, scale_, ra, cq, asm_);
  // F3, v columns: s [(cj + 2 alpha) Phi_q + 2 (H_k v)^T].
  assemble_constraint_jacobian(sys_, offsets_, q, scale_ * (cj + 2.0 * a), ra, cv, -1, -1, asm_);
  assemble_hessian_vector_rows(sys_, offsets_, q, v, 2.0 * scale_, nullptr, 0.0, ra, cv, asm_);
  // F3, lambda columns (penalty only): -s/p I.
  if (inverse_penalty_ > 0)
    for (int i = 0; i < nc_; ++i) asm_.add(ra + i, cl + i, -scale_ * inverse_penalty_);
}

void Index1Dae::derivative_times(const double* y, const double* x, double* out) {
  MultibodyDae::derivative_times(y, x, out);
  double* f3 = out + 2 * nq_;
  constraint_jacobian_times(sys_, offsets_, y, x + nq_, f3);
  for (int i = 0; i < nc_; ++i) f3[i] *= scale_;
}

void Index1Dae::error_test_mask(double* id) const {
  for (int i = 0; i < size(); ++i) id[i] = i < 2 * nq_ ? 1.0 : 0.0;
}

void Index1Dae::error_weights(double h, const double* y, double rtol, double atol, double* w) const {
  const double noise = position_noise(y);
  const double al = mass_scale_ * (atol + noise) / h;
  state_weights(h, y, rtol, atol, w);
  // v's floor at 5 roundings: its noise is a position's rounding per step, eps |r| / h (q' = v),
  // which does not add up over the steps (v is not integrated from it); at 100 the floor, not
  // rtol, set the steps' summed error from rtol 1e-9 on (docs/formulation.md, "Error control").
  // Penalty's velocities also times 1 / span_factor, as index2-ggl's: at loose rtol its phase
  // error over a long run missed the promise (docs/formulation.md, "penalty's velocities").
  error_per_unit_span(newton_step(h), newton_step(h), y, w, inverse_penalty_ > 0 ? span_factor(rtol) : 1.0, 5.0);
  for (int i = 2 * nq_; i < size(); ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + al);
}


}  // namespace mbdae
