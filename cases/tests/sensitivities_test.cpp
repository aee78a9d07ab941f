// Sensitivities (RunOptions::sensitivities, docs/sensitivities.md) against closed forms, through
// the public API and the executable: a damped oscillator's position, velocity and acceleration
// against its stiffness, damping, mass and initial position for every formulation; the IFToMM
// A01 pendulum's position and acceleration against its length (Jacobi's exact solution); a
// kinematic slider-crank's piston position and rate against its crank and rod lengths; bad requests refused before any run, the files
// and summary entries of `mbdae run --sensitivity`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/mbdae.h"
#include "cases/tests/run_command.h"
#include "cases/tests/test_scenes.h"
#include "core/errors.h"
#include "verification/iftomm/pendulum_exact.h"

namespace mbdae {
namespace {

using test_support::read_file;
using test_support::run_command;

// The damped slider of test_scenes.h (mass m on a rail, pushed by fz = -K z - C vz, released at z0).
std::string oscillator(const std::string& formulation) { return test_scenes::damped_slider("formulation: " + formulation); }

// The oscillator's closed form: z(t) and vz(t) for stiffness K, damping C, mass m, start z0.
struct Oscillator {
  double K = 50, C = 2, m = 2, z0 = 0.2;
  void at(double t, double& z, double& v) const {
    const double w = std::sqrt(K / m), zeta = C / (2 * std::sqrt(K * m)), wd = w * std::sqrt(1 - zeta * zeta);
    const double e = std::exp(-zeta * w * t);
    z = z0 * e * (std::cos(wd * t) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * t));
    v = -z0 * w / std::sqrt(1 - zeta * zeta) * e * std::sin(wd * t);
  }
};

// d(sensor)/d(parameter) of a closed form by central differences (step 1e-6 relative: exact to
// about 1e-10 of the derivative).
double closed_form_derivative(const std::function<double(double)>& f, double p) {
  const double h = 1e-6 * std::fabs(p);
  return (f(p + h) - f(p - h)) / (2 * h);
}

// The largest |computed - reference| of a column over the samples, relative to the reference's
// largest magnitude.
double relative_error(const Result& r, const std::string& column, const std::function<double(double)>& reference) {
  const int k = static_cast<int>(std::find(r.sensitivity_columns.begin(), r.sensitivity_columns.end(), column) -
                                 r.sensitivity_columns.begin());
  EXPECT_LT(k, static_cast<int>(r.sensitivity_columns.size())) << column;
  if (k >= static_cast<int>(r.sensitivity_columns.size())) return 1e300;
  double worst = 0, scale = 0;
  const auto& t = r.sensitivities[0];
  for (size_t i = 0; i < t.size(); ++i) {
    const double ref = reference(t[i]);
    worst = std::max(worst, std::fabs(r.sensitivities[k][i] - ref));
    scale = std::max(scale, std::fabs(ref));
  }
  return worst / scale;
}

TEST(Sensitivities, DampedOscillatorMatchesItsClosedFormInEveryFormulation) {
  const char* paths[] = {"forces.push.parameters.K", "forces.push.parameters.C", "bodies.slider.mass",
                         "coordinates.s.initial"};
  for (const char* form : {"index3", "index2-ggl", "index1", "index1-no-handover", "penalty"}) {
    SCOPED_TRACE(form);
    RunOptions opt;
    opt.sensitivities.assign(std::begin(paths), std::end(paths));
    std::string text = oscillator(form);
    const std::string vz = "  - {name: vz, type: velocity, body: slider, component: z}\n";
    text.replace(text.find(vz), vz.size(), vz + "  - {name: az, type: acceleration, body: slider, component: z}\n");
    const Result r = run(load_scene_text(text, "oscillator.yaml"), opt);
    ASSERT_TRUE(r.ok()) << r.message;
    ASSERT_EQ(r.sensitivities[0].size(), r.rows());
    EXPECT_EQ(r.summary["sensitivities"]["status"], "ok");
    // The scene's index3 runs as index2-ggl with sensitivities (or below rtol 1e-6), index1 below
    // rtol 1e-9 (the scene's rtol is 1e-10), and each says so; index1-no-handover stays index1.
    const auto& step = r.summary["steps"].back();
    const bool handed = std::string(form) == "index3" || std::string(form) == "index1";
    EXPECT_EQ(step["formulation"], handed ? "index2-ggl" : form);
    EXPECT_EQ(step.contains("formulation_with_sensitivities") || step.contains("formulation_handover"), handed);
    for (int which = 0; which < 4; ++which) {
      for (int sensor = 0; sensor < 3; ++sensor) {
        auto reference = [&](double t) {
          Oscillator o;
          double* p[] = {&o.K, &o.C, &o.m, &o.z0};
          return closed_form_derivative([&](double value) {
            Oscillator x = o;
            double* q[] = {&x.K, &x.C, &x.m, &x.z0};
            *q[which] = value;
            double z, v;
            x.at(t, z, v);
            return sensor == 0 ? z : sensor == 1 ? v : (-x.K * z - x.C * v) / x.m;
          }, *p[which]);
        };
        const char* names[] = {"z", "vz", "az"};
        const std::string column = std::string("d(") + names[sensor] + ")/d(" + paths[which] + ")";
        // Measured: 2e-9 to 3e-7 of the largest sensitivity (penalty: its constraint bias).
        EXPECT_LT(relative_error(r, column, reference), 1e-6) << column;
      }
    }
  }
}

// A01 (verification/iftomm/scenes/A01_simple_pendulum.yaml) over 10 s with the bob's position
// sensed at the centre of mass, so that its length is the one number bodies.link.com.0.
TEST(Sensitivities, PendulumBobAgainstItsLengthMatchesJacobisSolution) {
  const std::string text = R"(name: A01
gravity: [0, -9.81, 0]
bodies:
  - {name: link, mass: 1.0, com: [1, 0, 0], inertia: {xx: 0, yy: 0, zz: 0}}
joints:
  - {name: pivot, parent: ground, child: link, anchor: [0, 0, 0], chain: [R3], coordinates: [phi]}
coordinates:
  phi: {initial: 0}
sensors:
  - {name: x, type: position, body: link, point: com, component: x}
  - {name: y, type: position, body: link, point: com, component: y}
  - {name: ax, type: acceleration, body: link, point: com, component: x}
  - {name: ay, type: acceleration, body: link, point: com, component: y}
analysis:
  - {type: dynamics, t_end: 10, output_step: 0.05, rtol: 1.0e-10}
)";
  RunOptions opt;
  opt.sensitivities = {"bodies.link.com.0"};
  const Result r = run(load_scene_text(text, "a01.yaml"), opt);
  ASSERT_TRUE(r.ok()) << r.message;
  const char* names[] = {"x", "y", "ax", "ay"};
  for (int sensor = 0; sensor < 4; ++sensor) {
    // The accelerations from the energy (phi'^2 = 2 g / L cos phi, phi'' = -g / L sin phi):
    // x'' = -3 g sin phi cos phi, y'' = g (2 cos^2 phi - sin^2 phi), L only through phi(t).
    auto reference = [&](double t) {
      return closed_form_derivative([&](double length) {
        PendulumExact p;
        p.length = length;
        p.w0 = std::sqrt(9.81 / length);
        const double phi = p.phi(t), c = std::cos(phi), s = std::sin(phi);
        const double values[] = {p.x(t), p.y(t), -3 * 9.81 * s * c, 9.81 * (2 * c * c - s * s)};
        return values[sensor];
      }, 1.0);
    };
    const std::string column = std::string("d(") + names[sensor] + ")/d(bodies.link.com.0)";
    EXPECT_LT(relative_error(r, column, reference), 1e-6) << column;
  }
}

// A kinematic run (every degree of freedom driven: the implicit function theorem at each sample,
// formulation/kinematic_sensitivities.h): the slider-crank of verification/engine, its piston's
// position and rate against the crank radius r and the rod length l, two hardpoint coordinates
// that its joint and its cut hold, in closed form: x = r cos(wt) + sqrt(l^2 - r^2 sin^2(wt)).
TEST(Sensitivities, SliderCrankPistonAgainstCrankAndRodInClosedForm) {
  const Scene s = load_scene(std::string(MBDAE_SOURCE_DIR) + "/verification/engine/scenes/slider_crank.yaml");
  const char* paths[] = {"bodies.crank.points.pin.0", "bodies.rod.points.end.0"};
  RunOptions opt;
  opt.sensitivities.assign(std::begin(paths), std::end(paths));
  const Result r = run(s, opt);
  ASSERT_TRUE(r.ok()) << r.message;
  const std::string method = r.summary["steps"].back().value("sensitivity_method", "");
  EXPECT_NE(method.find("implicit function theorem"), std::string::npos) << method;
  const double w = 2 * 3.14159265358979323846;
  for (int which = 0; which < 2; ++which)
    for (int rate = 0; rate < 2; ++rate) {
      auto reference = [&](double t) {
        return closed_form_derivative([&](double value) {
          const double rr = which == 0 ? value : 0.1, l = which == 1 ? value : 0.35;
          const double c = std::cos(w * t), sn = std::sin(w * t), root = std::sqrt(l * l - rr * rr * sn * sn);
          return rate == 0 ? rr * c + root : -rr * w * sn - rr * rr * w * sn * c / root;
        }, which == 0 ? 0.1 : 0.35);
      };
      const std::string column = std::string("d(") + (rate == 0 ? "x" : "x_rate") + ")/d(" + paths[which] + ")";
      EXPECT_LT(relative_error(r, column, reference), 1e-6) << column;
    }
}

TEST(Sensitivities, BadRequestsAreRefusedBeforeTheRun) {
  const Scene scene = load_scene_text(oscillator("index3"), "oscillator.yaml");
  const struct {
    const char* path;
    const char* message;
  } cases[] = {
      {"forces.push.parameters.k", "no such parameter (`mbdae params SCENE` lists them); did you mean 'forces.push.parameters.K'?"},
      {"gravity", "not a single number; name one element: gravity.0"},
      {"analysis.dynamics.rtol", "a setting of the analysis, not a parameter of the model"},
      {"forces.push.fz", "not a single number"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.path);
    RunOptions opt;
    opt.sensitivities = {c.path};
    try {
      run(scene, opt);
      ADD_FAILURE() << "no error";
    } catch (const ModelError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
  RunOptions twice;
  twice.sensitivities = {"bodies.slider.mass", "bodies.slider.mass"};
  EXPECT_THROW(run(scene, twice), ModelError);
}

// A pendulum on a cart driven at 0.2 m/s that stops dead at t = 2.5 s (a drive's kink: the run's
// velocities jump at the restart) and a 4 N push stepping on at 0.7 s. Its sensitivities to the
// link's mass, its initial angle and the push's step time against central differences of rtol
// 1e-10 runs, over the whole run: the restart maps the state it started from, and the twins
// with it (before 2026-11-28 they mapped the restarted state, 4e-2 off after the kink).
const char* kCartPendulum = R"(name: cart_pendulum
gravity: [0, -9.81, 0]
bodies:
  - {name: cart, mass: 2.0, inertia: {xx: 0.01, yy: 0.01, zz: 0.01}}
  - {name: link, mass: 1.0, com: [0.5, 0, 0], inertia: {xx: 0.001, yy: 0.09, zz: 0.09}, points: {P1: [1, 0, 0]}}
joints:
  - {name: slide, parent: ground, child: cart, anchor: [0, 0, 0], chain: [T1], coordinates: [x]}
  - {name: pivot, parent: cart, child: link, anchor: [0, 0, 0], chain: [R3], coordinates: [phi]}
coordinates:
  x: {mode: driven, drive: {type: piecewise_linear, points: [[0, 0], [2.5, 0.5]]}}
  phi: {initial: -1.2}
forces:
  - {name: push, type: point_force, body: link, point: P1, fy: {type: step, time: 0.7, before: 0, after: 4.0}}
sensors:
  - {name: px, type: position, body: link, point: P1, component: x}
  - {name: w, type: coordinate_rate, coordinate: phi}
analysis:
  - {type: dynamics, t_end: 3.0, output_step: 0.01, rtol: 1.0e-8, atol: 1.0e-10}
)";

std::string exact_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

size_t sensitivity_index(const Result& r, const std::string& column) {
  const auto it = std::find(r.sensitivity_columns.begin(), r.sensitivity_columns.end(), column);
  EXPECT_NE(it, r.sensitivity_columns.end()) << column;
  return it == r.sensitivity_columns.end() ? 0 : static_cast<size_t>(it - r.sensitivity_columns.begin());
}

TEST(Sensitivities, CartPendulumThroughADrivesKinkAndAStepsTime) {
  const Scene scene = load_scene_text(kCartPendulum, "cart.yaml");
  const std::vector<std::pair<std::string, double>> params = {
      {"bodies.link.mass", 1.0}, {"coordinates.phi.initial", -1.2}, {"forces.push.fy.time", 0.7}};
  RunOptions opt;
  for (const auto& p : params) opt.sensitivities.push_back(p.first);
  const Result r = run(scene, opt);
  ASSERT_TRUE(r.ok()) << r.message;
  RunOptions tight;
  tight.rtol = 1e-10;
  for (const auto& [path, value] : params) {
    const double h = 1e-5 * std::max(1.0, std::fabs(value));
    const Result plus = run(with_parameters(scene, {{path, exact_text(value + h)}}), tight);
    const Result minus = run(with_parameters(scene, {{path, exact_text(value - h)}}), tight);
    for (const char* sensor : {"px", "w"}) {
      const auto& a = plus.column(sensor);
      const auto& b = minus.column(sensor);
      const std::string column = std::string("d(") + sensor + ")/d(" + path + ")";
      double before = 0, after = 0, scale = 0;
      for (size_t i = 0; i < a.size(); ++i) {
        const double t = plus.column("t")[i], fd = (a[i] - b[i]) / (2 * h);
        if (std::fabs(t - 0.7) < 1e-3) continue;  // the finite differences' own step straddles the push
        double& worst = t < 2.5 ? before : after;
        worst = std::max(worst, std::fabs(r.sensitivities[sensitivity_index(r, column)][i] - fd));
        scale = std::max(scale, std::fabs(fd));
      }
      std::printf("measured: cart pendulum %s: %.2e before the kink, %.2e after (of %.3g)\n", column.c_str(),
                  before / scale, after / scale, scale);
      EXPECT_LT(before, 1e-4 * scale) << column;
      EXPECT_LT(after, 1e-4 * scale) << column;
    }
  }
}

// Moved breakpoints the jump does not cover are refused before the run: two steps closer than
// twice the twins' step (their order could swap), a step beside a force expression of t (the
// twins hold their inputs over their step), a drive's knot.
TEST(Sensitivities, BreakpointsTheJumpDoesNotCoverAreRefused) {
  std::string two = kCartPendulum;
  const std::string push = "  - {name: push,";
  two.insert(two.find(push), "  - {name: push2, type: point_force, body: link, point: P1, fx: {type: step, time: 0.70001, "
                             "before: 0, after: 1.0}}\n");
  std::string expr = kCartPendulum;
  expr.insert(expr.find(push), "  - {name: wind, type: point_force, body: link, point: P1, fx: \"2 * sin(20 * t)\"}\n");
  const struct {
    std::string text, path, message;
  } cases[] = {{two, "forces.push.fy.time", "to within half its distance of the breakpoint at t = 0.70001"},
               {expr, "forces.push.fy.time", "force 'wind' has an expression of t"},
               {kCartPendulum, "coordinates.x.drive.points.1.0", "a driven coordinate's breakpoint"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.path);
    RunOptions opt;
    opt.sensitivities = {c.path};
    try {
      run(load_scene_text(c.text, "cart.yaml"), opt);
      ADD_FAILURE() << "no error";
    } catch (const ModelError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
}

// Sensitivities that stop while the run goes on leave fewer sensitivity rows than results
// rows: the run is not `ok` but sensitivities_failed (exit code 3), its results whole. Here a
// sensor that is not finite for the twin above the start (sqrt(0.2 - z) at z = 0.2 + d).
TEST(Sensitivities, StoppedSensitivitiesAreNotAWholeRun) {
  std::string text = oscillator("index2-ggl");
  const std::string analysis = "analysis:\n";
  text.replace(text.find(analysis), analysis.size(),
               "  - {name: gap, type: expression, expression: \"sqrt(0.2 - z)\"}\n" + analysis);
  RunOptions opt;
  opt.sensitivities = {"coordinates.s.initial"};
  opt.report_failures = false;
  const Result r = run(load_scene_text(text, "oscillator.yaml"), opt);
  EXPECT_EQ(r.status, "sensitivities_failed") << r.message;
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.summary["status"], "sensitivities_failed");
  EXPECT_EQ(r.summary["sensitivities"]["status"], "not_finite");
  EXPECT_EQ(r.rows(), 81u);
  EXPECT_LT(r.sensitivities[0].size(), r.rows());
  EXPECT_EQ(r.summary["sensitivities"]["rows"], r.sensitivities[0].size());
}

class SensitivitiesCli : public test_support::RunFolderTest {
 protected:
  SensitivitiesCli() : RunFolderTest("mbdae_sens_") {}
};

TEST_F(SensitivitiesCli, WritesTheCsvAndListsTheParametersInTheSummary) {
  {
    std::ofstream(dir / "s.yaml") << oscillator("index3");
  }
  const std::string base = std::string(MBDAE_EXE) + " run " + (dir / "s.yaml").string() + " --out " + out.string() + " --quiet";
  auto r = run_command(base + " --sensitivity bodies.slider.mass --sensitivity forces.push.parameters.K");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string csv = read_file(out / "sensitivities.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "t,d(z)/d(bodies.slider.mass),d(z)/d(forces.push.parameters.K),d(vz)/d(bodies.slider.mass),"
            "d(vz)/d(forces.push.parameters.K)");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 82);  // header and 81 samples, as results.csv
  const auto summary = nlohmann::json::parse(read_file(out / "summary.json"));
  const auto& s = summary["sensitivities"];
  EXPECT_EQ(s["status"], "ok");
  EXPECT_EQ(s["parameters"][0]["path"], "bodies.slider.mass");
  EXPECT_EQ(s["parameters"][0]["unit"], "kg");
  EXPECT_EQ(s["parameters"][0]["value"], 2.0);
  EXPECT_EQ(s["columns"][1]["unit"], "m/kg");
  EXPECT_EQ(s["columns"][3]["unit"], "(m/s)/kg");
  EXPECT_FALSE(std::filesystem::exists(out / "sensitivities_normalized.csv"));
  // The normalized form on request: (p / max|y|) dy/dp, p = 2 kg.
  r = run_command(base + " --sensitivity bodies.slider.mass --normalized-sensitivities");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string norm = read_file(out / "sensitivities_normalized.csv");
  EXPECT_EQ(norm.substr(0, norm.find('\n')), "t,d(z)/d(bodies.slider.mass)*p/max|z|,d(vz)/d(bodies.slider.mass)*p/max|vz|");
  EXPECT_EQ(std::count(norm.begin(), norm.end(), '\n'), 82);
  // A run without sensitivities into the same folder leaves no stale file.
  r = run_command(base);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out / "sensitivities.csv"));
  EXPECT_FALSE(std::filesystem::exists(out / "sensitivities_normalized.csv"));
  // Bad requests: usage errors (exit 1) before the folder is touched.
  for (const std::string& bad : {std::string(" --sensitivity"), std::string(" --sensitivity bodies.slider.mas"),
                                 std::string(" --sensitivity analysis.dynamics.t_end"),
                                 std::string(" --sensitivity bodies.slider.mass --formulation index3"),
                                 std::string(" --normalized-sensitivities")}) {
    r = run_command(base + bad);
    EXPECT_EQ(r.code, 1) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("sensitivit"), std::string::npos) << r.output;
  }
}

// A scene of static steps only has no samples: sensitivities.csv and sensitivities_normalized.csv
// are header lines with every column (no sensor is dropped for a scale it cannot have), and the
// step's sensitivities are in summary.json.
TEST_F(SensitivitiesCli, StaticStepsOnlyWriteEveryColumnAndNoRows) {
  std::string text = oscillator("index3");
  text.erase(text.find("  - {type: dynamics"));
  {
    std::ofstream(dir / "s.yaml") << text;
  }
  const auto r = run_command(std::string(MBDAE_EXE) + " run " + (dir / "s.yaml").string() + " --out " + out.string() +
                             " --quiet --sensitivity bodies.slider.mass --normalized-sensitivities");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(read_file(out / "sensitivities.csv"), "t,d(z)/d(bodies.slider.mass),d(vz)/d(bodies.slider.mass)\n");
  EXPECT_EQ(read_file(out / "sensitivities_normalized.csv"),
            "t,d(z)/d(bodies.slider.mass)*p/max|z|,d(vz)/d(bodies.slider.mass)*p/max|vz|\n");
  const auto summary = nlohmann::json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(summary["sensitivities"]["rows"], 0);
  EXPECT_TRUE(summary["steps"][0]["sensitivities"].contains("z")) << summary["steps"][0].dump();
}

}  // namespace
}  // namespace mbdae
