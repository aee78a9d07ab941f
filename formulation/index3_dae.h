// The index-3 DAE of a multibody system in absolute coordinates, for IDA:
//   y = [q, v, lambda],  y' = [q', v', lambda'] (lambda' unused)
//   F1 = q' - v                                  = 0
//   F2 = M(q) v' + Phi_q^T lambda - Q(q, v, t)   = 0
//   F3 = s Phi(q, t)                             = 0
// Only q is in the local error test (v and lambda are left out, IDASetId + IDASetSuppressAlg),
// with the velocity error per unit step by default (see error_weights).
// The constraint rows are scaled by s = m_ref / h_ref^2 so that they are of the size of the
// cj^2 M rows of the Newton matrix at the typical step h_ref.
// The Jacobian dF/dy + cj dF/dy' is exact: it includes d(M v')/dq, the gyroscopic derivatives,
// the applied forces' derivatives and sum_k lambda_k d2Phi_k/dq2.
// Modes, events, restarts, statistics and output are MultibodyDae's (shared with the other
// formulations).
#pragma once

#include <vector>

#include "core/sparse_assembler.h"
#include "formulation/multibody_dae.h"

namespace mbdae {

class Index3Dae : public MultibodyDae {
 public:
  // velocity_error_per_unit_step: formulation "index3" (true) or "index3-positions" (false).
  explicit Index3Dae(const System& sys, double constraint_scale = 1.0, bool velocity_error_per_unit_step = true);

  int size() const override { return 2 * nq_ + nc_; }
  // Rows 0..nq-1 are q' - v (assemble_kinematic_and_momentum).
  int kinematic_rows() const override { return nq_; }
  int residual(double t, const double* y, const double* yp, double* r) override;
  void error_test_mask(double* id) const override;
  // Weights of the error test and the Newton convergence test. Positions: with the velocity
  // error per unit step (formulation "index3", docs/formulation.md "Error control"), the
  // tolerances in model units times (h/T)^2 c, T the model's time scale: at index 3, v is the BDF
  // derivative of q, a local position error d gives a velocity error of about d/h, and (h/T)^2
  // keeps that below the velocity tolerance times h/T, so that the velocity errors of the steps
  // add up to about the velocity tolerance over T. c = min(S/T, 5, rtol / 1e-6) (at least 1,
  // span_factor), S the run's span: the errors add up over the run, not over T; the cap bounds
  // what that costs a long run, and rtol / 1e-6 keeps the rounding floor from coming sooner than
  // without c at the handover's rtol (formulation_registry.h). Never below the rounding of the
  // coordinates, never looser than the plain test. Without (index3-positions): rtol|q| + atol.
  // Velocities and multipliers are out of the error test; rounding in the position-level
  // constraints (eps) reaches them as eps/h and eps/h^2, so their tolerances are those of the
  // positions divided by h and h^2 (Hairer and Wanner, Solving ODEs II, VII.3):
  // rtol|v| + atol/h and rtol|lambda| + m_ref atol/h^2.
  void error_weights(double h, const double* y, double rtol, double atol, double* w) const override;

  bool velocities_error_tested() const override { return false; }
  // Output velocities from the interpolant of v (through the steps' velocities, one degree
  // higher than the derivative of the positions' interpolant, and measured more accurate:
  // spring-body energy 9.6e-9 against 1.6e-8).
  bool output_velocities_from_state() const override { return true; }

 private:
  void assemble(double t, double cj, const double* y, const double* yp) override;
  double scale_;
  // The position weights w (nq values) of the velocity error per unit step at step h.
  void velocity_error_per_unit_step(double h, const double* y, double rtol, double* w) const;
  // Rounding floor of the tested coordinates, relative to the model's positions (1e3 eps).
  static constexpr double kRoundingFloor = 1e3 * 2.220446049250313e-16;
  bool per_unit_step_;
};

}  // namespace mbdae
