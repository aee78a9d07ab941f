// Google Benchmark of the step loop's kernels on the five-point suspension (dynamics I system,
// 7 bodies, 49 coordinates, 47 constraint equations): the DAE residual, the Newton matrix
// assembly, a KLU numeric refactorization of it, and one output sample (acceleration solve and
// sensors). Run: build/verification/benchmarks/kernels_benchmark
#include <benchmark/benchmark.h>

#include "core/klu_solver.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "verification/benchmarks/suspension_fixture.h"

namespace {

using namespace mbdae;

// The row scaling run() uses: mean body mass / (1e-3 s)^2.
double constraint_scale(const System& sys) {
  double m = 0;
  for (const auto& b : sys.bodies) m += b.mass;
  return m / sys.bodies.size() / 1e-6;
}

struct State {
  bench::SuspensionFixture f;
  Index3Dae dae;
  std::vector<double> y, yp, r, values;
  explicit State(bench::SuspensionFixture fx)
      : f(std::move(fx)), dae(f.sys, constraint_scale(f.sys)), y(dae.size()), yp(dae.size()), r(dae.size()),
        values(dae.jacobian_pattern().nnz()) {
    std::copy(f.q.begin(), f.q.end(), y.begin());
    dae.state().modes = initial_modes(f.sys, y.data(), 0.0);
    dae.consistent_initial_values(0.0, y, yp);
    // A moving state: give the suspension some velocity along its degree of freedom.
    for (int i = 0; i < dae.nq(); ++i) y[dae.nq() + i] += 1e-3 * ((i * 7) % 5 - 2);
  }
};

State& state() {
  static State s(bench::suspension_at_equilibrium(std::string(MBDAE_SOURCE_DIR) +
                                                  "/cases/five_point_suspension/dynamics_step.yaml"));
  return s;
}

void BM_Residual(benchmark::State& st) {
  State& s = state();
  for (auto _ : st) {
    s.dae.residual(0.1, s.y.data(), s.yp.data(), s.r.data());
    benchmark::DoNotOptimize(s.r.data());
  }
  st.counters["bodies"] = s.f.sys.num_bodies();
  st.counters["ns_per_body"] = benchmark::Counter(s.f.sys.num_bodies(), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Residual);

void BM_NewtonMatrix(benchmark::State& st) {
  State& s = state();
  for (auto _ : st) {
    s.dae.jacobian(0.1, 1e4, s.y.data(), s.yp.data(), s.values.data());
    benchmark::DoNotOptimize(s.values.data());
  }
  st.counters["nnz"] = s.values.size();
  st.counters["ns_per_body"] = benchmark::Counter(s.f.sys.num_bodies(), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_NewtonMatrix);

void BM_KluRefactor(benchmark::State& st) {
  State& s = state();
  s.dae.jacobian(0.1, 1e4, s.y.data(), s.yp.data(), s.values.data());
  KluSolver klu;
  klu.analyze(s.dae.jacobian_pattern());
  klu.factor(s.values.data());
  for (auto _ : st) benchmark::DoNotOptimize(klu.factor(s.values.data()));
  st.counters["n"] = s.dae.size();
  st.counters["rcond"] = klu.rcond();
  st.counters["full_factorizations"] = klu.full_factorizations();
}
BENCHMARK(BM_KluRefactor);

void BM_OutputSample(benchmark::State& st) {
  State& s = state();
  std::vector<double> q, v, a, out(s.f.sys.sensors.size());
  for (auto _ : st) {
    s.dae.consistent_output(0.1, s.y.data(), s.yp.data(), q, v, a, false);
    evaluate_sensors(s.f.sys, s.dae.state().modes, q.data(), v.data(), a.data(), 0.1, out.data());
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_OutputSample);

void BM_OutputSampleProjected(benchmark::State& st) {
  State& s = state();
  std::vector<double> q, v, a, out(s.f.sys.sensors.size());
  for (auto _ : st) {
    s.dae.consistent_output(0.1, s.y.data(), s.yp.data(), q, v, a, true);
    evaluate_sensors(s.f.sys, s.dae.state().modes, q.data(), v.data(), a.data(), 0.1, out.data());
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_OutputSampleProjected);

}  // namespace

BENCHMARK_MAIN();
