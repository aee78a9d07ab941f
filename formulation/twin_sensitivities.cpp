#include "formulation/twin_sensitivities.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/finite_check.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"

namespace mbdae {

TwinSensitivities::TwinSensitivities(MultibodyDae& run, std::unique_ptr<MultibodyDae> base,
                                     std::vector<ParameterTwins> twins, bool in_error_test)
    : run_(run), base_(std::move(base)), twins_(std::move(twins)), in_error_test_(in_error_test) {
  const int n = run_.size();
  if (!base_ || base_->size() != n) throw std::invalid_argument("TwinSensitivities: a base of another size");
  breakpoints_ = run_.breakpoints();
  for (ParameterTwins& p : twins_) {
    if (!p.plus || !p.minus || p.plus->size() != n || p.minus->size() != n || !(p.delta > 0))
      throw std::invalid_argument("TwinSensitivities: twins of another size than the run's DAE");
    p.reach = parameter_reach(run_.system(), p.plus->system(), p.minus->system());
    if (!p.reach.constraints.empty() && !base_->gives_constraint_terms()) p.reach.local = false;
    p.breakpoints_plus = p.plus->breakpoints();
    p.breakpoints_minus = p.minus->breakpoints();
    if (p.breakpoints_plus.size() != breakpoints_.size() || p.breakpoints_minus.size() != breakpoints_.size())
      throw std::invalid_argument("TwinSensitivities: twins with other breakpoints than the run's");
  }
  yt_.resize(n);
  ypt_.resize(n);
  rp_.resize(n);
  rm_.resize(n);
  const int nq = run_.nq(), nx = nq + run_.nc();
  for (auto* v : {&qp_, &qm_, &vp_, &vm_, &at_}) v->resize(nq);
  g_.resize(nx);
  xp_.resize(nx);
  sp_plus_.resize(run_.system().sensors.size());
  sp_minus_.resize(run_.system().sensors.size());
}

void TwinSensitivities::follow(MultibodyDae& twin) {
  twin.state().modes = run_.state().modes;  // same sizes: no allocation
  twin.state().turns = run_.state().turns;
}

int TwinSensitivities::run_breakpoint(double t) const {
  for (size_t k = 0; k < breakpoints_.size(); ++k)
    if (std::fabs(t - breakpoints_[k]) <= 64 * 2.220446049250313e-16 * std::fabs(breakpoints_[k]))
      return static_cast<int>(k);
  return -1;
}

// A segment's end that is one of the run's breakpoints becomes the twin's own. The twin's inputs
// are held from its own copy of the last breakpoint the run has passed, where that lies after
// t_start: also when the segment starts at an event between the two (a landing 1 us after the
// run's step, before the twin's).
void TwinSensitivities::set_segment(double t_start, double t_end) {
  base_->set_segment(t_start, t_end);
  const int ke = run_breakpoint(t_end), ks = run_breakpoint(t_start);
  int passed = ks;  // the last of the run's breakpoints at or before t_start
  for (size_t k = 0; k < breakpoints_.size(); ++k)
    if (breakpoints_[k] <= t_start) passed = std::max(passed, static_cast<int>(k));
  for (ParameterTwins& p : twins_)
    for (int side = 0; side < 2; ++side) {
      MultibodyDae& twin = side == 0 ? *p.plus : *p.minus;
      const std::vector<double>& b = side == 0 ? p.breakpoints_plus : p.breakpoints_minus;
      twin.set_segment(t_start, ke >= 0 ? b[ke] : t_end);
      twin.hold_inputs_from(passed >= 0 && b[passed] > t_start ? b[passed] : -1e300);
    }
}

void TwinSensitivities::jump_at_breakpoint(double t, const double* yp_before, const double* yp_after,
                                           double* const* s) {
  const int k = run_breakpoint(t);
  if (k < 0) return;
  const int nd = 2 * run_.nq();  // q and v: every formulation's differential unknowns
  for (size_t i = 0; i < twins_.size(); ++i) {
    const ParameterTwins& p = twins_[i];
    const double dtdp = (p.breakpoints_plus[k] - p.breakpoints_minus[k]) / (2 * p.delta);
    if (dtdp == 0) continue;
    for (int j = 0; j < nd; ++j) s[i][j] += (yp_before[j] - yp_after[j]) * dtdp;
  }
}

int TwinSensitivities::residual(double t, const double* y, const double* yp, const double*, const double* const* s,
                                const double* const* sp, double* const* r) {
  follow(*base_);
  for (size_t i = 0; i < twins_.size(); ++i) base_->derivative_times(y, sp[i], r[i]);
  base_->jacobian_times(t, y, yp, count(), s, r);  // one pass over the kernels for all parameters
  for (size_t i = 0; i < twins_.size(); ++i)
    if (const int flag = add_parameter_difference(t, y, yp, twins_[i], r[i]); flag != 0) return flag;
  return 0;
}

// r += [F+(y, y') - F-(y, y')] / (2 d) = F_p: the twins' central difference at the run's state,
// two residuals (every term that does not depend on p is alike in both and cancels).
int TwinSensitivities::add_parameter_difference(double t, const double* y, const double* yp, ParameterTwins& p,
                                                double* r) {
  if (p.reach.local && !p.whole_residuals) return add_reached_difference(t, y, yp, p, r);
  const int n = run_.size();
  for (int sign = 1; sign >= -1; sign -= 2) {
    MultibodyDae& twin = sign > 0 ? *p.plus : *p.minus;
    follow(twin);
    if (const int flag = twin.residual(t, y, yp, sign > 0 ? rp_.data() : rm_.data()); flag != 0) return flag;
  }
  for (int k = 0; k < n; ++k) r[k] += (rp_[k] - rm_[k]) * (0.5 / p.delta);
  return 0;
}

// The same difference over the terms p reaches: the listed bodies' rows of M v' - Q (weight,
// gyroscopic), the listed forces' -Q and the listed constraints' own terms, each twin's at the
// run's (y, y').
int TwinSensitivities::add_reached_difference(double t, const double* y, const double* yp, ParameterTwins& p,
                                              double* r) {
  const int nq = run_.nq();
  const double* v = y + nq;
  double* f2 = r + nq;
  const double f = 0.5 / p.delta;
  follow(*p.plus);
  follow(*p.minus);
  const System &sp = p.plus->system(), &sm = p.minus->system();
  for (int b : p.reach.bodies) {
    double op[7], om[7];
    body_momentum(sp, b, y, v, yp + nq, op);
    body_momentum(sm, b, y, v, yp + nq, om);
    for (int k = 0; k < 7; ++k) f2[7 * b + k] += (op[k] - om[k]) * f;
  }
  const int nc = run_.system().num_constraint_rows();
  for (int k : p.reach.constraints) {
    MultibodyDae::ConstraintTerms cp, cm;
    p.plus->constraint_terms(t, y, k, cp);
    p.minus->constraint_terms(t, y, k, cm);
    const Constraint& c = sp.constraints[k];
    for (int l = 0; l < 14; ++l) {
      const int g = global_index(c.bi, c.bj, l);
      if (g < 0) continue;
      r[g] += (cp.f1[l] - cm.f1[l]) * f;
      f2[g] += (cp.f2[l] - cm.f2[l]) * f;
    }
    const int o = run_.constraint_offset(k);
    for (int b = 0; b < 2; ++b)
      for (int row = 0; row < c.rows(); ++row) r[2 * nq + b * nc + o + row] += (cp.rows[b][row] - cm.rows[b][row]) * f;
  }
  const double tp = p.plus->input_time(t), tm = p.minus->input_time(t);
  for (int k : p.reach.forces) {
    const Vec14 qp = force_local(sp, k, p.plus->state().modes, y, v, tp, &p.plus->state().turns);
    const Vec14 qm = force_local(sm, k, p.minus->state().modes, y, v, tm, &p.minus->state().turns);
    const Force& fo = sp.forces[k];
    for (int l = 0; l < 14; ++l) {
      const int g = global_index(fo.bi, fo.bj, l);
      if (g >= 0) f2[g] -= (qp[l] - qm[l]) * f;
    }
  }
  for (int i = 0; i < run_.size(); ++i)
    if (!std::isfinite(r[i])) return 1;  // recoverable, as a twin's non-finite residual
  return 0;
}

void TwinSensitivities::initial(double, const double*, const double*, double* const* s, double* const* sp) {
  const int n = run_.size();
  for (size_t i = 0; i < twins_.size(); ++i) {
    const ParameterTwins& p = twins_[i];
    for (int k = 0; k < n; ++k) {
      s[i][k] = (p.y_plus[k] - p.y_minus[k]) / (2 * p.delta);
      sp[i][k] = (p.yp_plus[k] - p.yp_minus[k]) / (2 * p.delta);
    }
  }
}

// Each twin made consistent from y +- d s with the run's modes (not from the switches' signs:
// at an event the switch is at zero).
void TwinSensitivities::restart(double t, const double* y, const double* yp, double* const* s, double* const* sp) {
  const int n = run_.size();
  std::vector<double> yy[2], yyp[2];
  for (size_t i = 0; i < twins_.size(); ++i) {
    ParameterTwins& p = twins_[i];
    for (int side = 0; side < 2; ++side) {
      MultibodyDae& twin = side == 0 ? *p.plus : *p.minus;
      const double d = side == 0 ? p.delta : -p.delta;
      follow(twin);
      yy[side].assign(n, 0.0);
      yyp[side].assign(n, 0.0);
      for (int k = 0; k < n; ++k) {
        yy[side][k] = y[k] + d * s[i][k];
        yyp[side][k] = yp[k] + d * sp[i][k];
      }
      twin.consistent_initial_values(t, yy[side], yyp[side]);
    }
    for (int k = 0; k < n; ++k) {
      s[i][k] = (yy[0][k] - yy[1][k]) / (2 * p.delta);
      sp[i][k] = (yyp[0][k] - yyp[1][k]) / (2 * p.delta);
    }
  }
}

bool TwinSensitivities::sensors(double t, const double* y, const double* yp, const double* const* s,
                                const double* const* sp, bool project, std::vector<std::vector<double>>& out) {
  out.resize(twins_.size());
  const bool derivative = !project && run_.state().output.accelerations &&
                          run_.augmented().last_output(run_.input_time(t)) != nullptr;
  for (size_t i = 0; i < twins_.size(); ++i) {
    if (!(derivative && sensors_by_derivative(t, y, yp, s[i], sp ? sp[i] : nullptr, twins_[i])) &&
        !sensors_by_twins(t, y, yp, s[i], sp ? sp[i] : nullptr, project, twins_[i]))
      return false;
    out[i].resize(sp_plus_.size());
    for (size_t k = 0; k < sp_plus_.size(); ++k) out[i][k] = (sp_plus_[k] - sp_minus_[k]) / (2 * twins_[i].delta);
  }
  return true;
}

// The twins' own consistent outputs at y +- d s (each its accelerations' solve), their sensors
// into sp_plus_ and sp_minus_.
bool TwinSensitivities::sensors_by_twins(double t, const double* y, const double* yp, const double* s,
                                         const double* sp, bool project, ParameterTwins& p) {
  const int n = run_.size();
  for (int sign = 1; sign >= -1; sign -= 2) {
    MultibodyDae& twin = sign > 0 ? *p.plus : *p.minus;
    follow(twin);
    for (int k = 0; k < n; ++k) {
      yt_[k] = y[k] + sign * p.delta * s[k];
      if (yp) ypt_[k] = yp[k] + sign * p.delta * sp[k];
    }
    twin.state().output = run_.state().output;
    twin.consistent_output(t, yt_.data(), yp ? ypt_.data() : nullptr, qo_, vo_, ao_, project);
    if (!twin.state().output_failure.empty()) {
      failure_ = twin.state().output_failure;
      return false;
    }
    evaluate_sensors(twin.system(), twin.state().modes, qo_.data(), vo_.data(), ao_.empty() ? nullptr : ao_.data(),
                     twin.input_time(t), sign > 0 ? sp_plus_.data() : sp_minus_.data(), nullptr, &twin.state().turns);
  }
  return true;
}

// The accelerations' and multipliers' sensitivity x_p from the run's own output solve: with
// r(q, v, x; p) = b - K x the acceleration system's residual (zero at the run's sample),
// K x_p = dr/dp along (s_q, s_v) at the run's x, that derivative the twins' central difference
// of r at (q +- d s_q, v +- d s_v) with x held; K x_p = g solved on the run's factorization of the
// sample (AugmentedSolver::output_derivative). The twins' sensors then at x +- d x_p. Two
// residuals of the acceleration system per twin pair and one solve with refinement, where the
// twins' own outputs cost each a solve with its refinement (docs/sensitivities.md, Cost). False
// where the refinement does not converge (the twins' outputs are taken then).
bool TwinSensitivities::sensors_by_derivative(double t, const double* y, const double* yp, const double* s,
                                              const double* sp, ParameterTwins& p) {
  AugmentedSolver& aug = run_.augmented();
  const double t_run = run_.input_time(t);
  const double* x = aug.last_output(t_run);
  const int nq = run_.nq(), nx = nq + run_.nc();
  const bool v_from_state = run_.output_velocities_from_state();
  if (!v_from_state && !yp) return false;
  for (int sign = 1; sign >= -1; sign -= 2) {
    MultibodyDae& twin = sign > 0 ? *p.plus : *p.minus;
    follow(twin);
    double* q = sign > 0 ? qp_.data() : qm_.data();
    double* v = sign > 0 ? vp_.data() : vm_.data();
    for (int k = 0; k < nq; ++k) {
      q[k] = y[k] + sign * p.delta * s[k];
      v[k] = v_from_state ? y[nq + k] + sign * p.delta * s[nq + k] : yp[k] + sign * p.delta * sp[k];
    }
    if (first_non_finite(q, nq) >= 0 || first_non_finite(v, nq) >= 0) return false;
    twin.augmented().acceleration_system_residual(twin.state().modes, q, v, twin.input_time(t), x,
                                                  sign > 0 ? rp_.data() : rm_.data());
  }
  for (int k = 0; k < nx; ++k) g_[k] = (rp_[k] - rm_[k]) / (2 * p.delta);
  // The refinement's guess: IDAS's interpolated s' of v (x_p's accelerations) and s of lambda,
  // where y = [q, v, lambda, ...] (a guess only: the refinement decides).
  const bool guess = sp && run_.size() >= 2 * nq + run_.nc();
  for (int k = 0; k < nx; ++k) xp_[k] = !guess ? 0.0 : k < nq ? sp[nq + k] : s[nq + k];
  if (!aug.output_derivative(y, t_run, g_.data(), xp_.data(), run_.state().output.acceleration_tolerance))
    return false;
  for (int sign = 1; sign >= -1; sign -= 2) {
    MultibodyDae& twin = sign > 0 ? *p.plus : *p.minus;
    for (int k = 0; k < nq; ++k) at_[k] = x[k] + sign * p.delta * xp_[k];
    evaluate_sensors(twin.system(), twin.state().modes, sign > 0 ? qp_.data() : qm_.data(),
                     sign > 0 ? vp_.data() : vm_.data(), at_.data(), twin.input_time(t),
                     sign > 0 ? sp_plus_.data() : sp_minus_.data(), nullptr, &twin.state().turns);
  }
  return true;
}

}  // namespace mbdae
