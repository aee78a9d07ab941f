// IDAS's forward sensitivities in the IDA driver (IdaOptions::sensitivities, core/ida_run.h):
// their setup, residual callback, error-weight floor, interpolation, and what happens when IDA
// fails with them.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "core/finite_check.h"
#include "core/ida_run.h"
#include "core/klu_linear_solver.h"

namespace mbdae::ida_detail {
namespace {

// The sensitivity equations' residual (IdaOptions::sensitivities), for every parameter at once.
int sensitivity_residual_fn(int ns, sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, N_Vector* s, N_Vector* sp,
                            N_Vector* rs, void* ud, N_Vector, N_Vector, N_Vector) {
  auto* u = static_cast<UserData*>(ud);
  if (!u->sens->reads_state_residual()) u->unread_residual = r;
  for (int i = 0; i < ns; ++i) {
    u->s_in[i] = N_VGetArrayPointer(s[i]);
    u->sp_in[i] = N_VGetArrayPointer(sp[i]);
    u->r_out[i] = N_VGetArrayPointer(rs[i]);
  }
  try {
    const int flag = u->sens->residual(t, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), N_VGetArrayPointer(r),
                                       u->s_in.data(), u->sp_in.data(), u->r_out.data());
    // IDAS solves these right-hand sides next, one after the other: together, in one pass.
    klu_linear_solver_expect_batch(u->ls, u->r_out.data(), flag == 0 ? ns : 0);
    return flag;
  } catch (const SolveError& e) {
    return callback_solve_error(u, e);
  } catch (const std::exception& e) {
    return callback_failed(u, "sensitivity residual", e);
  }
}

}  // namespace

// With sensitivities, IDAS calls weights_fn for the state (first, and always with the same
// weight vector) and for each sensitivity at pbar_i s_i. The sensitivities' tolerances never go
// below kSensitivityNoise times the state's size (or the component's own, where larger: the
// multipliers, in newtons): their residual's parameter derivative is a
// difference over twin models (formulation/twin_sensitivities.h) whose rounding is about 1e5 eps
// of the state, above the rounding-level floors of the state's own weights (measured: index2-ggl
// on A01 at rtol 1e-8 stopped at its first step without this floor).
constexpr double kSensitivityNoise = 1e-9;

void sensitivity_weight_floor(UserData* u, N_Vector y, N_Vector w) {
  const int n = u->problem->size();
  if (!u->state_weights) u->state_weights = w;
  double* wd = N_VGetArrayPointer(w);
  std::vector<double>& cap = u->sensitivity_weight_cap;
  if (w == u->state_weights) {
    const double* yd = N_VGetArrayPointer(y);
    double size = 0;
    for (int i = 0; i < n; ++i)
      if (u->id[i] > 0) size = max_num(size, std::fabs(yd[i]));
    cap.resize(n);  // sized once: no allocation after the first call
    for (int i = 0; i < n; ++i) {
      const double floor = kSensitivityNoise * max_num(size, std::fabs(yd[i]));
      cap[i] = floor > 0 ? 1 / floor : INFINITY;
    }
    return;
  }
  for (int i = 0; i < n && !cap.empty(); ++i) wd[i] = wd[i] > cap[i] ? cap[i] : wd[i];
}

// IDAS's forward sensitivities (IdaOptions::sensitivities): consistent initial values from the
// problem; the staggered corrector (the sensitivities' Newton iterations after the state's, on
// its Newton matrix); error weights those of the state at pbar_i s_i (IDASensEEtolerances).
void open_sensitivities(IdaRun& r) {
  SensitivityProblem* sp = r.o->sensitivities;
  if (!sp) return;
  r.ns = sp->count();
  for (N_Vector** v : {&r.s, &r.sp, &r.ss, &r.sps}) *v = check(N_VCloneVectorArray(r.ns, r.y), "N_VCloneVectorArray");
  r.s_data = data(r.s, r.ns);
  r.sp_data = data(r.sp, r.ns);
  r.ss_data = data(r.ss, r.ns);
  r.sps_data = data(r.sps, r.ns);
  r.ud.sens = sp;
  r.ud.id = data(r.id);
  r.ud.s_in.resize(r.ns);
  r.ud.sp_in.resize(r.ns);
  r.ud.r_out.resize(r.ns);
  sp->initial(r.o->t0, data(r.y), data(r.yp), r.s_data.data(), r.sp_data.data());
  check(IDASensInit(r.mem, r.ns, IDA_STAGGERED, sensitivity_residual_fn, r.s, r.sp), "IDASensInit");
  check(IDASensEEtolerances(r.mem), "IDASensEEtolerances");
  r.pbar.resize(r.ns);
  for (int i = 0; i < r.ns; ++i) r.pbar[i] = sp->scale(i);
  check(IDASetSensParams(r.mem, nullptr, r.pbar.data(), nullptr), "IDASetSensParams");
  check(IDASetSensErrCon(r.mem, sp->in_error_test() ? SUNTRUE : SUNFALSE), "IDASetSensErrCon");
  r.sens_on = true;
}

// IDAS's interpolants of s_i and s_i' at tt (nothing without sensitivities).
bool interpolate_sensitivities(IdaRun& r, double tt, N_Vector* s, N_Vector* sp) {
  for (int i = 0; r.sens_on && i < r.ns; ++i) {
    for (int k = 0; k < 2; ++k) {
      const int flag = IDAGetSensDky1(r.mem, tt, k, i, k == 0 ? s[i] : sp[i]);
      if (flag == IDA_SUCCESS) continue;
      fail(r, "integration_failed",
           "interpolating the sensitivities at t = " + std::to_string(tt) + " failed (" + ida_flag_name(flag) + ")", tt);
      return false;
    }
  }
  return true;
}

// The sensitivities at the last accepted step t_prev into r.s and r.sp: IDAS's interpolant
// there, or, before any step since the last (re)initialization, the values it was given (they
// are still in r.s, r.sp). False (the run not failed) if IDAS cannot give them.
bool sensitivities_at_last_step(IdaRun& r) {
  long steps = 0;
  if (IDAGetNumSteps(r.mem, &steps) != IDA_SUCCESS) return false;
  for (int i = 0; steps > 0 && i < r.ns; ++i)
    if (IDAGetSensDky1(r.mem, r.t_prev, 0, i, r.s[i]) != IDA_SUCCESS ||
        IDAGetSensDky1(r.mem, r.t_prev, 1, i, r.sp[i]) != IDA_SUCCESS)
      return false;
  return true;
}

// The sensitivities again from the last accepted step: their values there (IDAS's
// interpolant), made consistent by the problem, and IDA anew. False if that cannot be done.
static bool retry_sensitivities(IdaRun& r) {
  if (!sensitivities_at_last_step(r)) return false;
  back_to_last_step(r);
  try {
    r.o->sensitivities->restart(r.t, data(r.y), data(r.yp), r.s_data.data(), r.sp_data.data());
  } catch (const SolveError&) {
    return false;
  }
  ++r.stats.sensitivity_fallbacks;
  start_again(r);
  return true;
}

// IDA failed with the sensitivities on: the run goes on without them from its last accepted
// step (their rows end there; IdaStats::sensitivity_failure says why). Where the state itself
// cannot go on, it fails again there and the run ends with that failure.
bool drop_sensitivities(IdaRun& r, int flag) {
  double tt = r.t;
  IDAGetCurrentTime(r.mem, &tt);
  std::ostringstream os;
  os << "IDA failed with the sensitivities at t = " << tt << " (" << ida_flag_name(flag) << ")";
  if (!r.ud.callback_error.empty()) os << ": " << r.ud.callback_error;
  return drop_sensitivities(r, os.str());
}

// After a failure with the sensitivities in the local error test: their error test off for a window of steps after every start of IDA from
// here on (the retry is one), twice as long after each further failure while it is on; after
// kMaxTestFailures, off to the end. Measured: the first steps after an event, cut by the
// sensitivities' test to where their Newton iteration no longer converges (Dynamics I with the
// tyre radius or a hardpoint, docs/sensitivities.md).
static bool sensitivities_out_of_test(IdaRun& r) {
  constexpr int kMaxTestFailures = 10;
  if (!r.o->sensitivities->in_error_test() || r.sens_free_steps > 0 || r.sens_test_failures >= kMaxTestFailures)
    return false;
  r.sens_free_window = r.sens_test_failures == 0 ? 50 : 2 * r.sens_free_window;
  if (++r.sens_test_failures == kMaxTestFailures) r.sens_free_window = std::numeric_limits<long>::max();
  if (r.stats.sensitivity_test_off_time < 0) r.stats.sensitivity_test_off_time = r.t_prev;
  return retry_sensitivities(r);
}

void sensitivity_test_window(IdaRun& r, bool start) {
  if (!r.sens_on || r.sens_test_failures == 0) return;
  if (start) {
    r.sens_free_steps = r.sens_free_window;
    check(IDASetSensErrCon(r.mem, SUNFALSE), "IDASetSensErrCon");
  } else if (r.sens_free_steps > 0 && --r.sens_free_steps == 0) {
    check(IDASetSensErrCon(r.mem, SUNTRUE), "IDASetSensErrCon");
  }
}

bool drop_sensitivities(IdaRun& r, const std::string& why) {
  if (sensitivities_out_of_test(r)) return true;
  std::ostringstream os;
  os << why << "; the run went on without them from t = " << r.t_prev;
  r.stats.sensitivity_failure = os.str();
  check(IDASensToggleOff(r.mem), "IDASensToggleOff");
  r.sens_on = false;
  r.ud.unread_residual = nullptr;  // every residual IDA asks for from here on is evaluated
  back_to_last_step(r);
  start_again(r);
  return true;
}

}  // namespace mbdae::ida_detail
