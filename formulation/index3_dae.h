// The index-3 DAE of a multibody system in absolute coordinates, for IDA:
//   y = [q, v, lambda],  y' = [q', v', lambda'] (lambda' unused)
//   F1 = q' - v                                  = 0
//   F2 = M(q) v' + Phi_q^T lambda - Q(q, v, t)   = 0
//   F3 = s Phi(q, t)                             = 0
// Only q is in the local error test (v and lambda are left out, IDASetId + IDASetSuppressAlg).
// The constraint rows are scaled by s = m_ref / h_ref^2 so that they are of the size of the
// cj^2 M rows of the Newton matrix at the typical step h_ref.
// The Jacobian dF/dy + cj dF/dy' is exact: it includes d(M v')/dq, the gyroscopic derivatives,
// the applied forces' derivatives and sum_k lambda_k d2Phi_k/dq2.
#pragma once

#include <cmath>
#include <vector>

#include "core/dae_problem.h"
#include "formulation/augmented_solver.h"
#include "formulation/system.h"

namespace mbdae {

class Index3Dae : public DaeProblem {
 public:
  explicit Index3Dae(const System& sys, double constraint_scale = 1.0);

  int size() const override { return 2 * nq_ + nc_; }
  const CscPattern& jacobian_pattern() override { return asm_.pattern(); }
  int residual(double t, const double* y, const double* yp, double* r) override;
  int jacobian(double t, double cj, const double* y, const double* yp, double* values) override;
  void error_test_mask(double* id) const override;
  // Weights of the Newton convergence test. Velocities and multipliers are out of the error
  // test; rounding in the position-level constraints (eps) reaches them as eps/h and eps/h^2,
  // so their tolerances are those of the positions divided by h and h^2 (Hairer and Wanner,
  // Solving ODEs II, VII.3): rtol|v| + atol/h and rtol|lambda| + m_ref atol/h^2.
  void error_weights(double h, const double* y, double rtol, double atol, double* w) const override;
  std::string component_name(int i) const override;
  int num_switches() const override { return static_cast<int>(switch_forces_.size()); }
  void switches(double t, const double* y, double* g) override;
  void restart(double t, double* y, double* yp, const int* roots_found) override;
  bool changes_mode(double t, const double* y, const int* roots_found) override;
  // First backward-Euler step whose local error h^2/2 |q''| is about the tolerance.
  double initial_step(double t, const double* y, const double* yp, double rtol, double atol) override;
  std::vector<double> breakpoints() const override { return sys_.breakpoints(); }
  void after_step(double t, const double* y) override;
  void set_segment(double t_start, double t_end) override { segment_end_ = t_end; }
  // Time at which inputs (drives, ground profiles, forces) are evaluated: t itself, except at
  // the end of the current segment, where a jump must not be seen yet (left limit). The cap is
  // 16 roundings below the end (IDA lands within one of it): a wider window freezes the inputs
  // there, an error of rate x width (1e-13 s made rtol 1e-13 fail at a drive's kink).
  double input_time(double t) const {
    const double cap = segment_end_ - 16 * 2.220446049250313e-16 * (1.0 + std::fabs(segment_end_));
    return t < cap ? t : cap;
  }

  // Consistent initial values at rest or from given q, v: solves accelerations and multipliers.
  void consistent_initial_values(double t, std::vector<double>& y, std::vector<double>& yp);
  // Output state from an interpolated (y, y'): optionally projected onto the constraint manifold
  // (positions and velocities), then the accelerations solved from it. Returns the position
  // violation of the interpolated y.
  double consistent_output(double t, const double* y, const double* yp, std::vector<double>& q,
                           std::vector<double>& v, std::vector<double>& a, bool project);

  std::vector<char> modes;         // per force: wheel in contact
  double max_position_violation = 0;  // over accepted steps (integrator's own solution)
  // Solve accelerations for output samples (only needed by acceleration sensors).
  bool output_accelerations = true;
  double max_norm_drift = 0;          // max | |p| - 1 | over accepted steps
  // Conditioning of the constraints along the run (computed at output samples when
  // track_condition is set: one extra factorization per sample).
  bool track_condition = false;
  double max_condition = 0.0, max_condition_time = 0.0;
  int nq() const { return nq_; }
  int nc() const { return nc_; }
  const System& system() const { return sys_; }
  AugmentedSolver& augmented() { return aug_; }

 private:
  void assemble(double t, double cj, const double* y, const double* yp);
  void track_conditioning(double t, const double* q);
  const System& sys_;
  std::vector<int> offsets_;
  int nq_, nc_;
  double scale_;
  double mass_scale_ = 1e-3;
  double segment_end_ = 1e300;
  long condition_samples_ = 0;
  std::vector<int> switch_forces_;
  SparseAssembler asm_;
  AugmentedSolver aug_;
  std::vector<double> work_, out_phi_, out_phi2_;
};

}  // namespace mbdae
