// What every multibody formulation shares, whatever its unknowns beyond y = [q, v, ...]:
// modes of switching forces (wheel contact) and their events, restarts at events and
// breakpoints, inputs evaluated with their left limit at the end of a segment, the initial step,
// per-step statistics (constraint violation at position and velocity level, Euler-norm drift),
// consistent initial values of q, v, accelerations and multipliers, the projected output, the
// rows F1 = q' - v and F2 = M v' + Phi_q^T lambda - Q with their Newton-matrix blocks, and the
// Newton matrix's sparse pattern (recorded once) and value pass.
//
// A formulation derives from MultibodyDae and provides size(), the residual, assemble() (its
// Newton matrix by add() calls; record_pattern() at the end of its constructor), the error-test
// mask and weights. The first 2 nq components of y must be q and v, the next nc lambda; any
// further unknowns start at zero (consistent_initial_values()). What changes during a run lives
// in its RunState (state()), not in the model.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/dae_problem.h"
#include "core/sparse_assembler.h"
#include "formulation/augmented_solver.h"
#include "formulation/run_state.h"
#include "formulation/system.h"

namespace mbdae {

// Absolute tolerances in the model's units (formulation/tolerance_scales.h): positions [m],
// Euler parameters [1], velocities [m/s], Euler-parameter rates [1/s]. All zero: the single
// atol the integrator passes applies to every component (the behaviour before issue 13).
struct AbsoluteTolerances {
  double position = 0, rotation = 0, velocity = 0, rotation_rate = 0;
  double time = 1;  // [s] the model's time scale (velocity scale length / time)
  double length = 1;  // [m] the model's length scale
  double span = 0;    // [s] the span of the run (0: unknown, no control per unit of span)
  bool set() const { return position > 0; }
};

class MultibodyDae : public DaeProblem {
 public:
  explicit MultibodyDae(const System& sys);

  const CscPattern& jacobian_pattern() override { return asm_.pattern(); }
  // dF/dy + cj dF/dy' on the recorded pattern: assemble() in value mode.
  int jacobian(double t, double cj, const double* y, const double* yp, double* values) override;

  // Names: positions, velocities, then "multiplier of <constraint>" for the next nc
  // components; formulations with more unknowns override this.
  std::string component_name(int i) const override;
  int num_switches() const override { return static_cast<int>(switch_forces_.size()); }
  void switches(double t, const double* y, double* g) override;
  // New modes (flipped switches after an event; all from signs at a breakpoint), then
  // consistent_initial_values() at t from the current q and v.
  void restart(double t, double* y, double* yp, const int* roots_found) override;
  bool changes_mode(double t, const double* y, const int* roots_found) override;
  // First backward-Euler step whose local error h^2/2 |q''| is about the tolerance.
  double initial_step(double t, const double* y, const double* yp, double rtol, double atol) override;
  std::vector<double> breakpoints() const override { return sys_.breakpoints(); }
  // Records max |Phi|, max |Phi_q v + Phi_t| and max | |p| - 1 | of the step's solution.
  void after_step(double t, const double* y) override;
  void set_segment(double t_start, double t_end) override { segment_end_ = t_end; }
  // Time at which inputs (drives, ground profiles, forces) are evaluated: t itself, except at
  // the end of the current segment, where a jump must not be seen yet (left limit). The cap is
  // 16 roundings below the end (IDA lands within one of it): a wider window freezes the inputs
  // there, an error of rate x width (1e-13 s made rtol 1e-13 fail at a drive's kink).
  double input_time(double t) const {
    const double cap = segment_end_ - 16 * 2.220446049250313e-16 * (1.0 + std::fabs(segment_end_));
    if (t < inputs_from_) return inputs_from_;
    return t < cap ? t : cap;
  }
  // Inputs before t_start are held at their value at t_start (the right limit of a jump there):
  // a sensitivity twin whose breakpoint lies after the run's sees its own jump already where the
  // run's segment starts (formulation/twin_sensitivities.h). -inf (the default): no hold.
  void hold_inputs_from(double t_start) { inputs_from_ = t_start; }

  // Consistent initial values from the q and v in y: q and v projected onto the constraints,
  // y' = [v, a, 0...], lambda after v, the unknowns beyond 2 nq + nc (GGL's mu) zero.
  void consistent_initial_values(double t, std::vector<double>& y, std::vector<double>& yp);
  // out = F_y' x, the residual's derivative with respect to y' times x (size() values; every
  // formulation's F is affine in y'): the shared rows' x_q (F1) and M(q) x_v (F2), zero for the
  // formulation's own rows unless it overrides this (Index1Dae: its rows hold Phi_q v').
  virtual void derivative_times(const double* y, const double* x, double* out);
  // out[i] += F_y x[i] for i < count, F_y the Newton matrix at cj = 0 at (t, y, y'), without
  // assembling it: the assembling code in a product pass (SparseAssembler::begin_product), or a
  // formulation's own products (GglDae: each constraint's rows and row Hessians computed once
  // for all its uses and all x). The sensitivities' F_y s (formulation/twin_sensitivities.h).
  virtual void jacobian_times(double t, const double* y, const double* yp, int count, const double* const* x,
                              double* const* out);
  // Constraint k's own terms of the residual at (t, y): its rows of F1 and F2 on its two bodies'
  // local coordinates [ri, pi, rj, pj] and its own rows of the formulation's constraint blocks
  // (up to 3 each), for F_p over the constraints a parameter reaches (formulation/parameter_reach.h).
  // Only where gives_constraint_terms() (elsewhere F_p takes whole residuals).
  struct ConstraintTerms {
    Vec14 f1, f2;
    double rows[2][3];
  };
  virtual bool gives_constraint_terms() const { return false; }
  virtual void constraint_terms(double /*t*/, const double* /*y*/, int /*k*/, ConstraintTerms& /*out*/) const {}
  // Output state from an interpolated (y, y'): optionally projected onto the constraint
  // manifold (positions and velocities), then the accelerations solved from it. Returns the
  // position violation of the interpolated y. (Same contract as Index3Dae::consistent_output.)
  // Velocities are taken from y when they are in the error test (velocities_error_tested()),
  // else from the derivative of the positions' interpolant, q' in y'.
  double consistent_output(double t, const double* y, const double* yp, std::vector<double>& q,
                           std::vector<double>& v, std::vector<double>& a, bool project);
  // Whether v is in the local error test (then its interpolant is error-controlled).
  virtual bool velocities_error_tested() const = 0;
  // Whether output velocities come from the interpolant of v (else from q' in y').
  virtual bool output_velocities_from_state() const { return velocities_error_tested(); }
  bool output_needs_derivative() const override { return !output_velocities_from_state(); }

  // The run state (formulation/run_state.h): modes, turns, output settings, statistics, the
  // output failure and the per-evaluation cache. The model, system(), never changes.
  RunState& state() { return state_; }
  const RunState& state() const { return state_; }
  int nq() const { return nq_; }
  int nc() const { return nc_; }
  const System& system() const { return sys_; }
  int constraint_offset(int k) const { return offsets_[k]; }
  AugmentedSolver& augmented() { return aug_; }

 protected:
  // Projects q (positions) and v (velocities) onto the constraints at t and solves the
  // accelerations a and multipliers lambda with the current modes. Throws SolveError.
  void consistent_state(double t, double* q, double* v, double* a, double* lambda);
  // The formulation's Newton matrix, by add() calls on asm_ (the same calls for the pattern and
  // for the values).
  virtual void assemble(double t, double cj, const double* y, const double* yp) = 0;
  // Records asm_'s pattern (from q0) and sizes work_: the last line of a formulation's
  // constructor (assemble() is virtual, so the base constructor cannot call it).
  void record_pattern();
  // The rows every formulation shares, at y = [q, v, lambda, ...], y' = [q', v', ...]:
  //   F1 = q' - v  (rows 0..nq),   F2 = M(q) v' + Phi_q^T lambda - Q(q, v, t)  (rows nq..2nq).
  // `force_work` holds nq values. Computes the constraint Jacobian rows at q into the run
  // state's cache (constraint_rows()), for the formulation's own rows of the same residual.
  void kinematic_and_momentum_residual(double t, const double* y, const double* yp, double* r,
                                       double* force_work);
  const std::vector<Row14>& constraint_rows() const { return state_.cache.constraint_rows; }
  // Their Newton-matrix blocks: F1's cj I and -I; F2's cj M, d(M v')/dq with the gyroscopic
  // derivatives, -dQ/dq, -dQ/dv and sum_k lambda_k d2Phi_k/dq2. (Phi_q^T in F2's lambda
  // columns is added by the formulation with its constraint rows.)
  void assemble_kinematic_and_momentum(double t, double cj, const double* y, const double* yp,
                                       SparseAssembler& a) const;
  // 0, or 1 (IDA: recoverable, retry with a smaller step) if r has a non-finite entry.
  static int finite_or_retry(const double* r, int n);
  // Label of the constraint owning stacked constraint row `row`.
  std::string constraint_label(int row) const;
  // Rounding noise of the positions through the constraints: about 1e3 eps max(1, |q|).
  double position_noise(const double* y) const;
  // Absolute tolerances never below what rounding lets the Newton iteration resolve (an atol
  // under that asks for digits that do not exist): positions ten roundings of the largest
  // coordinate; velocities ten roundings of the largest velocity, and ten roundings of the
  // largest coordinate per step (a velocity below that moves no coordinate by a rounding within
  // the step). The step is the integrator's own, 1/cj of the last Newton matrix (cj = alpha/h,
  // alpha in [1, 2.3] for BDF orders 1-5), not the h of error_weights(): the driver passes a
  // deliberately small h there (loose multiplier weights after failures), which would loosen
  // the error test of v. Without the floor, an atol of 1e-15 fails on the suspension at rest,
  // where v is rounding noise of about 1e-15 m/s. `h` is used before the first Newton matrix.
  double position_atol(const double* y, double atol) const;
  double velocity_atol(double h, const double* y, double atol) const;
  // Error weights of the positions, w_i = 1 / (rtol |q_i| + aq), the same for every coordinate
  // (the Euler parameters against their own size, not their norm: docs/formulation.md, "Error
  // control").
  void position_weights(const double* y, double rtol, double aq, double* w) const;
  double newton_cj_ = 0;  // cj of the last Newton matrix (set by jacobian())

 public:
  // The rtol below which index3 hands over to index2-ggl (formulation_registry.h's
  // kIndex3HandoverRtol is this value): the span factor is at most rtol / kSpanRtol.
  static constexpr double kSpanRtol = 1e-6;
  // Per-kind absolute tolerances (set once, before integrating; see AbsoluteTolerances).
  void set_absolute_tolerances(const AbsoluteTolerances& a) { abs_tol_ = a; }
  const AbsoluteTolerances& absolute_tolerances() const { return abs_tol_; }

 protected:
  // Weights of q and v, w_i = 1 / (rtol |y_i| + a_i), a_i the absolute tolerance of the
  // component's kind (position or Euler parameter, velocity or Euler-parameter rate; `atol` for
  // all when no model-unit tolerances are set), floored at rounding (position_atol,
  // velocity_atol).
  void state_weights(double h, const double* y, double rtol, double atol, double* w) const;
  // Error per unit of the run's span (index2-ggl, index1, penalty; docs/formulation.md "Error
  // control"): the weights of q and v (the first 2 nq of w) tightened by S/h, S the span and h
  // the integrator's step, so that the local errors of the steps add up to about the tolerance
  // over the run; never looser than before, never tighter than 100 roundings of the model's
  // positions (max(L, |r|)) and velocities (max(L/T, |v|, |r| / noise_step)): `noise_step` is the
  // time over which a position's rounding counts as velocity noise (h, or sqrt(h S) where that
  // noise adds up as a random walk: GglDae::error_weights). The velocities' weights are further
  // tightened by `velocity_factor` (GglDae: span_factor), and their floor is `velocity_roundings`
  // roundings instead of 100 (Index1Dae: 5).
  void error_per_unit_span(double h, double noise_step, const double* y, double* w, double velocity_factor = 1.0,
                           double velocity_roundings = 100.0) const;
  // The span factor c of a control whose velocity errors add up into positions over the run (a
  // phase that drifts): S / T, at most kSpanCap and at most rtol / 1e-6, the rtol of index3's
  // handover (at the handover's rtol the control measured down to its rounding floor), at least 1
  // (docs/formulation.md, "index3 per unit of the span, capped").
  double span_factor(double rtol) const;
  static constexpr double kSpanCap = 5.0;
  // The model's position scale for the rounding floors: max(L, |x| + |y| + |z| of every body's
  // origin), L the model's length (AbsoluteTolerances).
  double position_magnitude(const double* y) const;
  static constexpr double kSpanRoundingFloor = 1e2 * 2.220446049250313e-16;
  // How often the error control asked for positions below their rounding: calls of the weights,
  // and those where the rounding floor replaced the control's tolerance for most position
  // components (the error then stops following rtol: docs/formulation.md, "Error control").
  struct FloorCount {
    long weights = 0, floored = 0;
  };
  mutable FloorCount floor_count_;
  void count_floor(int floored_components) const {
    ++floor_count_.weights;
    if (2 * floored_components > nq_) ++floor_count_.floored;
  }

 public:
  // The fraction of error-weight evaluations whose position tolerances sat at the rounding
  // floor (0 for a control without one).
  double rounding_floor_fraction() const {
    return floor_count_.weights ? double(floor_count_.floored) / floor_count_.weights : 0.0;
  }

 protected:
  // The integrator's step: 1/cj of the last Newton matrix (h before the first one).
  double newton_step(double h) const { return newton_cj_ > 0 ? 1.0 / newton_cj_ : h; }
  AbsoluteTolerances abs_tol_;

  const System& sys_;
  std::vector<int> offsets_;
  int nq_, nc_;
  ConstraintRowsPattern rows_pattern_;  // Phi_q's structural entries (the residuals' Phi_q^T lambda)
  double mass_scale_ = 1e-3;  // largest body mass (multipliers are forces: mass-scaled weights)
  double segment_end_ = 1e300;
  double inputs_from_ = -1e300;
  std::vector<int> switch_forces_;
  // Per switching function, its value at the last restart where that value disagreed with the
  // mode (else 0): the root function is g - offset, so that the next crossing is seen (restart).
  std::vector<double> switch_offsets_;
  void set_switch_offsets(double t, const double* y);
  AugmentedSolver aug_;
  RunState state_;
  std::vector<double> stat_work_, out_phi_;
  long condition_samples_ = 0;
  SparseAssembler asm_;        // the Newton matrix's pattern and slot table
  std::vector<double> work_;   // size() values for the residual
};

}  // namespace mbdae
