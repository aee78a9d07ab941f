// A DAE F(t, y, y') = 0 as the integrator sees it: residual, sparse Jacobian dF/dy + cj dF/dy'
// on a fixed pattern, switching functions for events, and a restart hook that makes (y, y')
// consistent after an event or a breakpoint. The multibody formulations implement this; the
// integrator (ida_driver) knows nothing of bodies.
#pragma once

#include <string>
#include <vector>

#include "core/sparse_assembler.h"

namespace mbdae {

class DaeProblem {
 public:
  virtual ~DaeProblem() = default;
  virtual int size() const = 0;
  virtual const CscPattern& jacobian_pattern() = 0;
  // Return 0 on success, > 0 for a recoverable failure, < 0 for a fatal one (IDA's convention).
  virtual int residual(double t, const double* y, const double* yp, double* r) = 0;
  virtual int jacobian(double t, double cj, const double* y, const double* yp, double* values) = 0;
  // 1 for components in the local error test, 0 for those left out (algebraic, velocities and
  // multipliers of an index-3 system).
  virtual void error_test_mask(double* id) const = 0;
  // Weights of the error test and of the Newton convergence test, 1 / tolerance per component,
  // for the step size h about to be attempted. The default is IDA's own 1/(rtol|y| + atol).
  virtual void error_weights(double h, const double* y, double rtol, double atol, double* w) const {
    for (int i = 0; i < size(); ++i) w[i] = 1.0 / (rtol * (y[i] < 0 ? -y[i] : y[i]) + atol);
  }
  virtual std::string component_name(int i) const { return "y[" + std::to_string(i) + "]"; }
  // nq > 0 when rows 0..nq-1 are exactly F_i = y'_i - y_{nq+i} (the kinematic rows q' - v): the
  // integrator can eliminate the velocity corrections from its Newton solves
  // (IdaOptions::reduced_newton, core/reduced_linear_solver.h). 0: no such structure, or not to be
  // used (index1: docs/formulation.md, "The reduced Newton solve").
  virtual int kinematic_rows() const { return 0; }

  // Event functions g(t, y) whose sign changes are located by root finding.
  virtual int num_switches() const { return 0; }
  virtual void switches(double /*t*/, const double* /*y*/, double* /*g*/) {}
  // After an event (roots_found non-null, IDA's +-1/0 per switch) or at a breakpoint (null):
  // update modes and make (y, y') consistent at t. Throws SolveError on failure.
  virtual void restart(double /*t*/, double* /*y*/, double* /*yp*/, const int* /*roots_found*/) {}
  // A first step for a (re)start at (t, y, y'), or 0 for the integrator's default.
  virtual double initial_step(double /*t*/, const double* /*y*/, const double* /*yp*/,
                              double /*rtol*/, double /*atol*/) {
    return 0.0;
  }
  // Whether the roots found would change a mode (false: the event is ignored).
  virtual bool changes_mode(double /*t*/, const double* /*y*/, const int* /*roots_found*/) { return true; }
  // Times where the problem's inputs are not smooth; the integrator stops and restarts there.
  virtual std::vector<double> breakpoints() const { return {}; }
  // The integrator works on [t_start, t_end] up to the next breakpoint: inputs that jump at
  // t_end must be evaluated with their left limit there.
  virtual void set_segment(double /*t_start*/, double /*t_end*/) {}
  // Whether output samples need y' (IDA interpolates it at a cost; null is passed if not).
  virtual bool output_needs_derivative() const { return true; }
  // Called after every accepted step with the step's solution.
  virtual void after_step(double /*t*/, const double* /*y*/) {}
};

}  // namespace mbdae
