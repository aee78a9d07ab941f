#include "core/ida_driver.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <numeric>
#include <sstream>

#include "core/errors.h"
#include "core/finite_check.h"
#include "core/ida_run.h"
#include "core/reduced_linear_solver.h"
#include "core/sundials_compat.h"
#include "core/vector_kernels.h"

namespace mbdae {
namespace ida_detail {

// The calling thread's CPU clock: a run's cpu_seconds is its own cost even when other runs (or
// Python threads) use the process's other cores at the same time.
double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

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
  if (u->sens) sensitivity_weight_floor(u, y, w);
  return 0;
}

int residual_fn(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void* ud) {
  auto* u = static_cast<UserData*>(ud);
  // IDAS's F at a step's converged state, for a sensitivity residual that does not read it: not
  // evaluated (a residual per step; the state's Newton iterations write elsewhere).
  if (r == u->unread_residual) return 0;
  try {
    return u->problem->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(r));
  } catch (const SolveError& e) {
    return callback_solve_error(u, e);
  } catch (const std::exception& e) {
    return callback_failed(u, "residual", e);
  }
}

int jacobian_fn(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix jac, void* ud,
                N_Vector, N_Vector, N_Vector) {
  auto* u = static_cast<UserData*>(ud);
  try {
    return u->problem->jacobian(t, cj, N_VGetArrayPointer(y), N_VGetArrayPointer(yp),
                                SUNSparseMatrix_Data(jac));
  } catch (const SolveError& e) {
    return callback_solve_error(u, e);
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
  check(IDAGetNumSteps(mem, &v), "IDAGetNumSteps"); s.steps += v;
  check(IDAGetNumResEvals(mem, &v), "IDAGetNumResEvals"); s.residual_evals += v;
  check(IDAGetNumJacEvals(mem, &v), "IDAGetNumJacEvals"); s.jacobian_evals += v;
  check(IDAGetNumLinSolvSetups(mem, &v), "IDAGetNumLinSolvSetups"); s.linear_setups += v;
  check(IDAGetNumErrTestFails(mem, &v), "IDAGetNumErrTestFails"); s.error_test_failures += v;
  check(IDAGetNumNonlinSolvIters(mem, &v), "IDAGetNumNonlinSolvIters"); s.nonlinear_iterations += v;
  check(IDAGetNumNonlinSolvConvFails(mem, &v), "IDAGetNumNonlinSolvConvFails"); s.nonlinear_failures += v;
  if (IDAGetSensNumResEvals(mem, &v) == IDA_SUCCESS) {  // IDA_NO_SENS without sensitivities
    s.sensitivity_residual_evals += v;
    check(IDAGetSensNumNonlinSolvIters(mem, &v), "IDAGetSensNumNonlinSolvIters"); s.sensitivity_nonlinear_iterations += v;
    check(IDAGetSensNumErrTestFails(mem, &v), "IDAGetSensNumErrTestFails"); s.sensitivity_error_test_failures += v;
    check(IDAGetSensNumNonlinSolvConvFails(mem, &v), "IDAGetSensNumNonlinSolvConvFails"); s.sensitivity_nonlinear_failures += v;
  }
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

void choose_initial_step(IdaRun& r, double tt) {
  if (r.o->initial_step > 0) return;
  const double h = r.problem->initial_step(tt, data(r.y), data(r.yp), r.o->rtol, r.o->atol);
  r.ud.h_initial = h > 0 ? std::min(r.h_cap, h) : r.h_cap;
}

void configure_ida(IdaRun& r) {
  const IdaOptions& o = *r.o;
  check(IDAInit(r.mem, residual_fn, o.t0, r.y, r.yp), "IDAInit");
  check(IDAWFtolerances(r.mem, weights_fn), "IDAWFtolerances");
  check(IDASetUserData(r.mem, &r.ud), "IDASetUserData");
  check(keep_ida_errors(r.mem, r.ctx, &r.ud.last_ida_error), "IDASetErrHandlerFn");
  check(IDASetId(r.mem, r.id), "IDASetId");
  check(IDASetSuppressAlg(r.mem, SUNTRUE), "IDASetSuppressAlg");
  check(IDASetLinearSolver(r.mem, r.ls, r.jac), "IDASetLinearSolver");
  check(IDASetJacFn(r.mem, jacobian_fn), "IDASetJacFn");
  check(IDASetMaxNumSteps(r.mem, o.max_steps), "IDASetMaxNumSteps");
  check(IDASetMaxOrd(r.mem, o.max_order), "IDASetMaxOrd");
  check(IDASetNonlinConvCoef(r.mem, o.nonlinear_convergence), "IDASetNonlinConvCoef");
  // Refresh the Newton matrix whenever cj changes by more than delta_cj: with index-3 rows the
  // matrix does not scale with cj, and IDA's rescaled old-matrix corrections fail to converge.
  check(IDASetDeltaCjLSetup(r.mem, o.delta_cj), "IDASetDeltaCjLSetup");
  if (o.max_step > 0) check(IDASetMaxStep(r.mem, o.max_step), "IDASetMaxStep");
  // IDA's own first step, 0.5/|y'|, uses accelerations and is far too small for a multibody
  // system at index 3; start from the problem's estimate instead (the error test adapts it).
  check(IDASetInitStep(r.mem, r.ud.h_initial), "IDASetInitStep");
  r.nsw = r.problem->num_switches();
  if (r.nsw > 0) {
    check(IDARootInit(r.mem, r.nsw, root_fn), "IDARootInit");
    check(IDASetNoInactiveRootWarn(r.mem), "IDASetNoInactiveRootWarn");
  }
  r.roots.assign(std::max(1, r.nsw), 0);
}

// Breakpoints inside the span end segments. One at t1 makes the end a stop time (next_stop).
void find_breakpoints(IdaRun& r) {
  const IdaOptions& o = *r.o;
  for (double b : r.problem->breakpoints()) {
    if (b > o.t0 && b < o.t1) r.bps.push_back(b);
    if (std::fabs(b - o.t1) <= 1e-12 * std::max(1.0, std::fabs(o.t1))) r.end_is_breakpoint = true;
  }
  std::sort(r.bps.begin(), r.bps.end());
}

void open_run(IdaRun& r, const std::vector<double>& y0, const std::vector<double>& yp0) {
  const IdaOptions& o = *r.o;
  r.n = r.problem->size();
  r.ctx = make_sun_context();
  if (!r.ctx) throw SolveError("integration_failed", "cannot create a SUNDIALS context");
  for (N_Vector* v : {&r.y, &r.yp, &r.id, &r.ys, &r.yps}) {
    *v = check(N_VNew_Serial(r.n, r.ctx), "N_VNew_Serial");
    use_vector_kernels(*v);  // IDA's vectors are clones of y: they inherit it
  }
  std::memcpy(data(r.y), y0.data(), r.n * sizeof(double));
  std::memcpy(data(r.yp), yp0.data(), r.n * sizeof(double));
  r.problem->error_test_mask(data(r.id));
  const CscPattern& pattern = r.problem->jacobian_pattern();
  r.jac = check(SUNSparseMatrix(r.n, r.n, std::max(1, pattern.nnz()), CSC_MAT, r.ctx), "SUNSparseMatrix");
  // The pattern once. IDA zeroes the matrix (pattern included) before each Jacobian call:
  // jacobian_fn writes every value (SparseAssembler::begin_values zeroes them), so that pass over
  // the matrix is skipped and the pattern stays.
  std::copy(pattern.colptr.begin(), pattern.colptr.end(), SUNSparseMatrix_IndexPointers(r.jac));
  std::copy(pattern.rowind.begin(), pattern.rowind.end(), SUNSparseMatrix_IndexValues(r.jac));
  r.jac->ops->zero = [](SUNMatrix) -> int { return 0; };
  r.ls = make_newton_linear_solver(pattern, o.reduced_newton ? r.problem->kinematic_rows() : 0, r.ctx);
  r.mem = check(IDACreate(r.ctx), "IDACreate");
  r.ud.problem = r.problem;
  r.ud.mem = r.mem;
  r.ud.ls = r.ls;
  r.ud.rtol = o.rtol;
  r.ud.atol = o.atol;
  r.ud.h_initial = o.initial_step > 0 ? o.initial_step : 1e-6 * (o.t1 - o.t0);
  r.h_cap = r.ud.h_initial;
  choose_initial_step(r, o.t0);
  configure_ida(r);
  find_breakpoints(r);
  r.with_derivative = r.problem->output_needs_derivative();
  open_sensitivities(r);
  r.t = r.t_prev = o.t0;
  r.y_prev = y0;
  r.yp_prev = yp0;
  r.y_before = y0;
  r.yp_before = yp0;
}

// A failure other than IDA's own (those: ida_failure) ends the run; the first one is kept.
void fail(IdaRun& r, const std::string& status, const std::string& message, double tt) {
  if (!r.stats.ok) return;
  r.stats.ok = false;
  r.stats.status = status;
  r.stats.message = message;
  r.stats.t_reached = tt;
}

// False (and the run failed) if x, a state or its derivative at tt, has a NaN or an infinity.
bool finite(IdaRun& r, const double* x, double tt, const char* what) {
  const int i = first_non_finite(x, r.n);
  if (i < 0) return true;
  const SolveError e =
      non_finite_error(what + r.problem->component_name(i) + " (y[" + std::to_string(i) + "])", x[i], tt);
  fail(r, e.status, e.what(), tt);
  return false;
}

// IDA's interpolant of y (k = 0) or y' (k = 1) at tt into v.
bool interpolate(IdaRun& r, double tt, int k, N_Vector v) {
  const int flag = IDAGetDky(r.mem, tt, k, v);
  if (flag == IDA_SUCCESS) return true;
  fail(r, "integration_failed",
       "interpolating the solution at t = " + std::to_string(tt) + " failed (" + ida_flag_name(flag) + ")", tt);
  return false;
}

// IDA stopped with an error: the message names the worst error estimates and IDA's own words.
void ida_failure(IdaRun& r, int flag) {
  double tt = r.t;
  check(IDAGetCurrentTime(r.mem, &tt), "IDAGetCurrentTime");
  if (r.ud.non_finite >= 0) {
    const int i = r.ud.non_finite;
    const SolveError e =
        non_finite_error(r.problem->component_name(i) + " (y[" + std::to_string(i) + "])", r.ud.non_finite_value, tt);
    return fail(r, e.status, e.what(), tt);
  }
  if (!r.ud.callback_status.empty()) return fail(r, r.ud.callback_status, r.ud.callback_error, tt);
  if (!r.ud.callback_error.empty())
    return fail(r, "internal_error", "the DAE's " + r.ud.callback_error + " (at t = " + std::to_string(tt) + ")", tt);
  std::ostringstream os;
  double h = 0;
  check(IDAGetCurrentStep(r.mem, &h), "IDAGetCurrentStep");
  os << "IDA failed at t = " << tt << " with step size " << h << " (" << ida_flag_name(flag) << ")";
  const std::string worst = worst_components(r.mem, *r.problem, r.ys, r.yps, r.id);
  if (!worst.empty()) os << "; largest error estimates: " << worst;
  if (!r.ud.last_ida_error.empty()) os << "; IDA: " << r.ud.last_ida_error;
  fail(r, "integration_failed", os.str(), r.t);  // reached: the last accepted step
}

double sample_time(const IdaRun& r, long k) {
  const IdaOptions& o = *r.o;
  return o.output_step > 0 ? std::min(o.t1, o.t0 + k * o.output_step) : (k == 0 ? o.t0 : o.t1);
}

// One sample to the caller, after checking it: a SolveError thrown there (a sensor that is not
// finite) ends the run like a failure of the solver.
void emit(IdaRun& r, double ts, const double* yy, const double* yyp, double* const* s, double* const* sp) {
  if (!finite(r, yy, ts, "") || (yyp && !finite(r, yyp, ts, "derivative of "))) return;
  try {
    const bool go_on = (*r.output)(ts, yy, yyp);
    if (r.sens_on && r.o->sensitivity_output) r.o->sensitivity_output(ts, yy, yyp, s, sp);
    if (!go_on) r.stop_requested = true;
  } catch (const SolveError& e) {
    fail(r, e.status, e.what(), ts);
  }
}

// Every sample up to t_reached, always from IDA's interpolant (also at a step's own time: the y'
// IDA returns at a stop time is not the derivative of its position interpolant).
void emit_until(IdaRun& r, double t_reached) {
  while (!r.stop_requested && r.stats.ok && r.sample_index >= 0) {
    const double ts = sample_time(r, r.sample_index);
    if (ts > t_reached) break;
    if (!interpolate(r, ts, 0, r.ys) || (r.with_derivative && !interpolate(r, ts, 1, r.yps)) ||
        !interpolate_sensitivities(r, ts, r.ss, r.sps))
      break;
    emit(r, ts, data(r.ys), r.with_derivative ? data(r.yps) : nullptr, r.ss_data.data(), r.sps_data.data());
    if (ts >= r.o->t1) {
      r.sample_index = -1;
      break;
    }
    ++r.sample_index;
  }
}

// The end of the run is a stop time only where the inputs are not smooth there (a drive's last
// knot): elsewhere the last step may go past t1 and the end is interpolated like every sample.
// A last step shortened to land on t1 can fail at index 3, where the Newton matrix's condition
// grows as 1/h^2 (verification/iftomm: EngineFindings.LastStepToTheEndTime).
double next_stop(const IdaRun& r) {
  const IdaOptions& o = *r.o;
  if (r.next_bp < r.bps.size()) return r.bps[r.next_bp];
  return r.end_is_breakpoint ? o.t1 : o.t1 + (o.t1 - o.t0);
}

// Only a real breakpoint ends a segment: the end of the run is no jump of the inputs unless a
// breakpoint falls on it, where the last sample shows the inputs' left limit as every sample at
// a breakpoint does (the run never goes past the jump).
double segment_end(const IdaRun& r) {
  if (r.next_bp < r.bps.size()) return r.bps[r.next_bp];
  return r.end_is_breakpoint ? r.o->t1 : 1e300;
}

// The last accepted step (interpolated root states are never kept).
void keep_step(IdaRun& r) {
  r.t_prev = r.t;
  std::memcpy(r.y_prev.data(), data(r.y), r.n * sizeof(double));
  std::memcpy(r.yp_prev.data(), data(r.yp), r.n * sizeof(double));
}

// IDA's counters restart at every IDAReInit: add them up first (and once more at the end).
void reinit(IdaRun& r, double tt) {
  collect(r.mem, r.stats);
  check(IDAReInit(r.mem, tt, r.y, r.yp), "IDAReInit");
  if (r.sens_on) {
    check(IDASensReInit(r.mem, IDA_STAGGERED, r.s, r.sp), "IDASensReInit");
    sensitivity_test_window(r, true);
  }
}

// A step past t1: the end state and the last samples are interpolated; a root beyond t1 is no
// event of this run.
void finish_past_end(IdaRun& r, int flag, double tret) {
  if (flag != IDA_ROOT_RETURN) r.problem->after_step(tret, data(r.y));
  emit_until(r, r.o->t1);
  if (r.stats.ok && interpolate(r, r.o->t1, 0, r.y) && interpolate(r, r.o->t1, 1, r.yp)) r.t = r.o->t1;
}

// The smallest step IDA may take from t: kMinStepUlps units in the last place of t. A step
// below it no longer resolves t (at 3e-19 s near t = 0.72 s, t + h == t), so a run whose steps
// collapse there fails at once with IDA's own message instead of crawling to the step budget
// (A02 with N = 40 at its singular configuration: 110000 steps and 2.5 min before; docs/errors.md).
constexpr double kMinStepUlps = 16;

void limit_step_from(IdaRun& r, double tt) {
  check(IDASetMinStep(r.mem, kMinStepUlps * std::numeric_limits<double>::epsilon() * std::fabs(tt)),
        "IDASetMinStep");
}

// IDA anew at r.t from (y, y') (after a restart or a retry): the first step chosen again, then on
// to the next stop.
void start_again(IdaRun& r) {
  choose_initial_step(r, r.t);
  check(IDASetInitStep(r.mem, r.ud.h_initial), "IDASetInitStep");
  reinit(r, r.t);
  check(IDASetStopTime(r.mem, next_stop(r)), "IDASetStopTime");
}

// Back to the last accepted step's state (keep_step), the failure of IDA's callbacks forgotten.
void back_to_last_step(IdaRun& r) {
  r.ud.callback_error.clear();
  r.ud.callback_status.clear();
  r.ud.non_finite = -1;
  std::memcpy(data(r.y), r.y_prev.data(), r.n * sizeof(double));
  std::memcpy(data(r.yp), r.yp_prev.data(), r.n * sizeof(double));
  r.t = r.t_prev;
}

// After an event (roots: which functions crossed) or a breakpoint (roots null): the problem's
// restart (new modes, a consistent state), then IDA anew from there. False: the run ends.
bool restart(IdaRun& r, const int* roots) {
  while (r.next_bp < r.bps.size() && r.bps[r.next_bp] <= r.t) ++r.next_bp;
  r.problem->set_segment(r.t, segment_end(r));
  try {
    if (r.sens_on) {  // the state before the restart: the sensitivities' restart maps it (with s) as the run's did
      std::memcpy(r.y_before.data(), data(r.y), r.n * sizeof(double));
      std::memcpy(r.yp_before.data(), data(r.yp), r.n * sizeof(double));
    }
    r.problem->restart(r.t, data(r.y), data(r.yp), roots);
    if (r.sens_on) {  // the sensitivities at t (IDAS's), made consistent with the restarted state
      r.o->sensitivities->set_segment(r.t, segment_end(r));
      if (!interpolate_sensitivities(r, r.t, r.s, r.sp)) return false;
      if (!roots) r.o->sensitivities->jump_at_breakpoint(r.t, r.yp_before.data(), data(r.yp), r.s_data.data());
      r.o->sensitivities->restart(r.t, r.y_before.data(), r.yp_before.data(), r.s_data.data(), r.sp_data.data());
    }
  } catch (const SolveError& e) {
    fail(r, e.status, std::string("restart at t = ") + std::to_string(r.t) + " failed: " + e.what(), r.t);
    return false;
  }
  if (!finite(r, data(r.y), r.t, "") || !finite(r, data(r.yp), r.t, "derivative of ")) return false;
  ++r.stats.restarts;
  start_again(r);
  keep_step(r);
  return true;
}

// After a step whose Newton matrix was factored afresh, the caller's check of that state
// (IdaOptions::after_fresh_factorization). False: the run failed there.
bool newton_matrix_fine(IdaRun& r, double tret) {
  if (!r.o->after_fresh_factorization) return true;
  const long fresh = newton_linear_solver_fresh_factorizations(r.ls);
  if (fresh == r.fresh_seen) return true;
  r.fresh_seen = fresh;
  if (r.o->after_fresh_factorization(tret, data(r.y))) return true;
  std::ostringstream os;
  os << "the Newton matrix's pivots degraded (factored afresh) at t = " << tret;
  fail(r, "integration_failed", os.str(), tret);
  return false;
}

// One IDA step and what follows it (samples, an event, a breakpoint). False: the run ends.
bool advance(IdaRun& r) {
  const IdaOptions& o = *r.o;
  double tret = r.t;
  limit_step_from(r, r.t);
  const int flag = IDASolve(r.mem, o.t1, &tret, r.y, r.yp, IDA_ONE_STEP);
  if (flag < 0) {
    if (r.sens_on && drop_sensitivities(r, flag)) return true;
    ida_failure(r, flag);
    return false;
  }
  if (!finite(r, data(r.y), tret, "")) return false;
  if (!newton_matrix_fine(r, tret)) return false;
  sensitivity_test_window(r, false);
  if (tret > o.t1) {
    finish_past_end(r, flag, tret);
    return false;
  }
  // A root found exactly at a breakpoint is the breakpoint's own jump: restart from signs.
  const bool at_breakpoint = r.next_bp < r.bps.size() &&
                             std::fabs(tret - r.bps[r.next_bp]) <= 1e-12 * std::max(1.0, std::fabs(tret));
  const bool is_root = flag == IDA_ROOT_RETURN && !at_breakpoint;
  if (is_root) {
    check(IDAGetRootInfo(r.mem, r.roots.data()), "IDAGetRootInfo");
    // A root that changes no mode (a switching function grazing zero) needs no restart.
    if (!r.problem->changes_mode(tret, data(r.y), r.roots.data())) return true;
  }
  // At a root the state is IDA's interpolant there, which restart() makes consistent.
  r.t = tret;
  r.problem->after_step(r.t, data(r.y));
  emit_until(r, r.t);
  if (!r.stats.ok) return false;
  if (is_root) {
    r.stats.event_times.push_back(r.t);
  } else {
    keep_step(r);
    if (flag != IDA_ROOT_RETURN && flag != IDA_TSTOP_RETURN) return true;
    if (r.t >= o.t1) return false;
    r.stats.breakpoint_times.push_back(r.t);
    ++r.next_bp;
  }
  return restart(r, is_root ? r.roots.data() : nullptr);
}

// The step budget (IdaOptions::max_total_steps), checked every kWatchWindow steps: the run
// fails once it has spent the budget, or when kWatchStrikes windows in a row advanced t so
// little that finishing at their rate would need more than the budget.
constexpr long kWatchWindow = 10000;
constexpr int kWatchStrikes = 10;

bool over_budget(IdaRun& r) {
  const IdaOptions& o = *r.o;
  if (o.max_total_steps <= 0 || ++r.watch_steps < kWatchWindow) return false;
  long steps = 0;
  IDAGetNumSteps(r.mem, &steps);
  steps += r.stats.steps;  // IDA's counter restarts at each reinit; stats holds the earlier ones
  const double advanced = r.t - r.watch_t;
  const double projected = steps + (advanced > 0 ? kWatchWindow * (o.t1 - r.t) / advanced : 1e300);
  r.watch_strikes = projected > o.max_total_steps ? r.watch_strikes + 1 : 0;
  r.watch_steps = 0;
  r.watch_t = r.t;
  if (steps < o.max_total_steps && r.watch_strikes < kWatchStrikes) return false;
  double h = 0;
  IDAGetCurrentStep(r.mem, &h);
  std::ostringstream os;
  os.precision(4);
  os << "step limit: " << static_cast<double>(steps) << " steps by t = " << r.t << " (step size " << h << " s)";
  if (steps < o.max_total_steps)
    os << ", and at the rate of the last " << kWatchStrikes * kWatchWindow << " steps the run to t = " << o.t1
       << " would need about " << projected << " steps";
  // The sensitivities' error test may be what holds the steps back (their differences' noise):
  // the run goes on without them (or with their assembled Newton matrix), within its budget.
  if (r.sens_on && steps < o.max_total_steps) {
    r.watch_strikes = 0;
    return !drop_sensitivities(r, os.str() + " with the sensitivities");
  }
  os << ", more than max_steps = " << static_cast<double>(o.max_total_steps)
     << " (a load or a motion growing without bound? raise max_steps in the step to go on; docs/errors.md)";
  fail(r, "step_limit", os.str(), r.t);
  return true;
}

}  // namespace ida_detail

using namespace ida_detail;

IdaStats integrate(DaeProblem& problem, const IdaOptions& o, std::vector<double>& y0, std::vector<double>& yp0,
                   const std::function<bool(double, const double*, const double*)>& output) {
  const double cpu0 = cpu_now();
  IdaRun r;
  r.problem = &problem;
  r.o = &o;
  r.output = &output;
  try {
    open_run(r, y0, yp0);
  } catch (const SolveError& e) {  // initial sensitivities that cannot be made: a failed run
    if (!r.mem || e.status == "internal_error") throw;  // a refused setting names its SUNDIALS call
    fail(r, e.status, e.what(), o.t0);
    r.stats.cpu_seconds = cpu_now() - cpu0;
    return r.stats;
  }
  // The first sample is the initial state.
  emit(r, o.t0, y0.data(), yp0.data(), r.s_data.data(), r.sp_data.data());
  r.sample_index = 1;
  check(IDASetStopTime(r.mem, next_stop(r)), "IDASetStopTime");
  problem.set_segment(r.t, segment_end(r));
  if (r.ns > 0) o.sensitivities->set_segment(r.t, segment_end(r));
  r.watch_t = o.t0;
  while (!r.stop_requested && r.stats.ok && r.t < o.t1) {
    if (o.stop && o.stop->load(std::memory_order_relaxed)) break;
    try {
      if (!advance(r) || over_budget(r)) break;
    } catch (const SolveError& e) {  // a SUNDIALS call that failed (check)
      fail(r, e.status, e.what(), r.t);
      break;
    }
  }
  collect(r.mem, r.stats);
  if (r.stats.ok) r.stats.t_reached = r.t;
  r.stats.fresh_factorizations = newton_linear_solver_fresh_factorizations(r.ls);
  std::memcpy(y0.data(), data(r.y), r.n * sizeof(double));
  std::memcpy(yp0.data(), data(r.yp), r.n * sizeof(double));
  r.stats.cpu_seconds = cpu_now() - cpu0;
  return r.stats;
}

}  // namespace mbdae
