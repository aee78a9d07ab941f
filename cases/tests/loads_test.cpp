// Closed-form checks of the loads of issue 13, each a small scene run through the public API:
// a torque-driven wheel, a motor whose torque is an expression of its speed, a follower force on
// a pinned bar (free, and held by a torsional spring), a torsional pendulum (undamped, damped),
// a mass on a bushing, a slider pushed by an expression of its position and velocity. Also the
// scene ergonomics: named ground points, points as [x, y, z], continuous coordinate sensors and
// the loader's messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <utility>

#include "cases/mbdae.h"
#include "core/errors.h"
#include "cases/tests/test_scenes.h"
#include "formulation/system.h"

namespace mbdae {
namespace {

// A wheel (inertia J = 0.5 about z) on a revolute joint R3 at the origin, no gravity.
std::string wheel(const std::string& forces, const std::string& sensors, const std::string& extra = "") {
  return R"(name: wheel
gravity: [0, 0, 0]
bodies:
  - {name: wheel, mass: 1.0, inertia: {xx: 0.3, yy: 0.3, zz: 0.5}}
joints:
  - {name: axle, parent: ground, child: wheel, anchor: [0, 0, 0], chain: [R3], coordinates: [theta]}
coordinates:
  theta: {initial: 0}
forces:)" + (forces.empty() ? std::string(" []\n") : "\n" + forces) +
         "sensors:" + (sensors.empty() ? std::string(" []\n") : "\n" + sensors) + extra;
}

Result run_text(const std::string& text) {
  const Scene scene = load_scene_text(text, "loads_test.yaml");
  RunOptions opt;
  Result r = run(scene, opt);
  EXPECT_TRUE(r.ok()) << r.message;
  return r;
}

const char* const kTight = R"(analysis:
  - {type: assembly, hold: [theta]}
  - {type: dynamics, t_end: T_END, output_step: 0.05, rtol: 1.0e-10, atol: 1.0e-12, formulation: FORM}
)";
// The closed forms are checked at rtol 1e-10 with the default index3 (whose error test bounds the
// velocity error per unit step since issue 13) and the formulations whose error test covers the
// velocities directly (index2-ggl, index1).
const char* const kFormulations[] = {"index3", "index2-ggl", "index1"};
std::string analysis(double t_end, const std::string& formulation = "index3") {
  std::string a = kTight;
  a.replace(a.find("T_END"), 5, std::to_string(t_end));
  a.replace(a.find("FORM"), 4, formulation);
  return a;
}

// theta = T t^2 / (2 J): 2 N m on J = 0.5, 18 rad (almost three turns) at t = 3. The axis is
// world-fixed in one run and body-fixed in the other (the same here: the body's z stays z).
TEST(Loads, TorqueDrivenWheel) {
  for (const char* form : kFormulations)
  for (const char* frame : {"world", "body"}) {
    SCOPED_TRACE(std::string(form) + ", axis in " + frame);
    const Result r = run_text(wheel(std::string("  - {name: motor, type: torque, body: wheel, axis: [0, 0, 1], frame: ") +
                                        frame + ", torque: 2}\n",
                                    "  - {name: angle, type: coordinate, coordinate: theta}\n"
                                    "  - {name: wrapped, type: coordinate, coordinate: theta, wrap: true}\n"
                                    "  - {name: torque, type: force_value, force: motor}\n",
                                    analysis(3.0, form)));
    const auto& t = r.column("t");
    const auto& angle = r.column("angle");
    const auto& wrapped = r.column("wrapped");
    ASSERT_GT(t.size(), 50u);
    double worst = 0;
    for (size_t k = 0; k < t.size(); ++k) {
      const double exact = 2.0 * t[k] * t[k];
      worst = std::max(worst, std::fabs(angle[k] - exact));
      // The wrapped sensor is the same angle in (-pi, pi].
      EXPECT_NEAR(std::remainder(wrapped[k] - exact, 2 * M_PI), 0.0, 1e-6) << t[k];
      EXPECT_GT(wrapped[k], -M_PI - 1e-12);
      EXPECT_LE(wrapped[k], M_PI + 1e-12);
    }
    EXPECT_NEAR(t.back(), 3.0, 1e-12);
    EXPECT_NEAR(angle.back(), 18.0, 1e-6) << frame;  // multi-turn: no jump at +-pi
    EXPECT_LT(worst, 1e-6) << frame;
    EXPECT_DOUBLE_EQ(r.column("torque").back(), 2.0);
  }
}

// A motor T = T0 (1 - w / w0) with w the wheel's speed (a coordinate_rate sensor): from rest,
// w(t) = w0 (1 - exp(-a t)), theta(t) = w0 (t - (1 - exp(-a t)) / a), a = T0 / (J w0).
TEST(Loads, MotorTorqueGivenByAnExpressionOfTheSpeed) {
  for (const char* form : kFormulations) {
  SCOPED_TRACE(form);
  const Result r = run_text(wheel("  - {name: motor, type: torque, body: wheel, axis: [0, 0, 1], "
                                  "torque: \"T0 * (1 - w / w0)\", parameters: {T0: 2, w0: 10}}\n",
                                  "  - {name: w, type: coordinate_rate, coordinate: theta}\n"
                                  "  - {name: angle, type: coordinate, coordinate: theta}\n"
                                  "  - {name: torque, type: force_value, force: motor}\n",
                                  analysis(5.0, form)));
  const double a = 2.0 / (0.5 * 10.0);
  const auto& t = r.column("t");
  double worst_w = 0, worst_angle = 0, worst_torque = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double e = std::exp(-a * t[k]);
    worst_w = std::max(worst_w, std::fabs(r.column("w")[k] - 10.0 * (1 - e)));
    worst_angle = std::max(worst_angle, std::fabs(r.column("angle")[k] - 10.0 * (t[k] - (1 - e) / a)));
    worst_torque = std::max(worst_torque, std::fabs(r.column("torque")[k] - 2.0 * e));
  }
  EXPECT_LT(worst_w, 1e-6);
  EXPECT_LT(worst_angle, 1e-6);
  EXPECT_LT(worst_torque, 1e-6);
  EXPECT_GT(r.column("angle").back(), 2 * M_PI);
  }
}

// A bar (mass 2, length 1 along x, pinned at one end about z) pushed at its tip by a follower
// force F = 3 along the bar's own y axis: a constant moment F L about the pin, so
// theta = F L t^2 / (2 J), J = m L^2 / 3 = 2/3 (a world-fixed force would not give this).
// With a torsional spring k = 30 (and damping 8) on the pin it settles at theta = F L / k.
std::string bar(const std::string& spring, const std::string& analysis_text) {
  return R"(name: bar
gravity: [0, 0, 0]
ground: {points: {pin: [0, 0, 0]}}
bodies:
  - {name: bar, mass: 2.0, com: [0.5, 0, 0], inertia: {xx: 0.01, yy: 0.1666666666666667, zz: 0.1666666666666667}}
joints:
  - {name: pin, parent: ground, child: bar, anchor: pin, chain: [R3], coordinates: [theta]}
coordinates:
  theta: {initial: 0}
forces:
  - {name: follower, type: point_force, body: bar, point: [1, 0, 0], frame: body, fy: 3}
)" + spring + R"(sensors:
  - {name: angle, type: coordinate, coordinate: theta}
  - {name: tip_x, type: position, body: bar, point: [1, 0, 0], component: x}
)" + analysis_text;
}

TEST(Loads, FollowerForceOnAPinnedBar) {
  const Result r = run_text(bar("", analysis(2.0)));
  const auto& t = r.column("t");
  double worst = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    worst = std::max(worst, std::fabs(r.column("angle")[k] - 2.25 * t[k] * t[k]));
    EXPECT_NEAR(r.column("tip_x")[k], std::cos(2.25 * t[k] * t[k]), 1e-6);
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_NEAR(r.column("angle").back(), 9.0, 1e-6);
}

TEST(Loads, FollowerForceAgainstATorsionalSpringSettlesAtFLOverK) {
  const Result r = run_text(bar("  - {name: spring, type: joint_spring_damper, coordinate: theta, stiffness: 30, damping: 8}\n",
                                analysis(12.0)));
  EXPECT_NEAR(r.column("angle").back(), 3.0 / 30.0, 1e-8);
}

// Torsional pendulum: J = 0.5, k = 8 (omega = 4, period pi / 2), theta0 = 0.3 from rest:
// theta = theta0 cos(omega t); with damping c = 0.4 (zeta = c / (2 sqrt(k J)) = 0.1):
// theta = theta0 exp(-zeta omega t) (cos(wd t) + zeta / sqrt(1 - zeta^2) sin(wd t)).
// Wound 10 rad (1.6 turns; issue 25) the same closed form holds: the spring counts whole turns
// (it wrapped q - rest to (-pi, pi] before, and snapped through at pi), and so does the sensor.
TEST(Loads, TorsionalPendulum) {
  for (double theta0 : {0.3, 10.0})
  for (double c : {0.0, 0.4}) {
    std::string text = wheel("  - {name: spring, type: joint_spring_damper, coordinate: theta, stiffness: 8, damping: " +
                                 std::to_string(c) + ", rest_deg: 0}\n",
                             "  - {name: angle, type: coordinate, coordinate: theta}\n"
                             "  - {name: torque, type: force_value, force: spring}\n", analysis(4.0));
    const std::string from = "theta: {initial: 0}";
    text.replace(text.find(from), from.size(), "theta: {initial: " + std::to_string(theta0) + "}");
    const Result r = run_text(text);
    const double omega = 4.0, zeta = c / (2 * std::sqrt(8.0 * 0.5)), wd = omega * std::sqrt(1 - zeta * zeta);
    const auto& t = r.column("t");
    double worst = 0, worst_torque = 0;
    for (size_t k = 0; k < t.size(); ++k) {
      const double exact = theta0 * std::exp(-zeta * omega * t[k]) *
                           (std::cos(wd * t[k]) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * t[k]));
      worst = std::max(worst, std::fabs(r.column("angle")[k] - exact));
      if (c == 0) worst_torque = std::max(worst_torque, std::fabs(r.column("torque")[k] + 8 * exact));
    }
    EXPECT_LT(worst, 1e-7 * theta0 / 0.3) << "damping " << c << ", theta0 " << theta0;
    EXPECT_LT(worst_torque, 8e-7 * theta0 / 0.3) << "theta0 " << theta0;
  }
}

// A block (mass 2, inertia 0.1) on six free coordinates, held by a bushing to ground at its
// centre of mass: under gravity from the unstressed pose it falls z = -(m g / k_z)(1 - cos(w t)),
// w = sqrt(k_z / m) = 20; an initial x offset 0.01 oscillates as 0.01 cos(sqrt(k_x / m) t). A
// torque of 1 N m about z against the rotational stiffness 10 settles (damped) at the exact
// angle psi with k sin(psi) = T (the bushing's angle is 2 sin(psi / 2), formulation/forces/bushing.cpp).
std::string block(const std::string& extra_force, const std::string& damping) {
  return R"(name: block
gravity: [0, 0, -9.81]
bodies:
  - {name: block, mass: 2.0, inertia: {xx: 0.1, yy: 0.1, zz: 0.1}}
joints:
  - {name: free, parent: ground, child: block, anchor: [0, 0, 0], chain: [T1, T2, T3, R1, R2, R3],
     coordinates: [x, y, z, rx, ry, rz]}
coordinates:
  x: {initial: 0.01}
  y: {initial: 0}
  z: {initial: 0}
  rx: {initial: 0}
  ry: {initial: 0}
  rz: {initial: 0}
forces:
  - {name: mount, type: bushing, body1: ground, point1: origin, body2: block, point2: com,
     stiffness: [100, 100, 800], rotational_stiffness: [10, 10, 10])" + damping + R"(}
)" + extra_force + R"(sensors:
  - {name: x, type: coordinate, coordinate: x}
  - {name: z, type: coordinate, coordinate: z}
  - {name: psi, type: coordinate, coordinate: rz}
analysis:
  - {type: assembly, hold: [x, y, z, rx, ry, rz]}
  - {type: dynamics, t_end: 10, output_step: 0.05, rtol: 1.0e-10, atol: 1.0e-12, formulation: index2-ggl}
)";
}

TEST(Loads, BushingTranslation) {
  const Result r = run_text(block("", ""));
  const auto& t = r.column("t");
  double worst_x = 0, worst_z = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    worst_x = std::max(worst_x, std::fabs(r.column("x")[k] - 0.01 * std::cos(std::sqrt(50.0) * t[k])));
    worst_z = std::max(worst_z, std::fabs(r.column("z")[k] + 2.0 * 9.81 / 800 * (1 - std::cos(20.0 * t[k]))));
  }
  EXPECT_LT(worst_x, 1e-7);
  EXPECT_LT(worst_z, 1e-7);
  for (double psi : r.column("psi")) EXPECT_NEAR(psi, 0.0, 1e-10);
}

TEST(Loads, BushingRotationUnderATorque) {
  const Result r = run_text(block("  - {name: twist, type: torque, body: block, axis: [0, 0, 1], torque: 1}\n",
                                  ", damping: [40, 40, 200], rotational_damping: [2, 2, 2]"));
  EXPECT_NEAR(r.column("psi").back(), std::asin(0.1), 1e-8);
  EXPECT_NEAR(r.column("z").back(), -2.0 * 9.81 / 800, 1e-8);
}

// The damped slider of test_scenes.h (fz = -K z - C vz from its sensors, K = 50, C = 2,
// omega = 5, zeta = 0.1, z0 = 0.2 from rest) against its closed form.
TEST(Loads, SliderPushedByAnExpressionOfItsState) {
  const Result r = run_text(test_scenes::damped_slider("atol: 1.0e-12, formulation: index2-ggl"));
  const double omega = 5, zeta = 0.1, wd = omega * std::sqrt(1 - zeta * zeta);
  const auto& t = r.column("t");
  double worst = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double exact = 0.2 * std::exp(-zeta * omega * t[k]) *
                         (std::cos(wd * t[k]) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * t[k]));
    worst = std::max(worst, std::fabs(r.column("z")[k] - exact));
  }
  EXPECT_LT(worst, 1e-7);
}

// Joint friction (formulation/forces/joint_friction.cpp), tau = -F tanh(w / w_s), spinning the
// wheel down from w0 = 10 rad/s with F = 1 N m, J = 0.5, w_s = 0.05 rad/s. Then J w' = -F tanh(w / w_s)
// has the closed form sinh(w / w_s) = sinh(w0 / w_s) exp(-F t / (J w_s)): w = w0 - (F / J) t
// while w >> w_s, at rest (not reversed) after t* = J w0 / F = 5 s, and the total angle is
// (J / F) (w0^2 / 2 + w_s^2 pi^2 / 12) (the integral of w coth(w / w_s) dw).
TEST(Loads, JointFrictionSpinsAWheelDownToRest) {
  const double w0 = 10, friction = 1, slip = 0.05, inertia = 0.5;
  for (const char* form : kFormulations) {
    SCOPED_TRACE(form);
    const Result r = run_text(
        wheel("  - {name: drag, type: joint_friction, coordinate: theta, friction: 1, slip_rate: 0.05}\n",
              "  - {name: angle, type: coordinate, coordinate: theta}\n"
              "  - {name: rate, type: coordinate_rate, coordinate: theta}\n"
              "  - {name: torque, type: force_value, force: drag}\n",
              std::string("analysis:\n  - {type: assembly, hold: [theta]}\n"
                          "  - {type: dynamics, t_end: 6, output_step: 0.05, rtol: 1.0e-10, atol: 1.0e-12, formulation: ") +
                  form + ", initial_velocities: {theta: 10}}\n"));
    const auto& t = r.column("t");
    const auto& angle = r.column("angle");
    const auto& rate = r.column("rate");
    const auto& torque = r.column("torque");
    ASSERT_GT(t.size(), 100u);
    double worst_rate = 0, worst_angle = 0, lowest = 0;
    for (size_t k = 0; k < t.size(); ++k) {
      const double log_y = std::log(std::sinh(w0 / slip)) - friction * t[k] / (inertia * slip);
      const double exact = slip * std::asinh(std::exp(log_y));
      worst_rate = std::max(worst_rate, std::fabs(rate[k] - exact));
      lowest = std::min(lowest, rate[k]);
      if (k > 0) {
        EXPECT_LE(rate[k], rate[k - 1] + 1e-9) << t[k];  // never speeds up
      }
      EXPECT_NEAR(torque[k], -friction * std::tanh(rate[k] / slip), 1e-12) << t[k];
      if (t[k] <= 4.5)  // w >= 1 rad/s = 20 w_s: Coulomb's constant deceleration
        worst_angle = std::max(worst_angle, std::fabs(angle[k] - (w0 * t[k] - friction * t[k] * t[k] / (2 * inertia))));
    }
    const double total = inertia / friction * (w0 * w0 / 2 + slip * slip * M_PI * M_PI / 12);
    EXPECT_LT(worst_rate, 1e-6);
    EXPECT_LT(worst_angle, 1e-6);
    EXPECT_GT(lowest, -1e-9);  // comes to rest, does not reverse
    EXPECT_NEAR(angle.back(), total, 1e-6);
    EXPECT_LT(std::fabs(rate.back()), 1e-9);
    char figures[96];
    std::snprintf(figures, sizeof figures, "%.2e rad/s, %.2e rad, %.2e rad", worst_rate, worst_angle,
                  std::fabs(angle.back() - total));
    RecordProperty(std::string("rate_angle_total_errors_") + form, figures);
  }
}

// ---- Loader messages -------------------------------------------------------------------------

std::string errors_of(const std::string& text) {
  try {
    const Scene s = load_scene_text(text, "loads_test.yaml");
    build_system(s.model);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

TEST(Loads, SensorNamedLikeAConstantIsRefused) {
  const std::string text = wheel("", "  - {name: pi, type: coordinate, coordinate: theta}\n", analysis(1));
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find("name: pi")), '\n'));
  const std::string e = errors_of(text);
  EXPECT_NE(e.find("loads_test.yaml:" + std::to_string(line) + ": field 'name': 'pi' is reserved in expressions"),
            std::string::npos)
      << e;
}

TEST(Loads, PointMessagesSayWhatIsAccepted) {
  std::string e = errors_of(wheel("  - {name: push, type: point_force, body: wheel, point: {x: 1}, fx: 1}\n", "", analysis(1)));
  EXPECT_NE(e.find("field 'point': expected a point name or [x, y, z], got a mapping"), std::string::npos) << e;
  e = errors_of(wheel("  - {name: push, type: point_force, body: wheel, point: rim, fx: 1}\n", "", analysis(1)));
  EXPECT_NE(e.find("body 'wheel' has no point 'rim' (its points: origin, com); expected a point name or [x, y, z]"),
            std::string::npos)
      << e;
  e = errors_of(wheel("  - {name: pull, type: spring_damper, body1: ground, point1: post, body2: wheel, stiffness: 1}\n", "",
                      analysis(1)));
  EXPECT_NE(e.find("ground has no point 'post' (its points: origin; name more under ground: {points: ...}); expected a "
                   "point name or [x, y, z]"),
            std::string::npos)
      << e;
}

TEST(Loads, LoadExpressionErrorsNameTheField) {
  std::string e = errors_of(wheel("  - {name: motor, type: torque, body: wheel, axis: [0, 0, 1], torque: \"T0 * speed\", "
                                  "parameters: {T0: 1}}\n",
                                  "", analysis(1)));
  EXPECT_NE(e.find("field 'torque': force 'motor': unknown name 'speed'"), std::string::npos) << e;
  e = errors_of(wheel("  - {name: motor, type: torque, body: wheel, axis: [0, 0, 1], torque: 1, parameters: {t: 1}}\n", "",
                      analysis(1)));
  EXPECT_NE(e.find("field 'parameters.t': 't' is reserved in expressions"), std::string::npos) << e;
  e = errors_of(wheel("  - {name: spring, type: joint_spring_damper, coordinate: phi, stiffness: 1}\n", "", analysis(1)));
  EXPECT_NE(e.find("no joint coordinate named 'phi'"), std::string::npos) << e;
}

// Hostile joint friction fields: each message names the file, the line and the field.
TEST(Loads, JointFrictionFieldsAreChecked) {
  auto message = [](const std::string& force) {
    const std::string text = wheel(force, "", analysis(1));
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find("name: drag")), '\n'));
    return std::make_pair(errors_of(text), "loads_test.yaml:" + std::to_string(line) + ": field ");
  };
  auto [e, at] = message("  - {name: drag, type: joint_friction, coordinate: theta, friction: -2, slip_rate: 0.1}\n");
  EXPECT_NE(e.find(at + "'friction': must not be negative, got -2"), std::string::npos) << e;
  std::tie(e, at) = message("  - {name: drag, type: joint_friction, coordinate: theta, friction: 2, slip_rate: 0}\n");
  EXPECT_NE(e.find(at + "'slip_rate': must be positive, got 0"), std::string::npos) << e;
  std::tie(e, at) = message("  - {name: drag, type: joint_friction, friction: 2, slip_rate: 0.1}\n");
  EXPECT_NE(e.find(at + "'coordinate': "), std::string::npos) << e;
  std::tie(e, at) = message("  - {name: drag, type: joint_friction, coordinate: theta, slip_rate: 0.1}\n");
  EXPECT_NE(e.find(at + "'friction': "), std::string::npos) << e;
  std::tie(e, at) = message("  - {name: drag, type: joint_friction, coordinate: phi, friction: 2, slip_rate: 0.1}\n");
  EXPECT_NE(e.find(at + "'coordinate': force 'drag': no joint coordinate named 'phi'"), std::string::npos) << e;
  std::tie(e, at) = message("  - {name: drag, type: joint_friction, coordinate: theta, friction: 2, slip_rate: 0.1, stiffness: 3}\n");
  EXPECT_NE(e.find(at + "'stiffness': does not apply to a joint_friction force (its fields: name, type, coordinate, "
                        "friction, slip_rate)"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace mbdae
