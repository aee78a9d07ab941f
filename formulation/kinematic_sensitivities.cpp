#include "formulation/kinematic_sensitivities.h"

#include <cmath>

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
  // Phi_q's pattern (assemble_constraint_jacobian's calls, the same at every q), copied once
  // into phi_q_ with zero values; each sample assembles its values in place.
  asm_.begin_pattern(n, n);
  assemble_constraint_jacobian(run_, offsets_, run_.q0.data(), 1.0, 0, 0, -1, -1, asm_);
  asm_.finalize();
  const CscPattern& p = asm_.pattern();
  std::vector<double> zeros(p.nnz(), 0.0);
  phi_q_ = Eigen::Map<const Eigen::SparseMatrix<double>>(n, n, p.nnz(), p.colptr.data(), p.rowind.data(),
                                                         zeros.data());
  lu_.analyzePattern(phi_q_);
  rhs_.resize(n);
  for (auto* v : {&a_, &b_, &qt_, &vt_}) v->resize(n);
  yp_.resize(run_.sensors.size());
  ym_.resize(run_.sensors.size());
}

// Phi_q at q into phi_q_'s values (its pattern analysed once).
bool KinematicSensitivities::factorize(const double* q) {
  asm_.begin_values(phi_q_.valuePtr());
  assemble_constraint_jacobian(run_, offsets_, q, 1.0, 0, 0, -1, -1, asm_);
  asm_.end_values();
  lu_.factorize(phi_q_);
  if (lu_.info() == Eigen::Success) return true;
  failure_ = "the constraint Jacobian is singular at this kinematic sample (a dead centre?)";
  return false;
}

bool KinematicSensitivities::sensors(const std::vector<char>& modes, const CoordinateTurns* turns, const double* q,
                                     const double* v, double t, std::vector<std::vector<double>>& out,
                                     std::vector<std::vector<double>>& dq) {
  const int n = run_.nq();
  if (!factorize(q)) return false;
  out.resize(twins_.size());
  dq.resize(twins_.size());
  for (size_t i = 0; i < twins_.size(); ++i) {
    const System& plus = *twins_[i].first;
    const System& minus = *twins_[i].second;
    const double d = deltas_[i];
    // Positions: Phi_q s_q = -(Phi+(q) - Phi-(q)) / 2d.
    constraint_values(plus, offsets_, q, t, a_.data());
    constraint_values(minus, offsets_, q, t, b_.data());
    for (int k = 0; k < n; ++k) rhs_[k] = -(a_[k] - b_[k]) / (2 * d);
    sq_ = lu_.solve(rhs_);
    // Velocities: Phi_q s_v = -(g+(q + d s_q, v) - g-(q - d s_q, v)) / 2d, g = Phi_q v + Phi_t.
    for (int k = 0; k < n; ++k) qt_[k] = q[k] + d * sq_[k];
    velocity_constraint_values(plus, offsets_, qt_.data(), v, t, a_.data());
    for (int k = 0; k < n; ++k) qt_[k] = q[k] - d * sq_[k];
    velocity_constraint_values(minus, offsets_, qt_.data(), v, t, b_.data());
    for (int k = 0; k < n; ++k) rhs_[k] = -(a_[k] - b_[k]) / (2 * d);
    sv_ = lu_.solve(rhs_);
    // The sensors of each twin at its moved state.
    for (int side = 0; side < 2; ++side) {
      const double e = side == 0 ? d : -d;
      for (int k = 0; k < n; ++k) {
        qt_[k] = q[k] + e * sq_[k];
        vt_[k] = v[k] + e * sv_[k];
      }
      evaluate_sensors(side == 0 ? plus : minus, modes, qt_.data(), vt_.data(), nullptr, t,
                       side == 0 ? yp_.data() : ym_.data(), nullptr, turns);
    }
    out[i].resize(yp_.size());
    for (size_t k = 0; k < yp_.size(); ++k) out[i][k] = (yp_[k] - ym_[k]) / (2 * d);
    dq[i].assign(sq_.data(), sq_.data() + n);
  }
  return true;
}

}  // namespace mbdae
