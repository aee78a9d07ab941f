// No heap allocation inside the step loop: residual, Newton matrix, KLU refactorization, output
// sampling and IDAS's sensitivities. Every malloc, calloc and realloc of the process is counted
// (C++ new goes through malloc), including those of KLU and SUNDIALS; the dynamics I run is
// observed between two output samples of a phase without events (the restart at an event does
// allocate, by design).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "core/ida_driver.h"
#include "core/tests/decay_problem.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "verification/benchmarks/suspension_fixture.h"

namespace {
std::atomic<long> g_allocations{0};
}

// C allocations too (KLU, SUNDIALS): interpose malloc, calloc and realloc.
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t m) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, m);
}
extern "C" void* realloc(void* p, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}

void* operator new(std::size_t n) {
  if (void* p = std::malloc(n ? n : 1)) return p;  // counted by malloc
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace mbdae {
namespace {

void expect_none_in_the_step_loop(bool reduced_newton) {
  bench::SuspensionFixture f = bench::suspension_at_equilibrium(
      std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/dynamics_step.yaml");
  Index3Dae dae(f.sys, 1.0);
  std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
  std::copy(f.q.begin(), f.q.end(), y.begin());
  dae.state().modes = initial_modes(f.sys, y.data(), 0.0);
  dae.consistent_initial_values(0.0, y, yp);
  IdaOptions o;
  o.t0 = 0;
  o.t1 = 1.5;
  o.rtol = 1e-8;
  o.atol = 1e-14;
  o.output_step = 0.001;
  o.reduced_newton = reduced_newton;
  std::vector<double> q, v, a, sensors(f.sys.sensors.size());
  long at_start = -1, at_end = -1, samples = 0, steps_seen = 0;
  // Windows without events: before the ground step (0.05..0.19 s, at rest) and the settled end
  // (1.0..1.45 s, moving). Samples inside each window count.
  long window_allocations = 0;
  auto output = [&](double t, const double* yy, const double* yyp) {
    dae.consistent_output(t, yy, yyp, q, v, a, false);
    evaluate_sensors(f.sys, dae.state().modes, q.data(), v.data(), a.data(), t, sensors.data());
    const bool in_window = (t >= 0.05 && t <= 0.19) || (t >= 1.0 && t <= 1.45);
    if (in_window && at_start < 0) at_start = g_allocations.load();
    if (!in_window && at_start >= 0) {
      at_end = g_allocations.load();
      window_allocations += at_end - at_start;
      at_start = -1;
    }
    if (in_window) ++samples;
    return true;
  };
  const IdaStats st = integrate(dae, o, y, yp, output);
  ASSERT_TRUE(st.ok) << st.message;
  steps_seen = st.steps;
  EXPECT_GT(samples, 500);
  EXPECT_GT(steps_seen, 100);
  EXPECT_EQ(window_allocations, 0) << "heap allocations inside the step loop";
  // The counter works: the setup and the restarts at events allocate.
  EXPECT_GT(g_allocations.load(), 100);
}

// The step loop of IDAS with sensitivities (their vector arrays, their residual and solves), on
// the decay of core/tests/decay_problem.h and three copies of its sensitivity to the initial value.
TEST(Allocations, NoneInTheStepLoopWithSensitivities) {
  testing::DecayProblem p;
  testing::DecayInitialValue sens;
  sens.copies = 3;  // several: their solves batched
  std::vector<double> y = {1.0, 2.0}, yp = {-1.0, -2.0};
  IdaOptions o;
  o.t1 = 20;
  o.rtol = 1e-10;
  o.atol = 1e-12;
  o.output_step = 0.01;
  o.sensitivities = &sens;
  long at_first = -1, at_last = -1, rows = 0;
  o.sensitivity_output = [&](double t, const double*, const double*, const double* const*, const double* const*) {
    if (t >= 1.0 && at_first < 0) at_first = g_allocations.load();
    if (t <= 19.0) at_last = g_allocations.load();
    ++rows;
  };
  const IdaStats st = integrate(p, o, y, yp, [](double, const double*, const double*) { return true; });
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_GT(st.steps, 100);
  EXPECT_EQ(rows, 2001);
  EXPECT_EQ(at_last - at_first, 0) << "heap allocations in the step loop with sensitivities";
}

TEST(Allocations, NoneInTheStepLoop) { expect_none_in_the_step_loop(false); }
// The same with the reduced Newton solve (core/reduced_linear_solver.h).
TEST(Allocations, NoneInTheReducedNewtonStepLoop) { expect_none_in_the_step_loop(true); }

}  // namespace
}  // namespace mbdae
