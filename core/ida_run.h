// The IDA driver's run (core/ida_driver.cpp) and its sensitivities (core/ida_sensitivities.cpp):
// internal to those two files. IdaRun holds one integration's SUNDIALS objects and bookkeeping;
// UserData is what IDA's callbacks see.
#pragma once

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/ida_driver.h"
#include "core/sundials_compat.h"

namespace mbdae::ida_detail {

struct UserData {
  DaeProblem* problem;
  void* mem;
  SUNLinearSolver ls = nullptr;  // the Newton matrix's solver (the sensitivities' solves batched)
  double rtol, atol, h_initial;
  std::string last_ida_error;  // IDA's own words about its last error (not printed)
  std::string callback_error;  // an exception of the problem's residual or Jacobian
  std::string callback_status;  // a SolveError's status (a load that is not finite), else empty
  int non_finite = -1;         // a component of y found not finite by weights_fn
  double non_finite_value = 0;
  SensitivityProblem* sens = nullptr;  // IdaOptions::sensitivities
  N_Vector state_weights = nullptr;    // the state's weight vector (IDA's first weights_fn call)
  const double* id = nullptr;          // the error test's mask
  // The sensitivities' largest weights, 1 / (kSensitivityNoise max(|y|, |y_i|)) (+inf where
  // that is 0), from the state at its last weights.
  std::vector<double> sensitivity_weight_cap;
  std::vector<const double*> s_in, sp_in;  // the sensitivity residual's arguments as arrays
  std::vector<double*> r_out;
  // The vector IDAS hands the sensitivity residual as F(y), where that residual does not read it
  // (SensitivityProblem::reads_state_residual), else null: in the staggered corrector IDAS
  // evaluates F at each step's converged state into it, for its own difference quotients.
  N_Vector unread_residual = nullptr;
};

// No C++ exception may cross IDA's C frames: one from the problem's residual or Jacobian (a bug,
// such as an assembly that does not repeat its pattern) is kept and IDA stopped (return -1).
inline int callback_failed(UserData* u, const char* where, const std::exception& e) {
  u->callback_error = std::string(where) + ": " + e.what();
  return -1;
}
// A SolveError of the problem (a load that is not finite, formulation/sensors.cpp) ends the run
// with its own status and message.
inline int callback_solve_error(UserData* u, const SolveError& e) {
  u->callback_status = e.status;
  u->callback_error = e.what();
  return -1;
}

// Every SUNDIALS call that returns a flag goes through check: a negative flag (a setting IDA
// refused, memory it could not get) ends the run as an internal error naming the call.
inline void check(int flag, const char* call) {
  if (flag < 0) throw SolveError("internal_error", std::string(call) + " failed (" + ida_flag_name(flag) + ")");
}
template <class T>
T check(T made, const char* call) {
  if (!made) throw SolveError("internal_error", std::string(call) + " returned nothing (out of memory?)");
  return made;
}

// One integration: the SUNDIALS objects, the segment and sample bookkeeping, the statistics.
// Built by open_run, advanced by the stages below; the destructor frees the SUNDIALS objects.
struct IdaRun {
  DaeProblem* problem = nullptr;
  const IdaOptions* o = nullptr;
  const std::function<bool(double, const double*, const double*)>* output = nullptr;
  int n = 0;
  SUNContext ctx = nullptr;
  N_Vector y = nullptr, yp = nullptr, id = nullptr, ys = nullptr, yps = nullptr;
  SUNMatrix jac = nullptr;
  SUNLinearSolver ls = nullptr;
  void* mem = nullptr;
  UserData ud{};
  double h_cap = 0;  // the first step never exceeds the default one
  int nsw = 0;       // switching functions
  std::vector<int> roots;
  std::vector<double> bps;  // breakpoints inside the span, sorted
  bool end_is_breakpoint = false;
  size_t next_bp = 0;
  long sample_index = 0;  // the next output sample; -1 once the last is emitted
  bool stop_requested = false;
  bool with_derivative = false;
  double t = 0, t_prev = 0;  // the current time and that of the last accepted step
  std::vector<double> y_prev, yp_prev;
  std::vector<double> y_before, yp_before;  // the state a restart started from (the sensitivities' restart)
  IdaStats stats;
  long fresh_seen = 0;    // fresh Newton-matrix factorizations already passed to after_fresh_factorization
  long watch_steps = 0;  // steps since watch_t (the step budget, IdaOptions::max_total_steps)
  double watch_t = 0;
  int watch_strikes = 0;  // windows in a row whose rate projects more than the budget
  // Sensitivities (IdaOptions::sensitivities): ns vectors each of s and s' (the state's, kept
  // between IDAS calls) and of a sample's interpolated ones; their data pointers.
  int ns = 0;
  bool sens_on = false;  // false once IDA failed with them (drop_sensitivities)
  // The sensitivities out of the local error test for sens_free_steps more steps after a start
  // of IDA, once a failure took them out (sensitivities_out_of_test): window and failures.
  long sens_free_steps = 0, sens_free_window = 0;
  int sens_test_failures = 0;
  N_Vector *s = nullptr, *sp = nullptr, *ss = nullptr, *sps = nullptr;
  std::vector<double*> s_data, sp_data, ss_data, sps_data;
  std::vector<double> pbar;

  IdaRun() = default;
  IdaRun(const IdaRun&) = delete;
  IdaRun& operator=(const IdaRun&) = delete;
  ~IdaRun() {
    if (mem) IDAFree(&mem);
    if (ls) SUNLinSolFree(ls);
    if (jac) SUNMatDestroy(jac);
    for (N_Vector v : {y, yp, id, ys, yps})
      if (v) N_VDestroy(v);
    for (N_Vector* v : {s, sp, ss, sps})
      if (v) N_VDestroyVectorArray(v, ns);
    if (ctx) SUNContext_Free(&ctx);
  }
};

inline double* data(N_Vector v) { return N_VGetArrayPointer(v); }

inline std::vector<double*> data(N_Vector* v, int n) {
  std::vector<double*> out(n);
  for (int i = 0; i < n; ++i) out[i] = data(v[i]);
  return out;
}

// Defined in core/ida_driver.cpp: a failure other than IDA's own ends the run (the first is
// kept); IDA anew at r.t (first step, reinit, next stop); back to the last accepted step.
void fail(IdaRun& r, const std::string& status, const std::string& message, double tt);
void start_again(IdaRun& r);
void back_to_last_step(IdaRun& r);

// Defined in core/ida_sensitivities.cpp (IdaOptions::sensitivities).
// The sensitivities' error weights never below the twins' difference noise (weights_fn calls it).
void sensitivity_weight_floor(UserData* u, N_Vector y, N_Vector w);
// IDAS's forward sensitivities on an opened run; nothing without them.
void open_sensitivities(IdaRun& r);
// IDAS's interpolants of s_i and s_i' at tt into s, sp; false (the run failed) if it cannot.
bool interpolate_sensitivities(IdaRun& r, double tt, N_Vector* s, N_Vector* sp);
// The sensitivities at the last accepted step into r.s, r.sp; false (the run not failed) if not.
bool sensitivities_at_last_step(IdaRun& r);
// IDA failed with the sensitivities on: them again from the last accepted step out of their
// error test for a window (sensitivities_out_of_test), or the run on without them. True: the run goes on.
bool drop_sensitivities(IdaRun& r, int flag);
// The same for a reason of the driver's own (the steps held back by the sensitivities).
bool drop_sensitivities(IdaRun& r, const std::string& why);
// At a start of IDA (start) and after each accepted step: the sensitivities' error test off
// for the window that a failure in it opened (sensitivities_out_of_test).
void sensitivity_test_window(IdaRun& r, bool start);

}  // namespace mbdae::ida_detail
