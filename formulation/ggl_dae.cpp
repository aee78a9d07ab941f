#include "formulation/ggl_dae.h"

#include <cmath>

#include "formulation/constraint_rates.h"
#include "formulation/constraints.h"
#include "formulation/mechanics.h"

namespace mbdae {

GglDae::GglDae(const System& sys, double constraint_scale, bool velocities_in_error_test)
    : MultibodyDae(sys), scale_(constraint_scale), v_in_test_(velocities_in_error_test) {
  record_pattern();
}

int GglDae::residual(double t_in, const double* y, const double* yp, double* r) {
  const double t = input_time(t_in);
  const double* q = y;
  const double* v = y + nq_;
  const double* mu = y + 2 * nq_ + nc_;
  // F1 = q' - v + Phi_q^T mu,  F2 = M v' + Phi_q^T lambda - Q
  kinematic_and_momentum_residual(t, y, yp, r, work_.data());
  add_constraint_forces(rows_pattern_, constraint_rows(), mu, r);
  // F3 = s Phi,  F4 = s (Phi_q v + Phi_t)
  double* f3 = r + 2 * nq_;
  double* f4 = f3 + nc_;
  constraint_values(sys_, offsets_, q, t, f3);
  velocity_constraint_values(sys_, offsets_, constraint_rows(), v, t, f4);
  for (int i = 0; i < 2 * nc_; ++i) f3[i] *= scale_;
  return finite_or_retry(r, size());
}

void GglDae::assemble(double t, double cj, const double* y, const double* yp) {
  const double* q = y;
  const double* v = y + nq_;
  const double* mu = y + 2 * nq_ + nc_;
  const int rq = 0, rv = nq_, rp = 2 * nq_, rw = 2 * nq_ + nc_;  // row blocks F1..F4
  const int cq = 0, cv = nq_, cl = 2 * nq_, cm = 2 * nq_ + nc_;  // column blocks q, v, lambda, mu
  // F1: cj I, -I (shared), sum mu_k H_k, Phi_q^T (mu columns).
  // F2: cj M, d(M v')/dq and gyroscopic derivatives, -dQ/dq, -dQ/dv, sum lambda_k H_k (shared),
  // Phi_q^T (lambda columns).
  assemble_kinematic_and_momentum(t, cj, y, yp, asm_);
  assemble_constraint_hessian(sys_, offsets_, q, mu, rq, cq, asm_);
  // F3: s Phi_q (q columns), with Phi_q^T into F1's mu columns.
  assemble_constraint_jacobian(sys_, offsets_, q, scale_, rp, cq, rq, cm, asm_);
  // F4: s Phi_q (v columns), with Phi_q^T into F2's lambda columns; s (H_k v)^T (q columns).
  assemble_constraint_jacobian(sys_, offsets_, q, scale_, rw, cv, rv, cl, asm_);
  assemble_hessian_vector_rows(sys_, offsets_, q, v, scale_, nullptr, 0.0, rw, cq, asm_);
}

void GglDae::jacobian_times(double t_in, const double* y, const double* yp, int count, const double* const* x,
                            double* const* out) {
  const double t = input_time(t_in);
  const double* q = y;
  const double* v = y + nq_;
  const double* lambda = y + 2 * nq_;
  const double* mu = lambda + nc_;
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < nq_; ++j) out[i][j] -= x[i][nq_ + j];  // F1: -I (v columns)
  // F2: d(M v')/dq and the gyroscopic derivatives in closed form, the applied forces' local
  // Jacobians times the local x.
  inertia_derivatives_times(sys_, q, v, yp + nq_, nq_, 0, nq_, count, x, out);
  force_derivatives_times(sys_, state_.modes, q, v, t, nq_, 0, nq_, count, x, out, &state_.turns);
  Row14 rows[3];
  Mat14 h[3];
  for (size_t k = 0; k < sys_.constraints.size(); ++k) {
    const Constraint& c = sys_.constraints[k];
    const LocalState s = gather(q, c.bi, c.bj);
    constraint_jacobian(c, s, rows);
    bool have_h = false;  // the row Hessians, computed once where the type has no closed form
    const Vec14 vl = gather_local(v, c.bi, c.bj);
    const int o = offsets_[k];
    for (int i = 0; i < count; ++i) {
      const double* xi = x[i];
      double* oi = out[i];
      const Vec14 xq = gather_local(xi, c.bi, c.bj), xv = gather_local(xi + nq_, c.bi, c.bj);
      Vec14 f1 = Vec14::Zero(), f2 = Vec14::Zero();
      double g[3];
      constraint_hessian_terms(c, s, xq, vl, mu + o, lambda + o, f1, f2, g, h, have_h);
      for (int r = 0; r < c.rows(); ++r) {
        const int row = o + r;
        f1 += xi[2 * nq_ + nc_ + row] * rows[r].transpose();           // Phi_q^T x_mu
        f2 += xi[2 * nq_ + row] * rows[r].transpose();                 // Phi_q^T x_lambda
        oi[2 * nq_ + row] += scale_ * rows[r].dot(xq);                 // F3: s Phi_q x_q
        oi[2 * nq_ + nc_ + row] += scale_ * (rows[r].dot(xv) + g[r]);  // F4: s (Phi_q x_v + (H v)^T x_q)
      }
      for (int l = 0; l < 14; ++l) {
        const int gl = global_index(c.bi, c.bj, l);
        if (gl < 0) continue;
        oi[gl] += f1[l];
        oi[nq_ + gl] += f2[l];
      }
    }
  }
}

void GglDae::constraint_terms(double t_in, const double* y, int k, ConstraintTerms& out) const {
  const double t = input_time(t_in);
  const Constraint& c = sys_.constraints[k];
  const LocalState s = gather(y, c.bi, c.bj);
  Row14 rows[3];
  double phi[3], rates[3];
  constraint_jacobian(c, s, rows);
  constraint_value(c, s, t, phi);
  velocity_rows(c, rows, y + nq_, t, rates);
  const double* lambda = y + 2 * nq_ + offsets_[k];
  const double* mu = y + 2 * nq_ + nc_ + offsets_[k];
  out.f1.setZero();
  out.f2.setZero();
  for (int r = 0; r < c.rows(); ++r) {
    out.f1 += mu[r] * rows[r].transpose();
    out.f2 += lambda[r] * rows[r].transpose();
    out.rows[0][r] = scale_ * phi[r];
    out.rows[1][r] = scale_ * rates[r];
  }
}

void GglDae::error_test_mask(double* id) const {
  for (int i = 0; i < size(); ++i) id[i] = i < nq_ || (v_in_test_ && i < 2 * nq_) ? 1.0 : 0.0;
}

void GglDae::error_weights(double h, const double* y, double rtol, double atol, double* w) const {
  const double noise = position_noise(y);
  const double aq = position_atol(y, atol);
  const double av = atol + noise / h;  // v out of the test: the Newton test's floor only
  const double al = mass_scale_ * (atol + noise / h) / h;
  const double am = (atol + noise) / h;
  if (v_in_test_) {
    state_weights(h, y, rtol, atol, w);
    // The floor of v: GGL's v carries a position's rounding per step (eps |r| / h, through
    // q' = v + Phi_q^T mu), noise that adds up over the S / h steps as a random walk, to
    // eps |r| / h sqrt(S / h): a velocity tolerance below eps |r| / sqrt(h S) would ask the
    // run's summed errors for less than that noise (docs/formulation.md, "Error control").
    const double step = newton_step(h);
    // Its velocity errors add up into the positions over the run as well (a drifting phase):
    // the velocities' per-unit-span tolerance times 1 / span_factor (docs/formulation.md).
    error_per_unit_span(step, std::sqrt(step * absolute_tolerances().span), y, w, span_factor(rtol));
  } else {
    position_weights(y, rtol, aq, w);
    for (int i = nq_; i < 2 * nq_; ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + av);
  }
  for (int i = 2 * nq_; i < 2 * nq_ + nc_; ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + al);
  for (int i = 2 * nq_ + nc_; i < size(); ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + am);
}

std::string GglDae::component_name(int i) const {
  if (i < 2 * nq_ + nc_) return MultibodyDae::component_name(i);
  return "velocity-constraint multiplier (mu) of " + constraint_label(i - 2 * nq_ - nc_);
}


}  // namespace mbdae
