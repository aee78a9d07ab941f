// Stabilized index-2 formulation (Gear, Gupta and Leimkuhler 1985) of a multibody system in
// absolute coordinates, for IDA:
//   y = [q, v, lambda, mu]   (nq, nq, nc, nc),   y' = [q', v', -, -] (lambda', mu' unused)
//   F1 = q' - v + Phi_q^T mu                      = 0
//   F2 = M(q) v' + Phi_q^T lambda - Q(q, v, t)    = 0
//   F3 = s Phi(q, t)                              = 0
//   F4 = s (Phi_q v + Phi_t)                      = 0
// Both the position and the velocity constraints hold at every step; the extra multiplier mu
// (zero in the exact solution) lets q leave the velocity integral by what the position
// constraints require. The system has index 2: q and v are differential variables, lambda
// and mu index-2 algebraic ones.
//
// Error test: q always; v by default (velocities_in_error_test): at index 2 the BDF error of v
// is controlled the same way as for an ODE (Brenan, Campbell, Petzold, Numerical Solution of
// IVPs in DAEs, 3.2: BDF converges with order k for all components of a Hessenberg index-2
// system, and only the index-2 variables need to be left out of the error estimate).
// lambda and mu are left out (IDASetSuppressAlg). Tolerances per unit of the run's span (issue
// 21: the local errors of the steps add up to the tolerance over the run). With v in the test
// the phase of the solution is error-controlled (measured: docs/formulation.md, "The index-2
// GGL formulation").
//
// The constraint rows are scaled by s (constraint_scale) for the conditioning of the Newton
// matrix; the solution does not depend on it.
//
// The Jacobian dF/dy + cj dF/dy' is exact: besides the index-3 blocks (mass, gyroscopic and
// applied-force derivatives, sum_k lambda_k H_k in F2) it has sum_k mu_k H_k in F1 and the rows
// (H_k v)^T = d(Phi_q v)/dq in F4 (formulation/constraint_rates.h), H_k = d2Phi_k/dq2.
#pragma once

#include "core/sparse_assembler.h"
#include "formulation/multibody_dae.h"

namespace mbdae {

class GglDae : public MultibodyDae {
 public:
  explicit GglDae(const System& sys, double constraint_scale = 1.0,
                  bool velocities_in_error_test = true);

  int size() const override { return 2 * nq_ + 2 * nc_; }
  int residual(double t, const double* y, const double* yp, double* r) override;
  void error_test_mask(double* id) const override;
  // Newton-test (and error-test) weights. Positions: rtol|q| + atol. Velocities: rtol|v| +
  // atol (with v in the test: both per unit of the run's span, times h / S, error_per_unit_span,
  // when the model's tolerances are set, v's also times 1 / span_factor(rtol)), plus the rounding floor of the positions amplified by 1/h when v is out of the
  // error test (atol floored at ten roundings of the largest |q|, |v|). The index-2 multipliers are a correction per step, of the size of the
  // error of q (mu) or of M v (lambda) divided by h: rtol|mu| + (atol + noise)/h and
  // rtol|lambda| + m_ref (atol + noise/h)/h.
  void error_weights(double h, const double* y, double rtol, double atol, double* w) const override;
  std::string component_name(int i) const override;
  // F_y x[i] without the assembly: the inertia and force terms as products with x
  // (inertia_derivatives_times, force_derivatives_times); each constraint's rows once for Phi_q
  // and Phi_q^T of every x[i], and its three Hessian terms (sum mu_k H_k, sum lambda_k H_k,
  // (H_k v)^T) by constraint_hessian_terms; the assembly computes the Hessians five times for a
  // three-row constraint and stores the matrix.
  void jacobian_times(double t, const double* y, const double* yp, int count, const double* const* x,
                      double* const* out) override;
  // Phi_q^T mu (F1) and Phi_q^T lambda (F2) of constraint k, and its rows of F3 = s Phi and
  // F4 = s (Phi_q v + Phi_t) (rows[0], rows[1]).
  bool gives_constraint_terms() const override { return true; }
  void constraint_terms(double t, const double* y, int k, ConstraintTerms& out) const override;

  bool velocities_error_tested() const override { return v_in_test_; }

 private:
  void assemble(double t, double cj, const double* y, const double* yp) override;
  double scale_;
  bool v_in_test_;
};

}  // namespace mbdae
