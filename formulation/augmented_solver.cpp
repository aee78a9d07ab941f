#include "formulation/augmented_solver.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "core/errors.h"
#include "core/finite_check.h"
#include "formulation/mechanics.h"

namespace mbdae {

AugmentedSolver::AugmentedSolver(const System& sys)
    : sys_(sys), offsets_(constraint_offsets(sys)), nq_(sys.nq()), nc_(offsets_.back()) {
  const int n = nq_ + nc_;
  asm_.begin_pattern(n, n);
  assemble(sys.q0.data(), true);
  asm_.finalize();
  klu_.analyze(asm_.pattern());
  values_.resize(asm_.pattern().nnz());
  rhs_.resize(n);
  work_.resize(n);
  work2_.resize(n);
  scratch_.resize(3 * static_cast<size_t>(n));
  for (auto& h : history_) h.resize(n);
  rows_.resize(3 * sys.constraints.size());
  phi_ = constraint_rows_pattern(sys);
}

void AugmentedSolver::assemble(const double* q, bool with_mass, double regularization) {
  // The same add() sequence for all: the weight pattern equals the mass pattern, and the
  // constraint block's diagonal is always in the pattern.
  if (with_mass)
    assemble_mass(sys_, q, 1.0, 0, 0, asm_);
  else
    assemble_weights(sys_, 1.0, 1.0, 0, 0, asm_);
  assemble_constraint_jacobian(sys_, offsets_, q, 1.0, nq_, 0, 0, nq_, asm_);
  for (int i = 0; i < nc_; ++i) asm_.add(nq_ + i, nq_ + i, -regularization);
}

void AugmentedSolver::assemble_values(const double* q, bool with_mass, double regularization) {
  asm_.begin_values(values_.data());
  assemble(q, with_mass, regularization);
  asm_.end_values();
}

bool AugmentedSolver::accelerations(const std::vector<char>& modes, const double* q,
                                    const double* v, double t, double* a, double* lambda) {
  history_size_ = 0;
  if (!solve_accelerations(klu_, modes, q, v, t)) return false;
  std::copy(rhs_.begin(), rhs_.begin() + nq_, a);
  if (lambda) std::copy(rhs_.begin() + nq_, rhs_.end(), lambda);
  return true;
}

// K = [M Phi_q^T; Phi_q 0] into values_, b = [Q; gamma] into rhs_.
void AugmentedSolver::assemble_acceleration_system(const std::vector<char>& modes, const double* q,
                                                   const double* v, double t) {
  assemble_values(q, true);
  check_overflow(values_.data(), static_cast<int>(values_.size()), t, "the mass matrix entries",
                 "a mass or an inertia");
  acceleration_right_side(modes, q, v, t);
}

// b = [Q; gamma] into rhs_.
void AugmentedSolver::acceleration_right_side(const std::vector<char>& modes, const double* q,
                                              const double* v, double t) {
  generalized_forces(sys_, modes, q, v, t, rhs_.data(), turns);
  check_overflow(rhs_.data(), nq_, t, "the applied forces", "a mass, gravity or a force");
  constraint_rates(sys_, offsets_, q, v, t, nullptr, rhs_.data() + nq_);
}

// The direct solve with `klu`: [a; lambda] into rhs_.
bool AugmentedSolver::solve_accelerations(KluSolver& klu, const std::vector<char>& modes, const double* q,
                                          const double* v, double t) {
  assemble_acceleration_system(modes, q, v, t);
  if (!klu.factor(values_.data())) return false;
  if (!klu.solve(rhs_.data())) return false;
  check_overflow(rhs_.data(), nq_ + nc_, t, "the accelerations and constraint forces",
                 "a force against a small mass or inertia");
  return true;
}

void AugmentedSolver::prepare_output_accelerations() {
  if (!output_prepared_) output_prepared_ = klu_output_.analyze(asm_.pattern());
}

bool AugmentedSolver::output_accelerations(const std::vector<char>& modes, const double* q,
                                           const double* v, double t, double* a, double tolerance) {
  if (!output_prepared_) return accelerations(modes, q, v, t, a, nullptr);
  if (history_size_ > 0 && !(t > history_t_[0])) history_size_ = 0;
  bool refined = false;
  if (klu_output_.factored() && history_size_ > 0) {
    acceleration_right_side(modes, q, v, t);
    refined = refine_accelerations(q, t, tolerance);  // the solution into rhs_
  }
  if (!refined && !solve_accelerations(klu_output_, modes, q, v, t)) return false;
  ++(refined ? refinement.refined : refinement.direct);
  last_output_direct_ = !refined;
  remember_output(t);
  std::copy(rhs_.begin(), rhs_.begin() + nq_, a);
  return true;
}

void AugmentedSolver::remember_output(double t) {
  choose_extrapolation_order(t);
  std::rotate(std::begin(history_), std::begin(history_) + kHistory - 1, std::end(history_));
  std::copy_backward(std::begin(history_t_), std::begin(history_t_) + kHistory - 1, std::end(history_t_));
  history_[0].assign(rhs_.begin(), rhs_.end());  // same size: no allocation
  history_t_[0] = t;
  history_size_ = std::min(history_size_ + 1, kHistory);
}

// Lagrange weights at t for the newest `points` samples (degree points - 1).
void AugmentedSolver::extrapolation_weights(double t, int points, double* w) const {
  for (int i = 0; i < points; ++i) {
    double num = 1, den = 1;
    for (int j = 0; j < points; ++j)
      if (j != i) {
        num *= t - history_t_[j];
        den *= history_t_[i] - history_t_[j];
      }
    w[i] = num / den;
  }
}

void AugmentedSolver::predict_accelerations(double t, int points, double* x) const {
  double w[kHistory];
  extrapolation_weights(t, points, w);
  const int n = nq_ + nc_;
  // Sample by sample over contiguous arrays (the loops vectorize); each x[k] sums its terms in
  // the same order as a loop over the samples per entry would.
  std::fill(x, x + n, 0.0);
  for (int i = 0; i < points; ++i) {
    const double wi = w[i];
    const double* h = history_[i].data();
    for (int k = 0; k < n; ++k) x[k] += wi * h[k];
  }
}

// The order is chosen like a BDF code's: of the extrapolations through points_ - 1, points_ and
// points_ + 1 samples, the one that would have predicted this sample's solution (in rhs_) best,
// its error in a and in lambda each relative to the block's max norm. Smooth motion sampled
// finely raises the degree (fewer refinement corrections); a kink or coarse sampling lowers it.
void AugmentedSolver::choose_extrapolation_order(double t) {
  if (history_size_ < 2 || ++samples_since_choice_ < kChoiceInterval) return;
  samples_since_choice_ = 0;
  const int lo = std::max(1, points_ - 1), hi = std::min(points_ + 1, history_size_);
  double w[3][kHistory] = {};
  for (int m = lo; m <= hi; ++m) extrapolation_weights(t, m, w[m - lo]);
  const int n = nq_ + nc_;
  double* s[3] = {scratch_.data(), scratch_.data() + n, scratch_.data() + 2 * n};
  std::fill(scratch_.begin(), scratch_.end(), 0.0);
  for (int i = 0; i < hi; ++i) {
    const double* h = history_[i].data();
    for (int c = 0; c < 3; ++c) {
      const double wc = w[c][i];
      double* sc = s[c];
      for (int k = 0; k < n; ++k) sc[k] += wc * h[k];
    }
  }
  // Plain comparisons rather than std::fmax (a libm call per entry): the values are finite here.
  auto max_abs_diff = [](const double* x, const double* y, int k0, int k1) {
    double m = 0;
    for (int k = k0; k < k1; ++k) {
      const double d = std::fabs(x[k] - (y ? y[k] : 0.0));
      m = d > m ? d : m;
    }
    return m;
  };
  double e[3][2] = {}, xmax[2] = {0, 0};
  for (int b = 0; b < 2; ++b) {
    const int k0 = b ? nq_ : 0, k1 = b ? n : nq_;
    xmax[b] = max_abs_diff(rhs_.data(), nullptr, k0, k1);
    for (int c = 0; c < 3; ++c) e[c][b] = max_abs_diff(s[c], rhs_.data(), k0, k1);
  }
  double best = INFINITY;
  for (int m = lo; m <= hi; ++m) {
    const double* em = e[m - lo];
    const double error = (xmax[0] > 0 ? em[0] / xmax[0] : 0) + (xmax[1] > 0 ? em[1] / xmax[1] : 0);
    if (error < best) {
      best = error;
      points_ = m;
    }
  }
}

// r = b - K x without assembling K: M a + Phi_q^T lambda and Phi_q a, from the constraint rows in
// rows_ (evaluated once per sample).
void AugmentedSolver::acceleration_residual(const double* q, const double* b, const double* x, double* r) const {
  mass_times(sys_, q, x, r);
  constraint_rows_products(phi_, rows_, x, x + nq_, r, r + nq_);
  for (int i = 0; i < nq_ + nc_; ++i) r[i] = b[i] - r[i];
}

bool AugmentedSolver::refine_accelerations(const double* q, double t, double tolerance) {
  double* x = work2_.data();
  predict_accelerations(t, std::min(points_, history_size_), x);
  constraint_jacobian_rows(sys_, q, rows_);
  if (!refine(q, rhs_.data(), x, t, tolerance, "the accelerations and constraint forces")) return false;
  std::copy(work2_.begin(), work2_.end(), rhs_.begin());
  return true;
}

// From x: r = b - K x, dx = K0^-1 r, x += dx (K from rows_ at q). The iteration contracts by
// rho = |K0^-1 (K - K0)| per correction (small for nearby states); the error left after a
// correction dx is about rho / (1 - rho) |dx|, with rho measured as the ratio of successive
// corrections (per block, a and lambda). Accepted when that estimate is below `tolerance` of the
// block's max norm (for a, or the rounding of b's forces, 1e3 eps |b_Q| / m); a slow (rho > 0.5)
// or diverging iteration is not.
bool AugmentedSolver::refine(const double* q, const double* b, double* x, double t, double tolerance,
                             const char* what) {
  const int n = nq_ + nc_;
  // The accelerations cannot be resolved below the rounding of the force balance, about eps |Q| / m
  // (gravity for a body it pulls): a mechanism at rest has a = 0 up to that rounding, and a
  // tolerance relative to |a| alone could never be met there (every sample would fall back to
  // the direct solve). So a is accepted at that rounding (1e3 eps |Q| / m) when it is the larger.
  double floor[2] = {0, 0};
  for (int body = 0; body < sys_.num_bodies(); ++body)
    if (sys_.bodies[body].mass > 0)
      for (int k = 0; k < 3; ++k) floor[0] = std::max(floor[0], std::fabs(b[7 * body + k]) / sys_.bodies[body].mass);
  floor[0] *= 1e3 * 2.220446049250313e-16;
  double last_dx[2] = {0, 0};
  for (int it = 0; it < kMaxRefinements; ++it) {
    acceleration_residual(q, b, x, work_.data());
    if (!klu_output_.solve(work_.data())) return false;
    ++refinement.corrections;
    double dx[2] = {0, 0}, xmax[2] = {0, 0};
    for (int i = 0; i < n; ++i) {
      x[i] += work_[i];
      const int blk = i >= nq_;
      // std::max is inlined (std::fmax is a libm call); as with fmax a NaN is skipped here and
      // caught by check_overflow.
      dx[blk] = std::max(dx[blk], std::fabs(work_[i]));
      xmax[blk] = std::max(xmax[blk], std::fabs(x[i]));
    }
    if (!std::isfinite(dx[0] + dx[1] + xmax[0] + xmax[1])) return false;
    bool converged = true, hopeless = false;
    for (int blk = 0; blk < 2; ++blk) {
      const double rho = it > 0 && last_dx[blk] > 0 ? dx[blk] / last_dx[blk] : 1.0;
      const double error = rho <= 0.5 ? rho / (1 - rho) * dx[blk] : INFINITY;
      const double allowed = std::max(tolerance * xmax[blk], floor[blk]);
      converged = converged && (dx[blk] == 0 || error <= allowed);
      // Not within the corrections left at this rate: the direct solve is cheaper.
      hopeless = hopeless || (it > 0 && error * std::pow(rho, kMaxRefinements - 1 - it) > allowed);
      last_dx[blk] = dx[blk];
    }
    if (hopeless && !converged) return false;
    if (converged) {
      check_overflow(x, n, t, what, "a force against a small mass or inertia");
      return true;
    }
  }
  return false;
}

void AugmentedSolver::acceleration_system_residual(const std::vector<char>& modes, const double* q,
                                                   const double* v, double t, const double* x, double* r) {
  acceleration_right_side(modes, q, v, t);
  constraint_jacobian_rows(sys_, q, rows_);
  acceleration_residual(q, rhs_.data(), x, r);
}

const double* AugmentedSolver::last_output(double t) const {
  return output_prepared_ && history_size_ > 0 && history_t_[0] == t ? history_[0].data() : nullptr;
}

bool AugmentedSolver::output_derivative(const double* q, double t, const double* g, double* dx, double tolerance) {
  const int n = nq_ + nc_;
  if (!klu_output_.factored()) return false;
  if (last_output_direct_) {  // K0 is K: one solve
    std::copy(g, g + n, dx);
    if (!klu_output_.solve(dx)) return false;
    check_overflow(dx, n, t, "the accelerations' sensitivities", "a force against a small mass or inertia");
    return true;
  }
  // rows_ are the sample's (refine_accelerations)
  return refine(q, g, dx, t, tolerance, "the accelerations' sensitivities");
}

void AugmentedSolver::check_overflow(const double* x, int n, double t, const char* what,
                                     const char* cause) const {
  const int i = first_non_finite(x, n);
  if (i < 0) return;
  std::ostringstream os;
  os << "overflow: " << what;
  // The forces and the accelerations are per coordinate: name the body.
  if (x == rhs_.data() && i < nq_) os << " of body " << sys_.bodies[i / 7].name;
  os << " are not finite at t = " << t << " (" << cause << " too large for double precision?)";
  throw SolveError("overflow", os.str());
}

bool AugmentedSolver::velocities(const double* q, double t, double* v) {
  // [I Phi_q^T; Phi_q 0] [dv; mu] = [0; -Phi_t - Phi_q v]
  assemble_values(q, false);
  if (!klu_.factor(values_.data())) return false;
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
  constraint_rates(sys_, offsets_, q, v, t, rhs_.data() + nq_, nullptr);
  constraint_jacobian_times(sys_, offsets_, q, v, work_.data());
  for (int i = 0; i < nc_; ++i) rhs_[nq_ + i] = -rhs_[nq_ + i] - work_[i];
  if (!klu_.solve(rhs_.data())) return false;
  for (int i = 0; i < nq_; ++i) v[i] += rhs_[i];
  return true;
}

double AugmentedSolver::constraint_condition(const double* q) {
  assemble_values(q, false);
  if (!klu_.factor(values_.data())) return INFINITY;
  return klu_.condest();
}

PositionSolveResult AugmentedSolver::positions(double* q, double t, double tol, int max_iter,
                                               double regularization) {
  PositionSolveResult res;
  std::vector<double>& phi = work_;
  constraint_values(sys_, offsets_, q, t, phi.data());
  double norm = max_abs(phi.data(), nc_);
  std::vector<double>& trial = trial_;
  trial.assign(q, q + nq_);
  for (res.iterations = 0; res.iterations < max_iter && norm > tol; ++res.iterations) {
    // Minimum-norm Gauss-Newton step: [I Phi_q^T; Phi_q -eps I] [dq; mu] = [0; -Phi]. With
    // eps > 0 (Levenberg-Marquardt) the step exists also for redundant constraints.
    assemble_values(q, false, regularization);
    if (!klu_.factor(values_.data())) break;
    std::fill(rhs_.begin(), rhs_.begin() + nq_, 0.0);
    for (int i = 0; i < nc_; ++i) rhs_[nq_ + i] = -phi[i];
    if (!klu_.solve(rhs_.data())) break;
    // Backtracking line search on max |Phi|.
    double alpha = 1.0, trial_norm = norm;
    for (int ls = 0; ls < 30; ++ls, alpha *= 0.5) {
      for (int i = 0; i < nq_; ++i) trial[i] = q[i] + alpha * rhs_[i];
      constraint_values(sys_, offsets_, trial.data(), t, work2_.data());
      trial_norm = max_abs(work2_.data(), nc_);
      if (std::isfinite(trial_norm) && trial_norm < (1.0 - 1e-4 * alpha) * norm) break;
    }
    if (!(trial_norm < norm)) break;
    std::copy(trial.begin(), trial.end(), q);
    std::copy(work2_.begin(), work2_.begin() + nc_, phi.begin());
    norm = trial_norm;
  }
  res.residual = norm;
  res.converged = norm <= tol;
  if (!res.converged) {
    // Name the most violated constraint equations.
    std::vector<int> rows(nc_);
    std::iota(rows.begin(), rows.end(), 0);
    const int k = std::min(3, nc_);
    std::partial_sort(rows.begin(), rows.begin() + k, rows.end(),
                      [&](int a, int b) { return std::fabs(phi[a]) > std::fabs(phi[b]); });
    std::ostringstream os;
    for (int i = 0; i < k; ++i) {
      const int r = rows[i];
      const int c = static_cast<int>(std::upper_bound(offsets_.begin(), offsets_.end(), r) -
                                     offsets_.begin()) - 1;
      os << (i ? "; " : "") << sys_.constraints[c].label << " = " << phi[r];
    }
    res.worst = os.str();
  }
  return res;
}

}  // namespace mbdae
