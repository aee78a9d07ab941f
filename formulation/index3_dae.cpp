#include "formulation/index3_dae.h"

#include <cmath>

#include "core/errors.h"
#include "formulation/mechanics.h"

namespace mbdae {

Index3Dae::Index3Dae(const System& sys, double constraint_scale)
    : sys_(sys),
      offsets_(constraint_offsets(sys)),
      nq_(sys.nq()),
      nc_(offsets_.back()),
      scale_(constraint_scale),
      aug_(sys) {
  modes = initial_modes(sys, sys.q0.data(), 0.0);
  for (const auto& b : sys.bodies) mass_scale_ = std::fmax(mass_scale_, b.mass);
  for (size_t k = 0; k < sys.forces.size(); ++k)
    if (force_has_switch(sys.forces[k])) switch_forces_.push_back(static_cast<int>(k));
  work_.resize(size());
  out_phi_.resize(nc_);
  out_phi2_.resize(nc_);
  // Record the Jacobian pattern once.
  std::vector<double> y(size(), 0.0), yp(size(), 0.0);
  std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
  asm_.begin_pattern(size(), size());
  assemble(0.0, 1.0, y.data(), yp.data());
  asm_.finalize();
}

int Index3Dae::residual(double t_in, const double* y, const double* yp, double* r) {
  const double t = input_time(t_in);
  const double* q = y;
  const double* v = y + nq_;
  const double* lambda = y + 2 * nq_;
  for (int i = 0; i < nq_; ++i) r[i] = yp[i] - v[i];
  double* f2 = r + nq_;
  mass_times(sys_, q, yp + nq_, f2);
  generalized_forces(sys_, modes, q, v, t, work_.data());
  for (int i = 0; i < nq_; ++i) f2[i] -= work_[i];
  add_constraint_forces(sys_, offsets_, q, lambda, f2);
  double* f3 = r + 2 * nq_;
  constraint_values(sys_, offsets_, q, t, f3);
  for (int i = 0; i < nc_; ++i) f3[i] *= scale_;
  for (int i = 0; i < size(); ++i)
    if (!std::isfinite(r[i])) return 1;  // recoverable: IDA retries with a smaller step
  return 0;
}

void Index3Dae::assemble(double t, double cj, const double* y, const double* yp) {
  const double* q = y;
  const double* v = y + nq_;
  const double* lambda = y + 2 * nq_;
  const int rq = 0, rv = nq_, rl = 2 * nq_;  // row blocks
  const int cq = 0, cv = nq_, cl = 2 * nq_;  // column blocks
  for (int i = 0; i < nq_; ++i) {
    asm_.add(rq + i, cq + i, cj);
    asm_.add(rq + i, cv + i, -1.0);
  }
  assemble_mass(sys_, q, cj, rv, cv, asm_);
  assemble_inertia_derivatives(sys_, q, v, yp + nq_, rv, cq, cv, asm_);
  assemble_force_derivatives(sys_, modes, q, v, t, rv, cq, cv, asm_);
  assemble_constraint_hessian(sys_, offsets_, q, lambda, rv, cq, asm_);
  assemble_constraint_jacobian(sys_, offsets_, q, scale_, rl, cq, rv, cl, asm_);
}

int Index3Dae::jacobian(double t_in, double cj, const double* y, const double* yp, double* values) {
  const double t = input_time(t_in);
  asm_.begin_values(values);
  assemble(t, cj, y, yp);
  return 0;
}

void Index3Dae::error_test_mask(double* id) const {
  for (int i = 0; i < size(); ++i) id[i] = i < nq_ ? 1.0 : 0.0;
}

void Index3Dae::error_weights(double h, const double* y, double rtol, double atol, double* w) const {
  // Rounding in the positions (about 1e3 eps |q|, through the constraints) reaches the Newton
  // corrections of v and lambda amplified by 1/h and 1/h^2: that noise floor, not the user's
  // atol, bounds how tightly they can converge.
  double qmax = 1.0;
  for (int i = 0; i < nq_; ++i) qmax = std::fmax(qmax, std::fabs(y[i]));
  const double noise = 1e3 * 2.22e-16 * qmax;
  const double av = atol + noise / h, al = mass_scale_ * (atol + noise / (h * h));
  // Positions: the user's tolerances, but never below ten roundings of the largest coordinate
  // (an atol under that asks the Newton iteration for digits that do not exist).
  const double aq = std::fmax(atol, 10 * 2.22e-16 * qmax);
  for (int i = 0; i < nq_; ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + aq);
  for (int i = nq_; i < 2 * nq_; ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + av);
  for (int i = 2 * nq_; i < size(); ++i) w[i] = 1.0 / (rtol * std::fabs(y[i]) + al);
}

std::string Index3Dae::component_name(int i) const {
  static const char* names[7] = {"x", "y", "z", "e0", "e1", "e2", "e3"};
  if (i < 2 * nq_) {
    const int k = i % nq_;
    return std::string(i < nq_ ? "" : "velocity of ") + sys_.bodies[k / 7].name + "." + names[k % 7];
  }
  const int row = i - 2 * nq_;
  for (size_t c = 0; c < sys_.constraints.size(); ++c)
    if (row < offsets_[c + 1]) return "multiplier of " + sys_.constraints[c].label;
  return "y[" + std::to_string(i) + "]";
}

void Index3Dae::switches(double t_in, const double* y, double* g) {
  const double t = input_time(t_in);
  for (size_t k = 0; k < switch_forces_.size(); ++k) {
    const Force& f = sys_.forces[switch_forces_[k]];
    g[k] = force_switch_value(f, gather(y, f.bi, f.bj), t);
  }
}

void Index3Dae::consistent_initial_values(double t, std::vector<double>& y, std::vector<double>& yp) {
  double* q = y.data();
  double* v = y.data() + nq_;
  const PositionSolveResult pr = aug_.positions(q, t, 1e-12);
  if (!pr.converged)
    throw SolveError("inconsistent_initial_state",
                     "initial positions violate the constraints (max " + std::to_string(pr.residual) +
                         "): " + pr.worst);
  if (!aug_.velocities(q, t, v)) throw SolveError("singular", "velocity projection is singular");
  std::fill(yp.begin(), yp.end(), 0.0);
  std::copy(v, v + nq_, yp.begin());
  if (!aug_.accelerations(modes, q, v, t, yp.data() + nq_, y.data() + 2 * nq_))
    throw SolveError("singular",
                     "the augmented mass matrix is singular at t = " + std::to_string(t) +
                         " (redundant constraints or an unconstrained massless body)");
}

double Index3Dae::initial_step(double, const double* y, const double* yp, double rtol, double atol) {
  // Weighted RMS norm of q'' = v' over the error-tested positions.
  double sum = 0;
  for (int i = 0; i < nq_; ++i) {
    const double w = 1.0 / (rtol * std::fabs(y[i]) + atol);
    sum += (yp[nq_ + i] * w) * (yp[nq_ + i] * w);
  }
  const double norm = std::sqrt(sum / nq_);
  return norm > 0 ? 0.5 * std::sqrt(2.0 / norm) : 0.0;
}

bool Index3Dae::changes_mode(double, const double*, const int* roots) {
  for (size_t k = 0; k < switch_forces_.size(); ++k)
    if (roots[k] != 0 && modes[switch_forces_[k]] != (roots[k] > 0)) return true;
  return false;
}

void Index3Dae::restart(double t, double* y, double* yp, const int* roots) {
  // New modes: flip the switches that crossed zero; at breakpoints, re-evaluate all from signs.
  for (size_t k = 0; k < switch_forces_.size(); ++k) {
    const int f = switch_forces_[k];
    if (roots) {
      if (roots[k] != 0) modes[f] = roots[k] > 0;
    } else {
      const Force& force = sys_.forces[f];
      modes[f] = force_switch_value(force, gather(y, force.bi, force.bj), t) > 0;
    }
  }
  std::vector<double> yy(y, y + size()), yyp(yp, yp + size());
  consistent_initial_values(t, yy, yyp);
  std::copy(yy.begin(), yy.end(), y);
  std::copy(yyp.begin(), yyp.end(), yp);
}

void Index3Dae::after_step(double t_in, const double* y) {
  const double t = input_time(t_in);
  constraint_values(sys_, offsets_, y, t, work_.data());
  max_position_violation = std::fmax(max_position_violation, max_abs(work_.data(), nc_));
  for (int b = 0; b < sys_.num_bodies(); ++b) {
    const double n = Eigen::Map<const Vec4>(y + 7 * b + 3).norm();
    max_norm_drift = std::fmax(max_norm_drift, std::fabs(n - 1.0));
  }
}

double Index3Dae::consistent_output(double t_in, const double* y, const double* yp,
                                    std::vector<double>& q, std::vector<double>& v,
                                    std::vector<double>& a, bool project) {
  const double t = input_time(t_in);
  q.assign(y, y + nq_);
  // Velocities: the interpolant of v (through the steps' velocities, one degree higher than the
  // derivative of the positions' interpolant, and measured more accurate: spring-body energy
  // 9.6e-9 against 1.6e-8).
  (void)yp;
  v.assign(y + nq_, y + 2 * nq_);
  a.resize(nq_, 0.0);
  // An interpolated sample violates the constraints by about the local error. If asked, project
  // it back (positions, then velocities), skipping what already holds to rounding. Then solve for
  // the accelerations of the state: interpolated accelerations of an index-3 solution are an
  // order of magnitude less accurate than these.
  constraint_values(sys_, offsets_, q.data(), t, out_phi_.data());
  const double violation = max_abs(out_phi_.data(), nc_);
  // The condition estimate costs a factorization: every tenth sample is enough to see it grow.
  if (track_condition && (condition_samples_++ % 10) == 0) track_conditioning(t, q.data());
  if (!project) {
    if (output_accelerations) aug_.accelerations(modes, q.data(), v.data(), t, a.data(), nullptr);
    return violation;
  }
  if (violation > 1e-14) aug_.positions(q.data(), t, 1e-14, 5);
  constraint_rates(sys_, offsets_, q.data(), v.data(), t, out_phi_.data(), nullptr);
  constraint_jacobian_times(sys_, offsets_, q.data(), v.data(), out_phi2_.data());
  double vmax = 1.0, vviol = 0.0;
  for (int i = 0; i < nq_; ++i) vmax = std::fmax(vmax, std::fabs(v[i]));
  for (int i = 0; i < nc_; ++i) vviol = std::fmax(vviol, std::fabs(out_phi_[i] + out_phi2_[i]));
  if (vviol > 1e-14 * vmax) aug_.velocities(q.data(), t, v.data());
  if (output_accelerations) aug_.accelerations(modes, q.data(), v.data(), t, a.data(), nullptr);
  return violation;
}

void Index3Dae::track_conditioning(double t, const double* q) {
  const double c = aug_.constraint_condition(q);
  if (c > max_condition) {
    max_condition = c;
    max_condition_time = t;
  }
}

}  // namespace mbdae
