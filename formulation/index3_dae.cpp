#include "formulation/index3_dae.h"

#include <cmath>

#include "core/finite_check.h"
#include "formulation/mechanics.h"

namespace mbdae {

Index3Dae::Index3Dae(const System& sys, double constraint_scale, bool error_per_unit_step)
    : MultibodyDae(sys), scale_(constraint_scale), per_unit_step_(error_per_unit_step) {
  record_pattern();
}

int Index3Dae::residual(double t_in, const double* y, const double* yp, double* r) {
  const double t = input_time(t_in);
  kinematic_and_momentum_residual(t, y, yp, r, work_.data());
  double* f3 = r + 2 * nq_;
  constraint_values(sys_, offsets_, y, t, f3);
  for (int i = 0; i < nc_; ++i) f3[i] *= scale_;
  return finite_or_retry(r, size());
}

void Index3Dae::assemble(double t, double cj, const double* y, const double* yp) {
  assemble_kinematic_and_momentum(t, cj, y, yp, asm_);
  // F3: s Phi_q (q columns), with Phi_q^T into F2's lambda columns.
  const int rv = nq_, rl = 2 * nq_, cq = 0, cl = 2 * nq_;
  assemble_constraint_jacobian(sys_, offsets_, y, scale_, rl, cq, rv, cl, asm_);
}

void Index3Dae::error_test_mask(double* id) const {
  for (int i = 0; i < size(); ++i) id[i] = i < nq_ ? 1.0 : 0.0;
}

void Index3Dae::error_weights(double h, const double* y, double rtol, double atol, double* w) const {
  // Rounding in the positions (about 1e3 eps |q|, through the constraints) reaches the Newton
  // corrections of v and lambda amplified by 1/h and 1/h^2: that noise floor, not the user's
  // atol, bounds how tightly they can converge.
  const double noise = position_noise(y);
  const double av = atol + noise / h, al = mass_scale_ * (atol + noise / (h * h));
  if (per_unit_step_ && abs_tol_.set()) {
    state_weights(h, y, rtol, atol, w);
    velocity_error_per_unit_step(newton_step(h), y, rtol, w);
  } else {
    position_weights(y, rtol, position_atol(y, atol), w);
  }
  for (int i = nq_; i < 2 * nq_; ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + av);
  for (int i = 2 * nq_; i < size(); ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + al);
}

void Index3Dae::velocity_error_per_unit_step(double h, const double* y, double rtol, double* w) const {
  // Tolerances of q times (h/T)^2 c (c = span_factor(rtol)), never below the rounding of the
  // coordinates (1e3 eps of the model's positions, 1e3 eps for Euler parameters), never looser
  // than the plain test.
  const double r = abs_tol_.time / h, f = max_num(1.0, r * r * span_factor(rtol));
  const double w_length = 1.0 / (kRoundingFloor * position_magnitude(y)), w_rotation = 1.0 / kRoundingFloor;
  int floored = 0;
  for (int i = 0; i < nq_; ++i) {
    const double wanted = w[i] * f, floor = max_num(w[i], i % 7 < 3 ? w_length : w_rotation);
    floored += wanted > floor;
    w[i] = min_num(wanted, floor);
  }
  count_floor(floored);
}


}  // namespace mbdae
