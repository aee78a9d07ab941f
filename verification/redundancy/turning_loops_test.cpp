// Planar loops in a turning plane (issue 23): a four-bar on a turntable and a flyball governor
// with pinned sleeve links, both closed by revolute cuts whose redundant equations (3 per cut)
// lie along the loop's normal, which turns in the world. Every formulation must reach the end
// `ok`, with the equations set aside named in summary.json, and the right motion against the
// one-degree-of-freedom Lagrange references of turning_loops_reference.h: index3 within the
// promise (every position and velocity within 10 rtol of its scale, the largest |x_ref|); the
// other formulations, whose error control tests local errors per step and does not promise
// 10 rtol (docs/formulation.md, "What the tolerance does not promise"), converging to the
// reference as rtol tightens (a loop opened by a degraded equation choice does not).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <tuple>

#include "verification/redundancy/turning_loops_cases.h"

namespace mbdae {
namespace {

TEST(TurningLoops, ReferencesConverged) {
  std::vector<double> times;
  for (int k = 0; k <= 300; ++k) times.push_back(0.01 * k);
  for (const TurningCase* c : {&kTurntableFourBar, &kPinnedGovernor}) {
    const auto fine = c->reference(c->theta0, c->rate0, times, kTurningReferenceStep);
    const auto coarse = c->reference(c->theta0, c->rate0, times, 2 * kTurningReferenceStep);
    double d = 0;
    for (size_t k = 0; k < fine.size(); ++k) d = std::max(d, std::fabs(fine[k].theta - coarse[k].theta));
    EXPECT_LT(d, 1e-10) << c->scene;  // RK4: the fine one 16 times closer still, far below the 1e-7 compared
    std::printf("%s: reference theta(3 s) = %.12f, doubling the step changes it by %.2g rad\n", c->scene,
                fine.back().theta, d);
  }
}

Result run_case(const TurningCase& c, const std::string& formulation, double rtol) {
  RunOptions opt;
  opt.formulation = formulation;
  opt.rtol = rtol;
  opt.verbose = false;
  opt.progress = false;
  return run(load_turning_case(c), opt);
}

// Ends ok with every sample, the equations set aside at t = 0 named (cut equations only).
void expect_complete(const TurningCase& c, const Result& r) {
  ASSERT_TRUE(r.ok()) << r.message;
  ASSERT_EQ(r.rows(), 301u);
  const auto& rc = r.summary["redundant_constraints"];
  EXPECT_EQ(static_cast<int>(rc["redundant"].size()), c.redundant) << rc.dump(1);
  ASSERT_EQ(rc["set_aside"].size(), 1u) << rc.dump(1);
  EXPECT_EQ(rc["set_aside"][0]["t"].get<double>(), 0.0);
  EXPECT_EQ(rc["set_aside"][0]["equations"], rc["redundant"]);
  for (const auto& eq : rc["redundant"]) EXPECT_EQ(eq.get<std::string>().rfind("cut ", 0), 0u) << eq;
}

class TurningLoop : public ::testing::TestWithParam<std::tuple<int, std::string>> {};

TEST_P(TurningLoop, RunsToTheEndWithTheRightMotion) {
  const TurningCase& c = std::get<0>(GetParam()) == 0 ? kTurntableFourBar : kPinnedGovernor;
  const std::string& formulation = std::get<1>(GetParam());
  const double rtol = load_turning_case(c).steps.back().rtol;  // the default, 1e-6
  const Result r = run_case(c, formulation, rtol);
  expect_complete(c, r);
  if (HasFatalFailure()) return;
  const TurningErrors e = turning_errors(c, r);
  std::printf("%s %s, rtol %g: largest error / scale %.3g (%.3g rtol)\n", c.scene, formulation.c_str(), rtol, e.worst,
              e.worst / rtol);
  // Every formulation with an error control that promises 10 rtol keeps it (since issue 21:
  // index2-ggl, index1 and penalty per unit of the run's span; measured 0.24 to 8.7 rtol, penalty's
  // 8.7 on the four-bar being its constraint bias).
  if (formulation != "index3-positions") {
    for (size_t k = 0; k < e.sensors.size(); ++k)
      EXPECT_LE(e.error[k], 10 * rtol * e.scale[k])
          << formulation << ": " << e.sensors[k] << " error " << e.error[k] << " on a scale of " << e.scale[k];
    return;
  }
  // index3-positions tests local errors per step (no promise): converging, 1000 times tighter at
  // least 30 times closer (measured 165 to 360 times).
  const Result tight = run_case(c, formulation, rtol / 1000);
  expect_complete(c, tight);
  if (HasFatalFailure()) return;
  const TurningErrors et = turning_errors(c, tight);
  std::printf("%s %s, rtol %g: largest error / scale %.3g\n", c.scene, formulation.c_str(), rtol / 1000, et.worst);
  EXPECT_LT(30 * et.worst, e.worst) << formulation;
  EXPECT_LT(e.worst, 0.5) << formulation;  // not a different motion
}

// The former choice (redundant_constraints: remove_world, world components set aside at t = 0)
// degrades at the first quarter turn of the four-bar. It is never `ok` with a wrong motion:
// index3 fails where the kept equations go singular and the diagnosis says the choice degraded,
// not the mechanism; index1 and penalty (which ended 1.3 rad off before the watch) stop at the
// first sample where the equations set aside no longer hold.
// The failure at a degraded world choice: its diagnosis, at a quarter turn (the loop's normal
// along world x), with the equations chosen again named.
void expect_degraded_choice(const Result& r, const std::string& formulation) {
  EXPECT_EQ(r.status, "integration_failed") << formulation;
  EXPECT_NE(r.message.find("(a degraded equation choice, not a singular configuration)"), std::string::npos)
      << formulation << ": " << r.message;
  const auto& step = r.summary["steps"].back();
  ASSERT_TRUE(step.contains("equation_choice")) << formulation << ": " << step.dump(1);
  EXPECT_TRUE(step["equation_choice"]["degraded"].get<bool>()) << formulation;
  EXPECT_EQ(step["equation_choice"]["set_aside_again"].get<int>(), 3) << formulation;
  const double t = step["t_reached"].get<double>();
  EXPECT_NEAR(std::fmod(t, 0.5), 0.25, 0.01) << formulation << ": " << t;
}

// With the world choice the kept equations go singular at every quarter turn. A run either stops
// there with the diagnosis or steps over it with the right motion (within the promise), never
// `ok` with a wrong one. Measured: index3 fails at the first one (0.2485 s: the check after a
// fresh factorization, cases/run/integration_stage.cpp; before, it stepped over the quarter turns
// until 2.25 s, or to the end with a wrong motion at other rtols and orderings), index2-ggl too
// (0.2495 s, s_min / s_max 3.8e-4: the nearly singular case of cases/run/failure_diagnosis.h),
// index1 and penalty just before the quarter turn, with the same diagnosis (the same check), or
// at the watch on the equations set aside (before that check).
TEST(TurningLoops, WorldChoiceIsDiagnosedNeverOkWithAWrongMotion) {
  Scene scene = load_turning_case(kTurntableFourBar);
  scene.redundant_constraints = "remove_world";
  RunOptions opt;
  opt.progress = false;
  opt.verbose = false;
  opt.formulation = "index3";
  const Result r3 = run(scene, opt);
  if (r3.ok()) {
    const double rtol = scene.steps.back().rtol;
    const TurningErrors e = turning_errors(kTurntableFourBar, r3);
    std::printf("index3, world choice: ok, largest error / scale %.3g (%.3g rtol)\n", e.worst, e.worst / rtol);
    EXPECT_EQ(r3.rows(), 301u);
    EXPECT_LE(e.worst, 10 * rtol);
  } else {
    expect_degraded_choice(r3, "index3");
  }
  opt.formulation = "index2-ggl";
  expect_degraded_choice(run(scene, opt), "index2-ggl");
  for (const char* f : {"index1", "penalty"}) {
    opt.formulation = f;
    const Result r = run(scene, opt);
    if (r.message.find("no longer hold at t = 0.25") == std::string::npos) expect_degraded_choice(r, f);
    EXPECT_EQ(r.status, "integration_failed") << f;
    EXPECT_EQ(r.rows(), 25u) << f;  // t = 0 ... 0.24; the sample at 0.25 is not written
  }
}

INSTANTIATE_TEST_SUITE_P(Formulations, TurningLoop,
                         ::testing::Combine(::testing::Values(0, 1),
                                            ::testing::Values("index3", "index3-positions", "index2-ggl", "index1",
                                                              "penalty")));

}  // namespace
}  // namespace mbdae
