// A formulation run through core/ida_driver integrate(), sampled as run() samples it (projected
// output), for the formulation tests: coordinate 0 and its rate at every sample.
#pragma once

#include <algorithm>
#include <vector>

#include "core/ida_driver.h"
#include "formulation/mechanics.h"
#include "formulation/system.h"
#include "formulation/tests/pendulum_reference.h"

namespace mbdae::testing {

struct RunResult {
  IdaStats stats;
  std::vector<double> t, x, rate;  // coordinate 0 and its rate at the samples
  double max_position_violation = 0, max_norm_drift = 0;
};

// Integrates `dae` from the model's initial configuration at rest.
template <class Dae>
RunResult integrate_model(Dae& dae, const IdaOptions& o) {
  const System& sys = dae.system();
  RunResult run;
  std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
  std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
  dae.state().modes = initial_modes(sys, y.data(), o.t0);
  dae.consistent_initial_values(o.t0, y, yp);
  std::vector<double> q, v, a;
  run.stats = integrate(dae, o, y, yp, [&](double t, const double* yy, const double* yyp) {
    dae.consistent_output(t, yy, yyp, q, v, a, true);
    run.t.push_back(t);
    run.x.push_back(coordinate_value(sys, 0, q.data()));
    run.rate.push_back(coordinate_rate(sys, 0, q.data(), v.data()));
    return true;
  });
  run.max_position_violation = dae.state().statistics.max_position_violation;
  run.max_norm_drift = dae.state().statistics.max_norm_drift;
  return run;
}

// The mean period of coordinate 0 between its downward zero crossings; 0 with fewer than two.
inline double measured_period(const RunResult& r) {
  const std::vector<double> c = downward_crossings(r.t, r.x, r.rate);
  if (c.size() < 2) return 0;
  return (c.back() - c.front()) / static_cast<double>(c.size() - 1);
}

}  // namespace mbdae::testing
