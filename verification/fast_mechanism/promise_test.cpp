// The tolerance's promise (issue 21) for every formulation, on two mechanisms against independent
// references: the fast mechanism (slider_crank_fast.yaml, its Lagrange equation) and IFToMM A01
// over 10 s (a 1 m pendulum released from the horizontal, about 4 periods, its exact solution
// from Jacobi's sn). Each run uses the model's default absolute tolerances (rtol times the
// length scale); the largest error of the position and of the velocity outputs, relative to the
// largest magnitude of their reference, must be within 10 rtol, at three rtols per formulation.
// The rtols are those where the formulation keeps the promise on both (docs/formulation.md
// "Error control", where the misses outside them are measured): index3 1e-2 .. 1e-6 (A01 missed
// at 1e-3 by 1.3 and at 1e-2 by 12 before its position test per unit of the span) and, run as
// index2-ggl below rtol 1e-6, 1e-8 and 1e-10
// (index3-no-handover stops near 3e-7 and 1.3e-6 relative from rtol 1e-7 on),
// index2-ggl 1e-4 .. 1e-10 (its velocity floor at the random walk of a position's rounding per
// step), index1 1e-2 .. 1e-8 (its Baumgarte rate 1 / T_f) and, run as index2-ggl below rtol 1e-9,
// 1e-10 (index1-no-handover stops near 3e-9 relative on the top and the governor),
// penalty 1e-2 .. 1e-4 (its constraint bias, 1.5e-6 on A01 and 2.9e-6 on the fast mechanism,
// is the floor).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

#include "cases/mbdae.h"
#include "verification/fast_mechanism/fast_mechanism_errors.h"
#include "verification/iftomm/pendulum_exact.h"

namespace mbdae {
namespace {

struct Relative {
  double position = 0, velocity = 0;
  long steps = 0;
};

RunOptions options(const std::string& formulation, double rtol) {
  RunOptions o;
  o.verbose = o.progress = false;
  o.formulation = formulation;
  o.rtol = rtol;
  return o;
}

long steps_of(const Result& r) { return r.summary["steps"].back()["statistics"]["steps"].get<long>(); }

Relative fast_mechanism(const std::string& formulation, double rtol) {
  const Result r = run(load_fast_mechanism(), options(formulation, rtol));
  EXPECT_TRUE(r.ok()) << r.message;
  if (!r.ok()) return {1e300, 1e300, 0};
  const FastMechanismErrors e = fast_mechanism_errors(r);
  return {e.position, e.velocity, steps_of(r)};
}

// A01 over 10 s, samples every 0.01 s, the scene's tolerances removed (model defaults).
Scene a01_ten_seconds() {
  const std::string path = std::string(MBDAE_SOURCE_DIR) + "/verification/iftomm/scenes/A01_simple_pendulum.yaml";
  Scene s = load_scene(path);
  set_parameter(s, "analysis.dynamics.t_end", "10");
  set_parameter(s, "analysis.dynamics.output_step", "0.01");
  AnalysisStep& step = s.steps.back();  // the scene's tight tolerances removed
  step.atol = 0;
  step.rtol = 1e-6;
  step.newton_convergence = AnalysisStep().newton_convergence;
  return s;
}

Relative a01(const std::string& formulation, double rtol) {
  const Result r = run(a01_ten_seconds(), options(formulation, rtol));
  EXPECT_TRUE(r.ok()) << r.message;
  if (!r.ok()) return {1e300, 1e300, 0};
  const PendulumExact exact;
  const int x = r.column_index("x_P1"), y = r.column_index("y_P1");
  const int vx = r.column_index("vx_P1"), vy = r.column_index("vy_P1");
  double ep = 0, ev = 0;
  for (size_t i = 0; i < r.rows(); ++i) {
    const double ti = r.data[0][i], phi = exact.phi(ti);
    // phi' from the energy, phi'^2 = 2 w0^2 cos(phi) (released at rest at phi = pi/2), its sign
    // from the motion
    const double sign = exact.phi(ti + 1e-6) < exact.phi(ti) ? -1.0 : 1.0;
    const double rate = sign * std::sqrt(std::fmax(0.0, 2 * exact.w0 * exact.w0 * std::cos(phi)));
    ep = std::max({ep, std::fabs(r.data[x][i] - std::sin(phi)), std::fabs(r.data[y][i] + std::cos(phi))});
    ev = std::max({ev, std::fabs(r.data[vx][i] - std::cos(phi) * rate), std::fabs(r.data[vy][i] - std::sin(phi) * rate)});
  }
  const double v_scale = std::sqrt(2 * 9.81);  // the speed at the bottom, the largest |v|
  return {ep / 1.0, ev / v_scale, steps_of(r)};
}

void expect_promise(const std::string& formulation, const char* name, Relative (*mechanism)(const std::string&, double),
                    double rtol) {
  const Relative e = mechanism(formulation, rtol);
  std::printf("%-11s %-15s rtol %.0e: positions %.3g, velocities %.3g of their scales (%.2g, %.2g rtol), %ld steps\n",
              formulation.c_str(), name, rtol, e.position, e.velocity, e.position / rtol, e.velocity / rtol, e.steps);
  EXPECT_LE(e.position, 10 * rtol) << formulation << " " << name << " rtol " << rtol;
  EXPECT_LE(e.velocity, 10 * rtol) << formulation << " " << name << " rtol " << rtol;
}

struct Case {
  std::string formulation;
  double rtol;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.formulation << " rtol " << c.rtol; }

class Promise : public ::testing::TestWithParam<Case> {};

TEST_P(Promise, FastMechanism) { expect_promise(GetParam().formulation, "fast mechanism", fast_mechanism, GetParam().rtol); }
TEST_P(Promise, A01TenSeconds) { expect_promise(GetParam().formulation, "A01 (10 s)", a01, GetParam().rtol); }

INSTANTIATE_TEST_SUITE_P(Formulations, Promise,
                         ::testing::Values(Case{"index3", 1e-2}, Case{"index3", 1e-3}, Case{"index3", 1e-4}, Case{"index3", 1e-5}, Case{"index3", 1e-6},
                                           Case{"index3", 1e-8}, Case{"index3", 1e-10},
                                           Case{"index2-ggl", 1e-4}, Case{"index2-ggl", 1e-7},
                                           Case{"index2-ggl", 1e-10}, Case{"index1", 1e-2}, Case{"index1", 1e-4},
                                           Case{"index1", 1e-6}, Case{"index1", 1e-8}, Case{"index1", 1e-10}, Case{"penalty", 1e-2}, Case{"penalty", 1e-3},
                                           Case{"penalty", 1e-4}),
                         [](const ::testing::TestParamInfo<Case>& i) {
                           std::string n = i.param.formulation + "_" + std::to_string(static_cast<int>(-std::log10(i.param.rtol) + 0.5));
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

}  // namespace
}  // namespace mbdae
