#include "core/ida_driver.h"

#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <cstdlib>
#include <ctime>
#include <numeric>
#include <sstream>

#include "core/errors.h"
#include "core/finite_check.h"
#include "core/klu_linear_solver.h"
#include "core/sundials_compat.h"

namespace mbdae {
namespace {

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct UserData {
  DaeProblem* problem;
  const CscPattern* pattern;
  void* mem;
  double rtol, atol, h_initial;
  std::string last_ida_error;  // IDA's own words about its last error (not printed)
  std::string callback_error;  // an exception of the problem's residual or Jacobian
  int non_finite = -1;         // a component of y found not finite by weights_fn
  double non_finite_value = 0;
};

int weights_fn(N_Vector y, N_Vector w, void* ud) {
  auto* u = static_cast<UserData*>(ud);
  // IDA evaluates the weights after every accepted step. A state with a NaN or an infinity gets
  // a zero or NaN weight, which IDA does not notice (with inf in y it was seen to loop forever
  // inside IDASolve): stop it here; the driver reports the component.
  const int bad = first_non_finite(N_VGetArrayPointer(y), u->problem->size());
  if (bad >= 0) {
    u->non_finite = bad;
    u->non_finite_value = N_VGetArrayPointer(y)[bad];
    return -1;
  }
  // Before the first step after an (re)initialization the step to be tried is the initial one.
  double h = 0;
  long steps = 0;
  IDAGetNumSteps(u->mem, &steps);
  if (steps > 0) IDAGetCurrentStep(u->mem, &h);
  if (!(h > 0)) h = u->h_initial;
  // The weights are kept until the next successful step, also through the step reductions
  // after failures: evaluate them for a step a thousand times smaller than the one about to be
  // tried (with 0.1, a kinematic sweep at rtol 1e-8 collapsed to h = 1e-12 after one failure:
  // the stale, too strict velocity and multiplier tolerances made every retry fail).
  u->problem->error_weights(1e-3 * h, N_VGetArrayPointer(y), u->rtol, u->atol, N_VGetArrayPointer(w));
  return 0;
}

// No C++ exception may cross IDA's C frames: one from the problem's residual or Jacobian (a bug,
// such as an assembly that does not repeat its pattern) is kept and IDA stopped (return -1).
int callback_failed(UserData* u, const char* where, const std::exception& e) {
  u->callback_error = std::string(where) + ": " + e.what();
  return -1;
}

int residual_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void* ud) {
  auto* u = static_cast<UserData*>(ud);
  try {
    return u->problem->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(r));
  } catch (const std::exception& e) {
    return callback_failed(u, "residual", e);
  }
}

int jacobian_fn(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix jac, void* ud,
                N_Vector, N_Vector, N_Vector) {
  auto* u = static_cast<UserData*>(ud);
  const CscPattern& p = *u->pattern;
  // IDA zeroes the whole matrix (pattern included) before each call: copy the pattern back.
  sunindextype* colptr = SUNSparseMatrix_IndexPointers(jac);
  sunindextype* rowind = SUNSparseMatrix_IndexValues(jac);
  for (int c = 0; c <= p.cols; ++c) colptr[c] = p.colptr[c];
  for (int k = 0; k < p.nnz(); ++k) rowind[k] = p.rowind[k];
  try {
    return u->problem->jacobian(t, cj, N_VGetArrayPointer(y), N_VGetArrayPointer(yp),
                                SUNSparseMatrix_Data(jac));
  } catch (const std::exception& e) {
    return callback_failed(u, "Jacobian", e);
  }
}

int root_fn(sunrealtype t, N_Vector y, N_Vector, sunrealtype* g, void* ud) {
  static_cast<UserData*>(ud)->problem->switches(t, N_VGetArrayPointer(y), g);
  return 0;
}

// IDA's counters restart at every IDAReInit: add them up before each one.
void collect(void* mem, IdaStats& s) {
  long v;
  IDAGetNumSteps(mem, &v); s.steps += v;
  IDAGetNumResEvals(mem, &v); s.residual_evals += v;
  IDAGetNumJacEvals(mem, &v); s.jacobian_evals += v;
  IDAGetNumLinSolvSetups(mem, &v); s.linear_setups += v;
  IDAGetNumErrTestFails(mem, &v); s.error_test_failures += v;
  IDAGetNumNonlinSolvIters(mem, &v); s.nonlinear_iterations += v;
  IDAGetNumNonlinSolvConvFails(mem, &v); s.nonlinear_failures += v;
  double h = 0;
  if (IDAGetLastStep(mem, &h) == IDA_SUCCESS && h != 0) s.last_step = h;
}

// Names of the components with the largest weighted local error estimates.
std::string worst_components(void* mem, DaeProblem& p, N_Vector tmp1, N_Vector tmp2, N_Vector id) {
  if (IDAGetErrWeights(mem, tmp1) != IDA_SUCCESS || IDAGetEstLocalErrors(mem, tmp2) != IDA_SUCCESS)
    return "";
  const double* w = N_VGetArrayPointer(tmp1);
  const double* e = N_VGetArrayPointer(tmp2);
  std::vector<int> idx(p.size());
  std::iota(idx.begin(), idx.end(), 0);
  const double* mask = N_VGetArrayPointer(id);
  auto score = [&](int i) { return mask[i] > 0 ? std::fabs(w[i] * e[i]) : 0.0; };
  const int k = std::min<int>(3, idx.size());
  std::partial_sort(idx.begin(), idx.begin() + k, idx.end(),
                    [&](int a, int b) { return score(a) > score(b); });
  std::ostringstream os;
  for (int i = 0; i < k; ++i) {
    if (score(idx[i]) == 0) break;
    os << (i ? ", " : "") << p.component_name(idx[i]) << " (weighted error " << score(idx[i]) << ")";
  }
  return os.str();
}

}  // namespace

IdaStats integrate(DaeProblem& problem, const IdaOptions& o, std::vector<double>& y0,
                   std::vector<double>& yp0,
                   const std::function<bool(double, const double*, const double*)>& output) {
  IdaStats stats;
  const double cpu0 = cpu_now();
  const int n = problem.size();
  const CscPattern& pattern = problem.jacobian_pattern();

  SUNContext ctx = make_sun_context();
  if (!ctx) throw SolveError("integration_failed", "cannot create a SUNDIALS context");
  N_Vector y = N_VNew_Serial(n, ctx), yp = N_VNew_Serial(n, ctx);
  N_Vector id = N_VNew_Serial(n, ctx);
  N_Vector ys = N_VNew_Serial(n, ctx), yps = N_VNew_Serial(n, ctx);
  std::memcpy(N_VGetArrayPointer(y), y0.data(), n * sizeof(double));
  std::memcpy(N_VGetArrayPointer(yp), yp0.data(), n * sizeof(double));
  problem.error_test_mask(N_VGetArrayPointer(id));

  SUNMatrix jac = SUNSparseMatrix(n, n, std::max(1, pattern.nnz()), CSC_MAT, ctx);
  SUNLinearSolver ls = make_klu_linear_solver(pattern, ctx);
  void* mem = IDACreate(ctx);
  UserData ud{&problem, &pattern, mem, o.rtol, o.atol,
              o.initial_step > 0 ? o.initial_step : 1e-6 * (o.t1 - o.t0), "", "", -1, 0.0};
  const double h_cap = ud.h_initial;
  auto choose_initial_step = [&](double tt) {
    if (o.initial_step > 0) return;
    const double h = problem.initial_step(tt, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), o.rtol, o.atol);
    ud.h_initial = h > 0 ? std::min(h_cap, h) : h_cap;
  };
  choose_initial_step(o.t0);
  IDAInit(mem, residual_fn, o.t0, y, yp);
  IDAWFtolerances(mem, weights_fn);
  IDASetUserData(mem, &ud);
  keep_ida_errors(mem, ctx, &ud.last_ida_error);
  IDASetId(mem, id);
  IDASetSuppressAlg(mem, SUNTRUE);
  IDASetLinearSolver(mem, ls, jac);
  IDASetJacFn(mem, jacobian_fn);
  IDASetMaxNumSteps(mem, o.max_steps);
  IDASetMaxOrd(mem, o.max_order);
  IDASetNonlinConvCoef(mem, o.nonlinear_convergence);
  // Refresh the Newton matrix whenever cj changes by more than delta_cj: with index-3 rows the
  // matrix does not scale with cj, and IDA's rescaled old-matrix corrections fail to converge.
  IDASetDeltaCjLSetup(mem, o.delta_cj);
  if (o.max_step > 0) IDASetMaxStep(mem, o.max_step);
  // IDA's own first step, 0.5/|y'|, uses accelerations and is far too small for a multibody
  // system at index 3; start from a fixed fraction of the span instead (the error test adapts it).
  IDASetInitStep(mem, ud.h_initial);
  const int nsw = problem.num_switches();
  if (nsw > 0) {
    IDARootInit(mem, nsw, root_fn);
    IDASetNoInactiveRootWarn(mem);
  }
  std::vector<int> roots(std::max(1, nsw));

  // Breakpoints inside the span end segments. One at t1 makes the end a stop time (see
  // next_stop below).
  std::vector<double> bps;
  bool end_is_breakpoint = false;
  for (double b : problem.breakpoints()) {
    if (b > o.t0 && b < o.t1) bps.push_back(b);
    if (std::fabs(b - o.t1) <= 1e-12 * std::max(1.0, std::fabs(o.t1))) end_is_breakpoint = true;
  }
  std::sort(bps.begin(), bps.end());

  // A failure other than IDA's own (those: `failure` below) ends the run; the first one is kept.
  auto fail = [&](const std::string& status, const std::string& message, double tt) {
    if (!stats.ok) return;
    stats.ok = false;
    stats.status = status;
    stats.message = message;
    stats.t_reached = tt;
  };
  // False (and the run failed) if x, a state or its derivative at tt, has a NaN or an infinity.
  auto finite = [&](const double* x, double tt, const char* what) {
    const int i = first_non_finite(x, n);
    if (i < 0) return true;
    const SolveError e = non_finite_error(what + problem.component_name(i) + " (y[" + std::to_string(i) + "])", x[i], tt);
    fail(e.status, e.what(), tt);
    return false;
  };
  // IDA's interpolant of y (k = 0) or y' (k = 1) at tt into v.
  auto interpolate = [&](double tt, int k, N_Vector v) {
    const int flag = IDAGetDky(mem, tt, k, v);
    if (flag == IDA_SUCCESS) return true;
    fail("integration_failed", "interpolating the solution at t = " + std::to_string(tt) + " failed (" + ida_flag_name(flag) + ")", tt);
    return false;
  };

  // Output samples.
  long sample_index = 0;
  auto sample_time = [&](long k) {
    return o.output_step > 0 ? std::min(o.t1, o.t0 + k * o.output_step) : (k == 0 ? o.t0 : o.t1);
  };
  bool stop_requested = false;
  const bool with_derivative = problem.output_needs_derivative();
  // One sample to the caller, after checking it: a SolveError thrown there (a sensor that is
  // not finite) ends the run like a failure of the solver.
  auto emit = [&](double ts, const double* yy, const double* yyp) {
    if (!finite(yy, ts, "") || (yyp && !finite(yyp, ts, "derivative of "))) return;
    try {
      if (!output(ts, yy, yyp)) stop_requested = true;
    } catch (const SolveError& e) {
      fail(e.status, e.what(), ts);
    }
  };
  auto emit_until = [&](double t_reached, bool inclusive) {
    while (!stop_requested && stats.ok && sample_index >= 0) {
      const double ts = sample_time(sample_index);
      if (ts > t_reached || (!inclusive && ts == t_reached)) break;
      // Always from IDA's interpolant (also at a step's own time: the y' IDA returns at a stop
      // time is not the derivative of its position interpolant).
      if (!interpolate(ts, 0, ys) || (with_derivative && !interpolate(ts, 1, yps))) break;
      emit(ts, N_VGetArrayPointer(ys), with_derivative ? N_VGetArrayPointer(yps) : nullptr);
      if (ts >= o.t1) { sample_index = -1; break; }
      ++sample_index;
    }
  };
  // The first sample is the initial state.
  emit(o.t0, y0.data(), yp0.data());
  sample_index = 1;

  double t = o.t0;
  size_t next_bp = 0;
  // The end of the run is a stop time only where the inputs are not smooth there (a drive's
  // last knot): elsewhere the last step may go past t1 and the end is interpolated like every
  // sample. A last step shortened to land on t1 can fail at index 3, where the Newton matrix's
  // condition grows as 1/h^2 (verification/iftomm: EngineFindings.LastStepToTheEndTime).
  const double t_beyond = o.t1 + (o.t1 - o.t0);
  auto next_stop = [&] {
    return next_bp < bps.size() ? bps[next_bp] : end_is_breakpoint ? o.t1 : t_beyond;
  };
  // Only a real breakpoint ends a segment: the end of the run is no jump of the inputs.
  auto segment_end = [&] { return next_bp < bps.size() ? bps[next_bp] : 1e300; };
  IDASetStopTime(mem, next_stop());
  problem.set_segment(t, segment_end());
  // The last accepted step (interpolated root states are never kept here).
  double t_prev = t;
  std::vector<double> y_prev(y0), yp_prev(yp0);
  auto keep_step = [&](double tt) {
    t_prev = tt;
    std::memcpy(y_prev.data(), N_VGetArrayPointer(y), n * sizeof(double));
    std::memcpy(yp_prev.data(), N_VGetArrayPointer(yp), n * sizeof(double));
  };
  // IDA's counters restart at every IDAReInit: add them up first (and once more at the end).
  auto reinit = [&](double tt) {
    collect(mem, stats);
    IDAReInit(mem, tt, y, yp);
  };
  auto failure = [&](int flag, double tt) {
    IDAGetCurrentTime(mem, &tt);
    if (ud.non_finite >= 0) {
      const int i = ud.non_finite;
      const SolveError e = non_finite_error(problem.component_name(i) + " (y[" + std::to_string(i) + "])",
                                            ud.non_finite_value, tt);
      return fail(e.status, e.what(), tt);
    }
    if (!ud.callback_error.empty())
      return fail("internal_error", "the DAE's " + ud.callback_error + " (at t = " + std::to_string(tt) + ")", tt);
    std::ostringstream os;
    double h = 0;
    IDAGetCurrentStep(mem, &h);
    os << "IDA failed at t = " << tt << " with step size " << h << " (" << ida_flag_name(flag) << ")";
    const std::string worst = worst_components(mem, problem, ys, yps, id);
    if (!worst.empty()) os << "; largest error estimates: " << worst;
    if (!ud.last_ida_error.empty()) os << "; IDA: " << ud.last_ida_error;
    stats.ok = false;
    stats.status = "integration_failed";
    stats.message = os.str();
    stats.t_reached = t;
  };
  while (!stop_requested && stats.ok && t < o.t1) {
    if (o.stop && o.stop->load(std::memory_order_relaxed)) break;
    double tret = t;
    int flag = IDASolve(mem, o.t1, &tret, y, yp, IDA_ONE_STEP);
    if (flag < 0) {
      failure(flag, tret);
      break;
    }
    if (!finite(N_VGetArrayPointer(y), tret, "")) break;
    if (tret > o.t1) {
      // Past the end: the end state and the last samples are interpolated; a root beyond t1 is
      // no event of this run.
      if (flag != IDA_ROOT_RETURN) problem.after_step(tret, N_VGetArrayPointer(y));
      emit_until(o.t1, true);
      if (stats.ok && interpolate(o.t1, 0, y) && interpolate(o.t1, 1, yp)) t = o.t1;
      break;
    }
    // A root found exactly at a breakpoint is the breakpoint's own jump: restart from signs.
    const bool at_breakpoint = next_bp < bps.size() &&
                               std::fabs(tret - bps[next_bp]) <= 1e-12 * std::max(1.0, std::fabs(tret));
    bool is_root = flag == IDA_ROOT_RETURN && !at_breakpoint;
    if (is_root) {
      IDAGetRootInfo(mem, roots.data());
      // A root that changes no mode (a switching function grazing zero) needs no restart.
      if (!problem.changes_mode(tret, N_VGetArrayPointer(y), roots.data())) continue;
      // The state IDA returns at a root is interpolated, and the interpolated velocities are
      // not error-controlled at index 3. Step back to the last accepted step and integrate again
      // with the root time as stop time, so that the state at the root is a converged step.
      const double t_root = tret;
      const double h_default = ud.h_initial;
      choose_initial_step(t_prev);
      ud.h_initial = std::min(ud.h_initial, t_root - t_prev);
      if (ud.h_initial > 1e-12 * std::max(1.0, std::fabs(t_root))) {
        std::memcpy(N_VGetArrayPointer(y), y_prev.data(), n * sizeof(double));
        std::memcpy(N_VGetArrayPointer(yp), yp_prev.data(), n * sizeof(double));
        IDASetInitStep(mem, ud.h_initial);
        reinit(t_prev);
        IDARootInit(mem, 0, nullptr);
        IDASetStopTime(mem, t_root);
        t = t_prev;
      } else {
        t = t_root;  // the root is at the last step: its state is that step's
      }
      while (t < t_root && !stop_requested && stats.ok) {
        flag = IDASolve(mem, t_root, &tret, y, yp, IDA_ONE_STEP);
        if (flag < 0 || !finite(N_VGetArrayPointer(y), tret, "")) break;
        t = tret;
        problem.after_step(t, N_VGetArrayPointer(y));
        emit_until(t, true);
      }
      IDARootInit(mem, nsw, root_fn);
      ud.h_initial = h_default;
      IDASetInitStep(mem, ud.h_initial);
      if (flag < 0) {
        failure(flag, tret);
        break;
      }
      if (!stats.ok) break;
      stats.event_times.push_back(t);
    } else {
      t = tret;
      problem.after_step(t, N_VGetArrayPointer(y));
      emit_until(t, true);
      if (!stats.ok) break;
      keep_step(t);
      if (flag != IDA_ROOT_RETURN && flag != IDA_TSTOP_RETURN) continue;
      if (t >= o.t1) break;
      stats.breakpoint_times.push_back(t);
      ++next_bp;
    }
    while (next_bp < bps.size() && bps[next_bp] <= t) ++next_bp;
    problem.set_segment(t, segment_end());
    try {
      problem.restart(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), is_root ? roots.data() : nullptr);
    } catch (const SolveError& e) {
      fail(e.status, std::string("restart at t = ") + std::to_string(t) + " failed: " + e.what(), t);
      break;
    }
    if (!finite(N_VGetArrayPointer(y), t, "") || !finite(N_VGetArrayPointer(yp), t, "derivative of ")) break;
    ++stats.restarts;
    choose_initial_step(t);
    IDASetInitStep(mem, ud.h_initial);
    reinit(t);
    IDASetStopTime(mem, next_stop());
    keep_step(t);
  }
  collect(mem, stats);
  if (stats.ok) stats.t_reached = t;
  stats.fresh_factorizations = klu_linear_solver_fresh_factorizations(ls);
  std::memcpy(y0.data(), N_VGetArrayPointer(y), n * sizeof(double));
  std::memcpy(yp0.data(), N_VGetArrayPointer(yp), n * sizeof(double));
  IDAFree(&mem);
  SUNLinSolFree(ls);
  SUNMatDestroy(jac);
  for (N_Vector v : {y, yp, id, ys, yps}) N_VDestroy(v);
  SUNContext_Free(&ctx);
  stats.cpu_seconds = cpu_now() - cpu0;
  return stats;
}

}  // namespace mbdae
