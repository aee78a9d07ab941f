// Forward sensitivities of a multibody run to scene parameters, for IDAS
// (core/sensitivity_problem.h), by twins: for each parameter p_i two copies of the run's
// formulation, built on the model with p_i + d_i and p_i - d_i (their own Systems, with the
// same coordinates and equations), whose modes and turns follow the run's. The sensitivity
// equations' residual is
//
//   F_y s + F_y' s' + F_p  =  A0 s  +  F_y' s'  +  [F+(y, y') - F-(y, y')] / (2 d),
//
// A0 = F_y the formulation's own Newton matrix at cj = 0, A0 s exact without assembling it
// (MultibodyDae::jacobian_times: one pass over the kernels per call for all parameters, on a
// copy of the run's DAE; until 2026-11-28 A0 was assembled at every call); F_y' s' exact, from the formulation
// (MultibodyDae::derivative_times: every formulation's F is affine in y', F_y' holds the
// identity, the mass matrix and index1's Phi_q); F_p the twins' central difference at the same
// (y, y'), where the terms that do not depend on p are evaluated bit for bit alike and cancel,
// so that no parameter needs code of its own (force parameters, masses, hardpoints, gravity,
// expression constants alike). Until 2026-11-27 F_y s + F_p was one central difference of the
// twins along s, [F+(y + d s, y') - F-(y - d s, y')] / (2 d), with A0 only after its failures:
// its truncation, d^2 times the third derivative along (s, 1), put A05's sensitivities 1.8e-1
// off (docs/sensitivities.md, Method).
// F_p takes two whole residuals of the twins only where the parameter changes the model's
// structure, or reaches a constraint and the formulation gives no constraint terms
// (formulation/parameter_reach.h); a force's stiffness, a body's mass, gravity or a hardpoint
// difference just the terms they reach, the same central difference without the cancelling rest.
// Consistent (s, s') at a restart are central differences of the twins' own consistent values
// at y +- d s; the sensors' sensitivities at a sample the twins' sensors at y +- d s with the
// accelerations' sensitivity solved on the run's own output factorization (sensors_by_derivative;
// the twins' own consistent outputs where that is not possible).
// A parameter that moves a breakpoint t_b (the time of an input's jump: a ground step, a point
// force's step): each twin keeps its own breakpoint, the run's segment mapped onto the twin's
// (its inputs held at their left limit before its t_b and at their right limit after it, so
// that F_p is not the jump over 2 d where the twins' t_b straddle the run's time), and at the
// run's t_b the sensitivities jump by (y'- - y'+) dt_b/dp on q and v (an ODE's classic jump
// condition: q and v are continuous there, v' jumps), dt_b/dp the twins' difference of t_b.
#pragma once

#include <memory>
#include <vector>

#include "core/sensitivity_problem.h"
#include "formulation/multibody_dae.h"
#include "formulation/parameter_reach.h"

namespace mbdae {

struct ParameterTwins {
  std::unique_ptr<MultibodyDae> plus, minus;  // the formulation on the model at p + d, p - d
  double delta = 0;  // d, in the parameter's units
  double scale = 1;  // a typical magnitude of the parameter (IDAS's pbar)
  // Each twin's consistent initial (y, y') from its own chain of analyses.
  std::vector<double> y_plus, yp_plus, y_minus, yp_minus;
  std::vector<double> breakpoints_plus, breakpoints_minus;  // each twin's (set by TwinSensitivities)
  // The residual terms p reaches (set by TwinSensitivities); whole_residuals: F_p from the twins'
  // whole residuals whatever the reach (a check of the reach).
  ParameterReach reach;
  bool whole_residuals = false;
};

class TwinSensitivities : public SensitivityProblem {
 public:
  // `run` is the formulation being integrated; the twins must have its size.
  // `base` is another copy of the run's formulation on the run's own model (its Newton matrix).
  TwinSensitivities(MultibodyDae& run, std::unique_ptr<MultibodyDae> base, std::vector<ParameterTwins> twins,
                    bool in_error_test);

  int count() const override { return static_cast<int>(twins_.size()); }
  double scale(int i) const override { return twins_[i].scale; }
  int residual(double t, const double* y, const double* yp, const double* residual, const double* const* s,
               const double* const* sp, double* const* r) override;
  void initial(double t, const double* y, const double* yp, double* const* s, double* const* sp) override;
  void restart(double t, const double* y, const double* yp, double* const* s, double* const* sp) override;
  void set_segment(double t_start, double t_end) override;
  void jump_at_breakpoint(double t, const double* yp_before, const double* yp_after, double* const* s) override;
  bool in_error_test() const override { return in_error_test_; }
  bool reads_state_residual() const override { return false; }
  // d(sensor k)/d(p_i) at a sample (out[i][k], sys.sensors order): the twins' sensors at
  // y +- d s_i, with accelerations from the run's own output solve (sensors_by_derivative;
  // called after the run's output sample at t) or, projected when `project`, the twins' own
  // consistent outputs. False, with `failure` set, when a twin's output state cannot be formed.
  bool sensors(double t, const double* y, const double* yp, const double* const* s, const double* const* sp,
               bool project, std::vector<std::vector<double>>& out);
  const std::string& failure() const { return failure_; }
  const ParameterTwins& twins(int i) const { return twins_[i]; }

 private:
  void follow(MultibodyDae& twin);  // the run's modes and turns
  int add_parameter_difference(double t, const double* y, const double* yp, ParameterTwins& p, double* r);
  int add_reached_difference(double t, const double* y, const double* yp, ParameterTwins& p, double* r);

  int run_breakpoint(double t) const;  // the index of t among the run's breakpoints, or -1
  bool sensors_by_twins(double t, const double* y, const double* yp, const double* s, const double* sp, bool project,
                        ParameterTwins& p);
  bool sensors_by_derivative(double t, const double* y, const double* yp, const double* s, const double* sp,
                             ParameterTwins& p);

  MultibodyDae& run_;
  std::vector<double> breakpoints_;  // the run's
  std::unique_ptr<MultibodyDae> base_;
  std::vector<ParameterTwins> twins_;
  bool in_error_test_;
  std::vector<double> yt_, ypt_, rp_, rm_;  // work (size of the DAE)
  std::vector<double> qo_, vo_, ao_, sp_plus_, sp_minus_;
  std::vector<double> qp_, qm_, vp_, vm_, at_, g_, xp_;  // sensors_by_derivative's work
  std::string failure_;
};

}  // namespace mbdae
