#include "formulation/multibody_dae.h"

#include <algorithm>
#include <cstdio>

#include "core/errors.h"
#include "core/finite_check.h"
#include "formulation/constraint_rates.h"
#include "formulation/mechanics.h"

namespace mbdae {

MultibodyDae::MultibodyDae(const System& sys)
    : sys_(sys), offsets_(constraint_offsets(sys)), nq_(sys.nq()), nc_(offsets_.back()),
      rows_pattern_(constraint_rows_pattern(sys)), aug_(sys) {
  state_.modes = initial_modes(sys, sys.q0.data(), 0.0);
  state_.turns = initial_turns(sys);
  aug_.turns = &state_.turns;
  for (const auto& b : sys.bodies) mass_scale_ = max_num(mass_scale_, b.mass);
  for (size_t k = 0; k < sys.forces.size(); ++k)
    if (force_has_switch(sys.forces[k])) switch_forces_.push_back(static_cast<int>(k));
  switch_offsets_.assign(switch_forces_.size(), 0.0);
  stat_work_.resize(std::max(nq_, nc_));
  out_phi_.resize(nc_);
}

std::string MultibodyDae::constraint_label(int row) const {
  for (size_t c = 0; c < sys_.constraints.size(); ++c)
    if (row < offsets_[c + 1]) return sys_.constraints[c].label;
  return "row " + std::to_string(row);
}

void MultibodyDae::consistent_initial_values(double t, std::vector<double>& y, std::vector<double>& yp) {
  double* q = y.data();
  double* v = y.data() + nq_;
  std::fill(yp.begin(), yp.end(), 0.0);
  consistent_state(t, q, v, yp.data() + nq_, y.data() + 2 * nq_);
  std::copy(v, v + nq_, yp.begin());
  std::fill(y.begin() + 2 * nq_ + nc_, y.end(), 0.0);  // further unknowns (GGL's mu)
}

void MultibodyDae::derivative_times(const double* y, const double* x, double* out) {
  std::copy(x, x + nq_, out);
  mass_times(sys_, y, x + nq_, out + nq_);
  std::fill(out + 2 * nq_, out + size(), 0.0);
}

void MultibodyDae::jacobian_times(double t, const double* y, const double* yp, int count, const double* const* x,
                                  double* const* out) {
  asm_.begin_product(count, x, out);
  assemble(input_time(t), 0.0, y, yp);
  asm_.end_product();
}

void MultibodyDae::record_pattern() {
  work_.resize(size());
  std::vector<double> y(size(), 0.0), yp(size(), 0.0);
  std::copy(sys_.q0.begin(), sys_.q0.end(), y.begin());
  asm_.begin_pattern(size(), size());
  assemble(0.0, 1.0, y.data(), yp.data());
  asm_.finalize();
}

int MultibodyDae::jacobian(double t_in, double cj, const double* y, const double* yp, double* values) {
  newton_cj_ = cj;
  asm_.begin_values(values);
  assemble(input_time(t_in), cj, y, yp);
  asm_.end_values();  // throws if the calls differ from the pattern's (the driver reports it)
  return 0;
}

void MultibodyDae::kinematic_and_momentum_residual(double t, const double* y, const double* yp,
                                                   double* r, double* force_work) {
  const double* q = y;
  const double* v = y + nq_;
  const double* lambda = y + 2 * nq_;
  for (int i = 0; i < nq_; ++i) r[i] = yp[i] - v[i];
  double* f2 = r + nq_;
  mass_times(sys_, q, yp + nq_, f2);
  generalized_forces(sys_, state_.modes, q, v, t, force_work, &state_.turns);
  for (int i = 0; i < nq_; ++i) f2[i] -= force_work[i];
  constraint_jacobian_rows(sys_, q, state_.cache.constraint_rows);
  add_constraint_forces(rows_pattern_, state_.cache.constraint_rows, lambda, f2);
}

void MultibodyDae::assemble_kinematic_and_momentum(double t, double cj, const double* y,
                                                   const double* yp, SparseAssembler& a) const {
  const double* q = y;
  const double* v = y + nq_;
  const double* lambda = y + 2 * nq_;
  const int rq = 0, rv = nq_;  // row blocks F1, F2
  const int cq = 0, cv = nq_;  // column blocks q, v
  for (int i = 0; i < nq_; ++i) {
    a.add(rq + i, cq + i, cj);
    a.add(rq + i, cv + i, -1.0);
  }
  assemble_mass(sys_, q, cj, rv, cv, a);
  assemble_inertia_derivatives(sys_, q, v, yp + nq_, rv, cq, cv, a);
  assemble_force_derivatives(sys_, state_.modes, q, v, t, rv, cq, cv, a, &state_.turns);
  assemble_constraint_hessian(sys_, offsets_, q, lambda, rv, cq, a);
}

int MultibodyDae::finite_or_retry(const double* r, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(r[i])) return 1;
  return 0;
}

std::string MultibodyDae::component_name(int i) const {
  static const char* names[7] = {"x", "y", "z", "e0", "e1", "e2", "e3"};
  if (i < 2 * nq_) {
    const int k = i % nq_;
    return std::string(i < nq_ ? "" : "velocity of ") + sys_.bodies[k / 7].name + "." + names[k % 7];
  }
  if (i < 2 * nq_ + nc_) return "multiplier of " + constraint_label(i - 2 * nq_);
  return "y[" + std::to_string(i) + "]";
}

double MultibodyDae::position_noise(const double* y) const {
  return 1e3 * 2.22e-16 * max_num(1.0, max_abs(y, nq_));
}

double MultibodyDae::position_atol(const double* y, double atol) const {
  return max_num(atol, 10 * 2.22e-16 * max_abs(y, nq_));
}

double MultibodyDae::velocity_atol(double h, const double* y, double atol) const {
  const double qmax = max_abs(y, nq_), vmax = max_abs(y + nq_, nq_);
  const double step = newton_cj_ > 0 ? 1.0 / newton_cj_ : h;
  return max_num(atol, 10 * 2.22e-16 * max_num(vmax, qmax / step));
}

void MultibodyDae::position_weights(const double* y, double rtol, double aq, double* w) const {
  for (int i = 0; i < nq_; ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + aq);
}

void MultibodyDae::state_weights(double h, const double* y, double rtol, double atol, double* w) const {
  const double aq = position_atol(y, abs_tol_.set() ? abs_tol_.position : atol);
  // Euler parameters floored like every coordinate before model-unit tolerances: at ten
  // roundings of the largest coordinate (a 40-bar four-bar whose couplers' e1..e3 stay 0 fails
  // with a floor of ten roundings of 1).
  const double ap = abs_tol_.set() ? position_atol(y, abs_tol_.rotation) : aq;
  const double av = velocity_atol(h, y, abs_tol_.set() ? abs_tol_.velocity : atol);
  const double ar = abs_tol_.set() ? velocity_atol(h, y, abs_tol_.rotation_rate) : av;
  for (int i = 0; i < nq_; ++i) {
    const bool euler = i % 7 >= 3;
    const double a_q = euler ? ap : aq;
    w[i] = 1.0 / (rtol * std::fabs(y[i]) + a_q);
    w[nq_ + i] = 1.0 / (rtol * std::fabs(y[nq_ + i]) + (euler ? ar : av));
  }
}

double MultibodyDae::position_magnitude(const double* y) const {
  double rmax = abs_tol_.length;
  for (int i = 0; i < nq_; i += 7) rmax = max_num(rmax, std::fabs(y[i]) + std::fabs(y[i + 1]) + std::fabs(y[i + 2]));
  return rmax;
}

double MultibodyDae::span_factor(double rtol) const {
  return max_num(1.0, min_num(min_num(abs_tol_.span / abs_tol_.time, kSpanCap), rtol / kSpanRtol));
}

void MultibodyDae::error_per_unit_span(double h, double noise_step, const double* y, double* w,
                                       double velocity_factor, double velocity_roundings) const {
  if (!abs_tol_.set() || !(abs_tol_.span > 0)) return;
  const double f = max_num(1.0, abs_tol_.span / h);
  const double rmax = position_magnitude(y);
  const double vmax = max_num(abs_tol_.length / abs_tol_.time, max_abs(y + nq_, nq_));
  const double e = kSpanRoundingFloor;
  const double w_length = 1.0 / (e * rmax), w_rotation = 1.0 / e;
  const double ev = velocity_roundings * 2.220446049250313e-16;
  const double w_velocity = 1.0 / (ev * max_num(vmax, rmax / noise_step));
  const double w_rate = 1.0 / (ev * max_num(1.0, 1.0 / noise_step));
  int floored = 0;
  for (int i = 0; i < nq_; ++i) {
    const bool euler = i % 7 >= 3;
    const double wanted = w[i] * f, floor = max_num(w[i], euler ? w_rotation : w_length);
    floored += wanted > floor;
    w[i] = min_num(wanted, floor);
    w[nq_ + i] = min_num(w[nq_ + i] * f * velocity_factor, max_num(w[nq_ + i], euler ? w_rate : w_velocity));
  }
  count_floor(floored);
}

void MultibodyDae::switches(double t_in, const double* y, double* g) {
  const double t = input_time(t_in);
  for (size_t k = 0; k < switch_forces_.size(); ++k) {
    const Force& f = sys_.forces[switch_forces_[k]];
    g[k] = force_switch_value(f, gather(y, f.bi, f.bj), t) - switch_offsets_[k];
  }
}

bool MultibodyDae::changes_mode(double, const double*, const int* roots) {
  for (size_t k = 0; k < switch_forces_.size(); ++k)
    if (roots[k] != 0 && state_.modes[switch_forces_[k]] != (roots[k] > 0)) return true;
  return false;
}

void MultibodyDae::restart(double t, double* y, double* yp, const int* roots) {
  for (size_t k = 0; k < switch_forces_.size(); ++k) {
    const int f = switch_forces_[k];
    if (roots) {
      if (roots[k] != 0) state_.modes[f] = roots[k] > 0;
    } else {
      const Force& force = sys_.forces[f];
      state_.modes[f] = force_switch_value(force, gather(y, force.bi, force.bj), t) > 0;
    }
  }
  std::vector<double> yy(y, y + size()), yyp(yp, yp + size());
  consistent_initial_values(t, yy, yyp);
  std::copy(yy.begin(), yy.end(), y);
  std::copy(yyp.begin(), yyp.end(), yp);
  set_switch_offsets(t, y);
  update_turns(sys_, y, y + nq_, t, state_.turns);
}

// The state at a root (IDA's interpolant at the root time, made consistent: core/ida_driver.cpp)
// can lie up to a local error on the other side of the switch: a wheel set free there while still a
// little below the ground would never see g cross zero again and would fall through the ground
// (seen on dynamics II at rtol 1e-4). Where g disagrees with its mode, the root function is
// shifted by g's value here, so that it starts at zero and the next crossing is found; the
// shift is of the order of the local error and is dropped at the next restart.
void MultibodyDae::set_switch_offsets(double t, const double* y) {
  switch_offsets_.assign(switch_forces_.size(), 0.0);
  for (size_t k = 0; k < switch_forces_.size(); ++k) {
    const Force& force = sys_.forces[switch_forces_[k]];
    const double g = force_switch_value(force, gather(y, force.bi, force.bj), t);
    if ((g > 0) != static_cast<bool>(state_.modes[switch_forces_[k]]) && g != 0) switch_offsets_[k] = g;
  }
}

double MultibodyDae::initial_step(double, const double* y, const double* yp, double rtol, double atol) {
  // Weighted RMS norm of q'' = v' over the positions.
  double sum = 0;
  for (int i = 0; i < nq_; ++i) {
    const double w = 1.0 / (rtol * std::fabs(y[i]) + atol);
    sum += (yp[nq_ + i] * w) * (yp[nq_ + i] * w);
  }
  const double norm = std::sqrt(sum / nq_);
  return norm > 0 ? 0.5 * std::sqrt(2.0 / norm) : 0.0;
}

void MultibodyDae::after_step(double t_in, const double* y) {
  const double t = input_time(t_in);
  constraint_values(sys_, offsets_, y, t, stat_work_.data());
  state_.statistics.max_position_violation = max_num(state_.statistics.max_position_violation, max_abs(stat_work_.data(), nc_));
  velocity_constraint_values(sys_, offsets_, y, y + nq_, t, stat_work_.data());
  state_.statistics.max_velocity_violation = max_num(state_.statistics.max_velocity_violation, max_abs(stat_work_.data(), nc_));
  for (int b = 0; b < sys_.num_bodies(); ++b) {
    const double n = Eigen::Map<const Vec4>(y + 7 * b + 3).norm();
    state_.statistics.max_norm_drift = max_num(state_.statistics.max_norm_drift, std::fabs(n - 1.0));
  }
  update_turns(sys_, y, y + nq_, t, state_.turns);
}

void MultibodyDae::consistent_state(double t, double* q, double* v, double* a, double* lambda) {
  if (nq_ == 0)
    throw SolveError("nothing_moves", "nothing moves: the scene has no body that can move (none, or all "
                                      "welded or locked to ground), so there is nothing to integrate");
  const PositionSolveResult pr = aug_.positions(q, t, 1e-12);
  if (!pr.converged)
    throw SolveError("inconsistent_initial_state",
                     "initial positions violate the constraints (max " + std::to_string(pr.residual) +
                         "): " + pr.worst);
  if (!aug_.velocities(q, t, v)) throw SolveError("singular", "velocity projection is singular");
  if (state_.output.accelerations) aug_.prepare_output_accelerations();
  if (!aug_.accelerations(state_.modes, q, v, t, a, lambda))
    throw SolveError("singular",
                     "the augmented mass matrix is singular at t = " + std::to_string(t) +
                         " (redundant constraints or an unconstrained massless body)");
}

double MultibodyDae::consistent_output(double t_in, const double* y, const double* yp,
                                       std::vector<double>& q, std::vector<double>& v,
                                       std::vector<double>& a, bool project) {
  const double t = input_time(t_in);
  q.assign(y, y + nq_);
  if (output_velocities_from_state())
    v.assign(y + nq_, y + 2 * nq_);
  else
    v.assign(yp, yp + nq_);
  a.resize(nq_, 0.0);
  // An interpolated sample violates the constraints by about the local error. If asked, project
  // it back (positions, then velocities), skipping what already holds to rounding. Then solve for
  // the accelerations of the state (more accurate than interpolated ones).
  constraint_values(sys_, offsets_, q.data(), t, out_phi_.data());
  const double violation = max_abs(out_phi_.data(), nc_);
  // The condition estimate costs a factorization: every tenth sample is enough to see it grow.
  if (state_.output.track_condition && (condition_samples_++ % 10) == 0) {
    const double c = aug_.constraint_condition(q.data());
    if (c > state_.statistics.max_condition) {
      state_.statistics.max_condition = c;
      state_.statistics.max_condition_time = t;
    }
  }
  // A solve that fails is reported in state_.output_failure (the run stops there): its numbers are
  // not written as if they were the state. The position projection asks for 1e-14 but is
  // accepted at the rounding level of the coordinates (position_noise).
  state_.output_failure.clear();
  char buf[200];
  bool finite = true;
  for (int i = 0; i < nq_; ++i) finite = finite && std::isfinite(q[i]) && std::isfinite(v[i]);
  if (!finite) {
    std::snprintf(buf, sizeof buf, "output sample at t = %.17g: the interpolated positions are not finite", t_in);
    state_.output_failure = buf;
  }
  if (project && state_.output_failure.empty()) {
    if (violation > 1e-14) {
      const PositionSolveResult r = aug_.positions(q.data(), t, 1e-14, 5);
      if (!(r.residual <= max_num(1e-14, position_noise(q.data())))) {
        std::snprintf(buf, sizeof buf, "output sample at t = %.17g: the projection onto the position constraints did not converge (max |Phi| %.3g after %d iterations)",
                      t_in, r.residual, r.iterations);
        state_.output_failure = buf;
      }
    }
    velocity_constraint_values(sys_, offsets_, q.data(), v.data(), t, out_phi_.data());
    const double vmax = max_num(1.0, max_abs(v.data(), nq_));
    if (state_.output_failure.empty() && max_abs(out_phi_.data(), nc_) > 1e-14 * vmax && !aug_.velocities(q.data(), t, v.data())) {
      std::snprintf(buf, sizeof buf, "output sample at t = %.17g: the projection onto the velocity constraints failed (singular constraint Jacobian)", t_in);
      state_.output_failure = buf;
    }
  }
  if (state_.output_failure.empty() && state_.output.accelerations && !aug_.output_accelerations(state_.modes, q.data(), v.data(), t, a.data(), state_.output.acceleration_tolerance)) {
    std::snprintf(buf, sizeof buf, "output sample at t = %.17g: the acceleration solve failed (singular augmented matrix)", t_in);
    state_.output_failure = buf;
  }
  return violation;
}

}  // namespace mbdae
