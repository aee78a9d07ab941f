// Forward sensitivities s_i = dy/dp_i of a DaeProblem's solution to parameters p_i, integrated
// by IDAS alongside the solution (core/ida_driver.h): the sensitivity equations
//   F_y s_i + F_y' s_i' + F_p_i = 0
// share the solution's Newton matrix. The integrator knows nothing of what the parameters are:
// the problem gives the equations' residual, consistent values at (re)starts and a scale per
// parameter for the error weights.
#pragma once

namespace mbdae {

class SensitivityProblem {
 public:
  virtual ~SensitivityProblem() = default;
  virtual int count() const = 0;
  // A typical magnitude of parameter i (IDAS's pbar: the sensitivities are weighted as
  // pbar_i s_i, a change of the state in its own units).
  virtual double scale(int i) const = 0;
  // r[i] = F_y s[i] + F_y' sp[i] + F_p_i at (t, y, y'), whose residual is `residual` (the
  // problem's own F there). 0 on success, > 0 recoverable, < 0 fatal (IDA's convention).
  virtual int residual(double t, const double* y, const double* yp, const double* residual,
                       const double* const* s, const double* const* sp, double* const* r) = 0;
  // Whether residual() reads its `residual` argument; if not, the integrator may leave it
  // unevaluated.
  virtual bool reads_state_residual() const { return true; }
  // Consistent (s[i], sp[i]) at the start, (y, y') consistent there. Throws SolveError.
  virtual void initial(double t, const double* y, const double* yp, double* const* s, double* const* sp) = 0;
  // After the problem's restart at t: consistent (s[i], sp[i]) from the s[i] before it, (y, y')
  // the state the restart started from (at an impulsive restart, a drive's kink, the run's
  // velocities jump, and the sensitivities follow the restart's map at that state). Throws
  // SolveError on failure.
  virtual void restart(double t, const double* y, const double* yp, double* const* s, double* const* sp) = 0;
  // At a breakpoint t_b (an input's jump at a fixed time, DaeProblem::breakpoints), before
  // restart(): s[i] += (y'- - y'+) dt_b/dp_i on the differential unknowns, the jump that the
  // breakpoint's own dependence on p_i gives (y'- the derivative IDA reached t_b with, y'+ the
  // restarted one). Nothing for parameters that do not move it.
  virtual void jump_at_breakpoint(double /*t*/, const double* /*yp_before*/, const double* /*yp_after*/,
                                  double* const* /*s*/) {}
  // The segment the integrator works on (DaeProblem::set_segment), for the problem's own copies.
  virtual void set_segment(double /*t_start*/, double /*t_end*/) {}
  // Whether the sensitivities are in the local error test (else only in the Newton test).
  virtual bool in_error_test() const { return false; }
};

}  // namespace mbdae
