// Runs that cannot give true numbers must stop with a failure that says why (docs/errors.md,
// exit code 3) instead of writing NaN or inf with status ok, or failing with an unrelated
// message: an expression sensor that is infinite, masses or gravity that overflow double
// precision, scenes in which nothing moves. The scenes are variants of one pendulum, run as
// `mbdae run` runs them (load_scene_text + run_scene).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cases/mbdae.h"
#include "cases/scene/scene.h"

namespace {

// A pendulum on a hinge; `extra` is appended to its sensors, `mass`, `gravity` replace its own.
std::string pendulum(const std::string& mass = "2", const std::string& gravity = "-9.81",
                     const std::string& extra = "") {
  return "name: pend\n"
         "gravity: [0, 0, " + gravity + "]\n"
         "bodies:\n"
         "  - {name: arm, mass: " + mass + ", com: [0, 0, -0.5], inertia: {xx: 0.1, yy: 0.1, zz: 0.01}}\n"
         "joints:\n"
         "  - {name: hinge, parent: ground, child: arm, anchor: [0, 0, 0], chain: [R2], coordinates: [theta]}\n"
         "coordinates:\n"
         "  theta: {initial_deg: 30}\n"
         "sensors:\n"
         "  - {name: theta, type: coordinate, coordinate: theta}\n" + extra +
         "analysis:\n"
         "  - {type: dynamics, t_end: 1, output_step: 0.1}\n";
}

mbdae::Result run_text(const std::string& text) {
  mbdae::RunOptions o;
  o.verbose = false;
  o.progress = false;
  return mbdae::run(mbdae::load_scene_text(text, "scene.yaml"), o);
}

void expect_failure(const mbdae::Result& r, const std::string& status, const std::string& words) {
  EXPECT_EQ(r.exit_code, 3) << r.summary.dump(2);
  EXPECT_EQ(r.summary["status"], status) << r.summary.dump(2);
  const std::string message = r.summary.value("message", "");
  EXPECT_NE(message.find(words), std::string::npos) << message;
}

TEST(NumericFailures, PendulumRunsCleanly) {  // the scene itself is fine
  const mbdae::Result r = run_text(pendulum());
  EXPECT_EQ(r.exit_code, 0) << r.summary.dump(2);
  EXPECT_EQ(r.rows(), 11u);
}

// An expression sensor dividing by zero was written as inf in every row, with status ok.
TEST(NumericFailures, InfiniteSensorStopsTheRun) {
  const mbdae::Result r =
      run_text(pendulum("2", "-9.81", "  - {name: inverse, type: expression, expression: \"1 / (theta - theta)\"}\n"));
  expect_failure(r, "non_finite", "sensor inverse is +inf at t = 0 ");
  EXPECT_EQ(r.rows(), 0u);  // no row with inf is written
}

// A sensor that becomes NaN later: asin((0.6 - theta) / 0.6) once theta < 0 (released at
// 30 deg, the pendulum, of period 1.55 s, passes 0 at about 0.39 s): the rows before are kept,
// the run stops at the first NaN sample (t = 0.4).
TEST(NumericFailures, SensorTurningNaNStopsAtThatSample) {
  const mbdae::Result r = run_text(
      pendulum("2", "-9.81", "  - {name: odd, type: expression, expression: \"asin((0.6 - theta) / 0.6)\"}\n"));
  expect_failure(r, "non_finite", "sensor odd is NaN at t = 0.4 ");
  ASSERT_EQ(r.rows(), 4u);  // t = 0 ... 0.3
  for (const auto& row : r.row_major()) {
    EXPECT_GT(row[1], 0.0);
    EXPECT_TRUE(std::isfinite(row[2]));
  }
}

// Masses or gravity beyond double precision said "the augmented mass matrix is singular".
TEST(NumericFailures, OverflowingInputsSayOverflow) {
  expect_failure(run_text(pendulum("1e308")), "overflow", "overflow: the applied forces of body arm");
  expect_failure(run_text(pendulum("2", "-1e308")), "overflow", "overflow: the applied forces of body arm");
}

// An empty scene, or one whose only body is welded to ground, said "velocity projection is
// singular".
TEST(NumericFailures, NothingMoves) {
  const std::string empty =
      "name: empty\nanalysis:\n  - {type: dynamics, t_end: 1, output_step: 0.1}\n";
  expect_failure(run_text(empty), "nothing_moves", "nothing moves: ");
  const std::string welded =
      "name: weld\n"
      "bodies:\n  - {name: block, mass: 1}\n"
      "joints:\n  - {name: fix, parent: ground, child: block, anchor: [0, 0, 1], chain: []}\n"
      "analysis:\n  - {type: kinematics, t_end: 1, output_step: 0.1}\n";
  expect_failure(run_text(welded), "nothing_moves", "nothing moves: ");
}

}  // namespace
