#include "formulation/kinematic_sensitivities.h"

#include <algorithm>
#include <cmath>

#include "formulation/body_point.h"
#include "formulation/constraint_rates.h"
#include "formulation/constraints.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"

namespace mbdae {

KinematicSensitivities::KinematicSensitivities(const System& run,
                                               std::vector<std::pair<const System*, const System*>> twins,
                                               std::vector<double> deltas)
    : run_(run), twins_(std::move(twins)), deltas_(std::move(deltas)), offsets_(constraint_offsets(run)) {
  const int n = run_.nq();
  // Phi_q's pattern (assemble_constraint_jacobian's calls, the same at every q), analysed once;
  // each sample assembles its values in place.
  asm_.begin_pattern(n, n);
  assemble_constraint_jacobian(run_, offsets_, run_.q0.data(), 1.0, 0, 0, -1, -1, asm_);
  asm_.finalize();
  values_.resize(asm_.pattern().nnz());
  klu_.analyze(asm_.pattern());
  for (const auto& [plus, minus] : twins_) reach_.push_back(parameter_reach(run_, *plus, *minus));
  const size_t np = twins_.size();
  sq_.resize(n * np);
  sv_.resize(n * np);
  for (size_t i = 0; i < np; ++i) {
    sq_cols_.push_back(sq_.data() + n * i);
    sv_cols_.push_back(sv_.data() + n * i);
  }
  for (auto* w : {&a_, &b_, &qt_, &vt_}) w->resize(n);
  yp_.resize(run_.sensors.size());
  ym_.resize(run_.sensors.size());
}

// Phi_q at q into values_, factorized (its pattern analysed once).
bool KinematicSensitivities::factorize(const double* q) {
  asm_.begin_values(values_.data());
  assemble_constraint_jacobian(run_, offsets_, q, 1.0, 0, 0, -1, -1, asm_);
  asm_.end_values();
  if (klu_.factor(values_.data())) return true;
  failure_ = "the constraint Jacobian is singular at this kinematic sample (a dead centre?)";
  return false;
}

// -dPhi/dp at q: the twins' central difference over the constraints the parameter reaches (each
// evaluated alike in both, so that the others would cancel), or over all of them.
void KinematicSensitivities::position_side(size_t i, const double* q, double t, double* rhs) {
  const System& plus = *twins_[i].first;
  const System& minus = *twins_[i].second;
  const double d = deltas_[i];
  const int n = run_.nq();
  if (!reach_[i].local) {
    constraint_values(plus, offsets_, q, t, a_.data());
    constraint_values(minus, offsets_, q, t, b_.data());
    for (int k = 0; k < n; ++k) rhs[k] = -(a_[k] - b_[k]) / (2 * d);
    return;
  }
  std::fill(rhs, rhs + n, 0.0);
  for (int k : reach_[i].constraints) {
    const Constraint& cp = plus.constraints[k];
    const Constraint& cm = minus.constraints[k];
    const LocalState s = gather(q, cp.bi, cp.bj);
    double fp[3], fm[3];
    constraint_value(cp, s, t, fp);
    constraint_value(cm, s, t, fm);
    for (int r = 0; r < cp.rows(); ++r) rhs[offsets_[k] + r] = -(fp[r] - fm[r]) / (2 * d);
  }
}

// -[(H v) s_q + d(Phi_q v + Phi_t)/dp] at (q, v) for every parameter: the rows' Hessians along
// each s_q on the run's model (constraint by constraint, its state and, where its type has no
// closed form, its row Hessians once for all parameters), and the twins' central difference of
// the velocity rows over the reached constraints (or of the whole velocity constraints along
// s_q, where the structure differs).
void KinematicSensitivities::velocity_sides(const double* q, const double* v, double t) {
  const int n = run_.nq();
  const double zero[3] = {0, 0, 0};
  Mat14 h[3];
  for (size_t k = 0; k < run_.constraints.size(); ++k) {
    const Constraint& c = run_.constraints[k];
    const LocalState s = gather(q, c.bi, c.bj);
    const Vec14 vl = gather_local(v, c.bi, c.bj);
    bool have_h = false;
    for (size_t i = 0; i < twins_.size(); ++i) {
      if (!reach_[i].local) continue;
      const Vec14 xq = gather_local(sq_cols_[i], c.bi, c.bj);
      Vec14 f1 = Vec14::Zero(), f2 = Vec14::Zero();
      double g[3] = {0, 0, 0};
      constraint_hessian_terms(c, s, xq, vl, zero, zero, f1, f2, g, h, have_h);
      for (int r = 0; r < c.rows(); ++r) sv_cols_[i][offsets_[k] + r] = -g[r];
    }
  }
  Row14 rows[3];
  for (size_t i = 0; i < twins_.size(); ++i) {
    const System& plus = *twins_[i].first;
    const System& minus = *twins_[i].second;
    const double d = deltas_[i];
    double* rhs = sv_cols_[i];
    if (!reach_[i].local) {
      for (int k = 0; k < n; ++k) qt_[k] = q[k] + d * sq_cols_[i][k];
      velocity_constraint_values(plus, offsets_, qt_.data(), v, t, a_.data());
      for (int k = 0; k < n; ++k) qt_[k] = q[k] - d * sq_cols_[i][k];
      velocity_constraint_values(minus, offsets_, qt_.data(), v, t, b_.data());
      for (int k = 0; k < n; ++k) rhs[k] = -(a_[k] - b_[k]) / (2 * d);
      continue;
    }
    for (int k : reach_[i].constraints) {
      const Constraint& cp = plus.constraints[k];
      const Constraint& cm = minus.constraints[k];
      const LocalState s = gather(q, cp.bi, cp.bj);
      double gp[3], gm[3];
      constraint_jacobian(cp, s, rows);
      velocity_rows(cp, rows, v, t, gp);
      constraint_jacobian(cm, s, rows);
      velocity_rows(cm, rows, v, t, gm);
      for (int r = 0; r < cp.rows(); ++r) rhs[offsets_[k] + r] -= (gp[r] - gm[r]) / (2 * d);
    }
  }
}

bool KinematicSensitivities::sensors(const std::vector<char>& modes, const CoordinateTurns* turns, const double* q,
                                     const double* v, double t, std::vector<std::vector<double>>& out,
                                     std::vector<std::vector<double>>& dq) {
  const int n = run_.nq();
  const int np = static_cast<int>(twins_.size());
  if (!factorize(q)) return false;
  for (int i = 0; i < np; ++i) position_side(i, q, t, sq_cols_[i]);
  if (!klu_.solve_many(sq_cols_.data(), np)) return false;
  velocity_sides(q, v, t);
  if (!klu_.solve_many(sv_cols_.data(), np)) return false;
  out.resize(np);
  dq.resize(np);
  for (int i = 0; i < np; ++i) {
    const double d = deltas_[i];
    // The sensors of each twin at its moved state.
    for (int side = 0; side < 2; ++side) {
      const double e = side == 0 ? d : -d;
      for (int k = 0; k < n; ++k) {
        qt_[k] = q[k] + e * sq_cols_[i][k];
        vt_[k] = v[k] + e * sv_cols_[i][k];
      }
      evaluate_sensors(side == 0 ? *twins_[i].first : *twins_[i].second, modes, qt_.data(), vt_.data(), nullptr, t,
                       side == 0 ? yp_.data() : ym_.data(), nullptr, turns);
    }
    out[i].resize(yp_.size());
    for (size_t k = 0; k < yp_.size(); ++k) out[i][k] = (yp_[k] - ym_[k]) / (2 * d);
    dq[i].assign(sq_cols_[i], sq_cols_[i] + n);
  }
  return true;
}

}  // namespace mbdae
