// The public API (cases/mbdae.h): parameter overrides equal the same edit made in the file
// (field by field of the Scene, and by running it), unknown paths and bad values are reported
// like the file's own errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>

#include "cases/mbdae.h"

namespace mbdae {
namespace {

namespace fs = std::filesystem;

const std::string kDir = std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/";

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `text` with its first `from` (after `after`, if given) replaced by `to`; fails if absent.
std::string edit(std::string text, const std::string& from, const std::string& to, const std::string& after = "") {
  const size_t start = after.empty() ? 0 : text.find(after);
  EXPECT_NE(start, std::string::npos) << after;
  const size_t k = text.find(from, start);
  EXPECT_NE(k, std::string::npos) << from;
  if (k != std::string::npos) text.replace(k, from.size(), to);
  return text;
}

// A copy of the suspension's scene and model files in a fresh folder, optionally edited.
std::string copy_case(const std::string& folder, const std::string& scene, const std::string& scene_text,
                      const std::string& model_text) {
  const fs::path dir = fs::path(::testing::TempDir()) / folder;
  fs::create_directories(dir);
  std::ofstream(dir / scene) << scene_text;
  std::ofstream(dir / "model.yaml") << model_text;
  return (dir / scene).string();
}

std::string base(const std::string& file) { return fs::path(file).filename().string(); }

void expect_same(const TimeFunction& a, const TimeFunction& b, const std::string& what) {
  EXPECT_EQ(a.describe(), b.describe()) << what;
  for (double t : {0.0, 0.1, 0.2, 0.5, 1.0, 1.7})
    EXPECT_EQ(a.value(t), b.value(t)) << what << " at t = " << t;
}
void expect_same(const SourceLocation& a, const SourceLocation& b, const std::string& what) {
  EXPECT_EQ(base(a.file), base(b.file)) << what;
  EXPECT_EQ(a.line, b.line) << what;
}

// Every field of two scenes (file names compared without their folder).
void expect_same_scene(const Scene& a, const Scene& b) {
  const Model &ma = a.model, &mb = b.model;
  EXPECT_EQ(ma.name, mb.name);
  EXPECT_EQ(ma.gravity, mb.gravity);
  ASSERT_EQ(ma.bodies.size(), mb.bodies.size());
  for (size_t k = 0; k < ma.bodies.size(); ++k) {
    const auto &x = ma.bodies[k], &y = mb.bodies[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.mass, y.mass) << x.name;
    EXPECT_EQ(x.com, y.com) << x.name;
    EXPECT_EQ(x.inertia, y.inertia) << x.name;
    EXPECT_EQ(x.points, y.points) << x.name;
    expect_same(x.where, y.where, x.name);
  }
  ASSERT_EQ(ma.joints.size(), mb.joints.size());
  for (size_t k = 0; k < ma.joints.size(); ++k) {
    const auto &x = ma.joints[k], &y = mb.joints[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.parent, y.parent);
    EXPECT_EQ(x.child, y.child);
    EXPECT_EQ(x.anchor_point, y.anchor_point);
    EXPECT_EQ(x.anchor, y.anchor);
    ASSERT_EQ(x.chain.size(), y.chain.size());
    for (size_t e = 0; e < x.chain.size(); ++e) {
      EXPECT_EQ(x.chain[e].rotation, y.chain[e].rotation);
      EXPECT_EQ(x.chain[e].axis, y.chain[e].axis);
      EXPECT_EQ(x.chain[e].coordinate, y.chain[e].coordinate);
    }
    expect_same(x.where, y.where, x.name);
  }
  ASSERT_EQ(ma.cuts.size(), mb.cuts.size());
  for (size_t k = 0; k < ma.cuts.size(); ++k) {
    const auto &x = ma.cuts[k], &y = mb.cuts[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(std::tie(x.body1, x.point1, x.body2, x.point2), std::tie(y.body1, y.point1, y.body2, y.point2));
    EXPECT_EQ(x.axis1, y.axis1);
    EXPECT_EQ(x.axis2, y.axis2);
    EXPECT_EQ(x.distance, y.distance);
    expect_same(x.where, y.where, x.name);
  }
  ASSERT_EQ(ma.forces.size(), mb.forces.size());
  for (size_t k = 0; k < ma.forces.size(); ++k) {
    const auto &x = ma.forces[k], &y = mb.forces[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(std::tie(x.body1, x.point1, x.body2, x.point2), std::tie(y.body1, y.point1, y.body2, y.point2));
    EXPECT_EQ(std::tie(x.stiffness, x.damping, x.free_length, x.radius), std::tie(y.stiffness, y.damping, y.free_length, y.radius)) << x.name;
    EXPECT_EQ(x.axis, y.axis);
    for (auto [f, g] : {std::make_pair(&x.fx, &y.fx), {&x.fy, &y.fy}, {&x.fz, &y.fz}, {&x.ground, &y.ground}})
      expect_same(*f, *g, x.name);
    EXPECT_EQ(x.law, y.law);
    EXPECT_EQ(x.parameters, y.parameters);
    expect_same(x.where, y.where, x.name);
  }
  ASSERT_EQ(ma.sensors.size(), mb.sensors.size());
  for (size_t k = 0; k < ma.sensors.size(); ++k) {
    const auto &x = ma.sensors[k], &y = mb.sensors[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(std::tie(x.body, x.point, x.target, x.component, x.expression),
              std::tie(y.body, y.point, y.target, y.component, y.expression));
    EXPECT_EQ(x.axis, y.axis);
    expect_same(x.where, y.where, x.name);
  }
  ASSERT_EQ(ma.coordinates.size(), mb.coordinates.size());
  for (auto ia = ma.coordinates.begin(), ib = mb.coordinates.begin(); ia != ma.coordinates.end(); ++ia, ++ib) {
    EXPECT_EQ(ia->first, ib->first);
    EXPECT_EQ(ia->second.initial, ib->second.initial) << ia->first;
    EXPECT_EQ(ia->second.mode, ib->second.mode) << ia->first;
    expect_same(ia->second.drive, ib->second.drive, ia->first);
    expect_same(ia->second.where, ib->second.where, ia->first);
  }
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t k = 0; k < a.steps.size(); ++k) {
    const AnalysisStep &x = a.steps[k], &y = b.steps[k];
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(std::tie(x.hold, x.release, x.unknowns, x.quiet_sensors, x.formulation, x.mode_check, x.newton_solve),
              std::tie(y.hold, y.release, y.unknowns, y.quiet_sensors, y.formulation, y.mode_check, y.newton_solve));
    EXPECT_EQ(std::tie(x.t0, x.t_end, x.output_step, x.rtol, x.atol, x.max_step, x.constraint_scale),
              std::tie(y.t0, y.t_end, y.output_step, y.rtol, y.atol, y.max_step, y.constraint_scale)) << k;
    EXPECT_EQ(std::tie(x.newton_convergence, x.output_projection, x.baumgarte_alpha, x.baumgarte_beta, x.penalty),
              std::tie(y.newton_convergence, y.output_projection, y.baumgarte_alpha, y.baumgarte_beta, y.penalty));
    EXPECT_EQ(std::tie(x.quiet_until, x.mode_check_deg, x.initial_velocities),
              std::tie(y.quiet_until, y.mode_check_deg, y.initial_velocities));
    expect_same(x.where, y.where, "step " + std::to_string(k));
  }
  EXPECT_EQ(a.columns, b.columns);
  EXPECT_EQ(a.redundant_constraints, b.redundant_constraints);
}

// Two runs of the same scene give the same numbers, bit for bit.
void expect_same_run(const Scene& a, const Scene& b) {
  RunOptions opt;
  const Result ra = run(a, opt), rb = run(b, opt);
  ASSERT_TRUE(ra.ok()) << ra.message;
  ASSERT_TRUE(rb.ok()) << rb.message;
  EXPECT_EQ(ra.columns, rb.columns);
  ASSERT_EQ(ra.data.size(), rb.data.size());
  for (size_t c = 0; c < ra.data.size(); ++c) EXPECT_TRUE(ra.data[c] == rb.data[c]) << ra.columns[c];
  EXPECT_TRUE(ra.q == rb.q);
  EXPECT_EQ(ra.summary["steps"].dump().size() > 0, true);
  EXPECT_EQ(ra.summary["equilibrium_coordinates"], rb.summary["equilibrium_coordinates"]);
}

TEST(SetParameter, SceneFileValueEqualsEditedFile) {
  const std::string path = kDir + "dynamics_step.yaml";
  Scene s = load_scene(path);
  set_parameter(s, "forces.tyre.stiffness", "3.0e5");
  const Scene edited = load_scene_text(edit(read(path), "stiffness: 2.0e5", "stiffness: 3.0e5"), path);
  ASSERT_EQ(edited.model.forces.back().stiffness, 3.0e5);  // the edit took
  expect_same_scene(s, edited);
  expect_same_run(s, edited);
}

TEST(SetParameter, AnalysisStepByTypeAndByIndex) {
  const std::string path = kDir + "dynamics_step.yaml";
  const Scene s = with_parameters(load_scene(path), {{"analysis.dynamics.rtol", "1.0e-7"}, {"analysis.2.t_end", "0.6"},
                                                     {"analysis.0.hold", "[q4, q15]"}});
  std::string text = edit(read(path), "rtol: 1.0e-8", "rtol: 1.0e-7");
  text = edit(text, "t_end: 1.5", "t_end: 0.6");
  text = edit(text, "{type: assembly, hold: [q4]}", "{type: assembly, hold: [q4, q15]}");
  const Scene edited = load_scene_text(text, path);
  ASSERT_EQ(edited.steps[2].rtol, 1.0e-7);
  expect_same_scene(s, edited);
  expect_same_run(s, edited);
}

// newton_solve: reduced (core/reduced_linear_solver.h) runs Dynamics I to the same trajectory as
// the full Newton solve, up to the rounding the different linear solves leave (measured 3e-10 m
// at the scene's rtol 1e-8: docs/performance.md); summary.json names the solve used, and a
// formulation without the kinematic rows (index2-ggl) keeps the full one.
TEST(SetParameter, ReducedNewtonSolveGivesTheSameTrajectory) {
  const Scene full = load_scene(kDir + "dynamics_step.yaml");
  const Scene reduced = with_parameters(full, {{"analysis.dynamics.newton_solve", "reduced"}});
  const Result rf = run(full, RunOptions()), rr = run(reduced, RunOptions());
  ASSERT_TRUE(rf.ok()) << rf.message;
  ASSERT_TRUE(rr.ok()) << rr.message;
  EXPECT_EQ(rf.summary["steps"][2]["newton_solve"], "full");
  EXPECT_EQ(rr.summary["steps"][2]["newton_solve"], "reduced");
  const std::vector<double>&zf = rf.column("wheel_z"), &zr = rr.column("wheel_z");
  ASSERT_EQ(zf.size(), zr.size());
  double worst = 0;
  for (size_t i = 0; i < zf.size(); ++i) worst = std::max(worst, std::fabs(zf[i] - zr[i]));
  RecordProperty("max_wheel_z_difference", std::to_string(worst));
  EXPECT_LT(worst, 1e-8);  // both runs are within about 1e-9 m of the converged reference
  RunOptions ggl;
  ggl.formulation = "index2-ggl";
  const Result rg = run(with_parameters(reduced, {{"analysis.dynamics.t_end", "0.1"}}), ggl);
  ASSERT_TRUE(rg.ok()) << rg.message;
  EXPECT_EQ(rg.summary["steps"][2]["newton_solve"], "full");
}

TEST(SetParameter, ModelFileValueEqualsEditedModelFile) {
  // bodies.wheel.mass and the spring's stiffness live in model.yaml; coordinates.q4 too (the
  // scene names only q1); a new key of the scene's own tyre goes into the scene.
  const std::string scene_text = read(kDir + "dynamics_step.yaml"), model_text = read(kDir + "model.yaml");
  Scene s = load_scene(copy_case("override_plain", "dynamics_step.yaml", scene_text, model_text));
  s = with_parameters(s, {{"bodies.wheel.mass", "13"}, {"forces.suspension.stiffness", "1.5e5"},
                          {"coordinates.q4.initial", "0.21"}, {"gravity", "[0, 0, -9.80665]"}});
  std::string m = edit(model_text, "mass: 12", "mass: 13", "name: wheel");
  m = edit(m, "stiffness: 1.4e5", "stiffness: 1.5e5");
  m = edit(m, "q4: {initial: 0.207743260032}", "q4: {initial: 0.21}");
  m = edit(m, "gravity: [0, 0, -9.81]", "gravity: [0, 0, -9.80665]");
  const Scene edited = load_scene(copy_case("override_edited", "dynamics_step.yaml", scene_text, m));
  ASSERT_EQ(edited.model.gravity.z(), -9.80665);
  expect_same_scene(s, edited);
  expect_same_run(s, edited);
}

TEST(SetParameter, UnknownPathNamesTheMissingItem) {
  const Scene s = load_scene(kDir + "dynamics_step.yaml");
  for (const auto& [path, missing] : std::vector<std::pair<std::string, std::string>>{
           {"forces.nosuch.stiffness", "'nosuch' in 'forces'"},
           {"analysis.statics.rtol", "'statics' in 'analysis'"},
           {"analysis.7.t_end", "'7' in 'analysis'"},
           {"bodies.carrier.points.nowhere.x", "'nowhere' in 'bodies.carrier.points'"},
           {"bodies.wheel.points.cp1", "'points' in 'bodies.wheel'"},
           {"forces..stiffness", "not a parameter path"}}) {
    Scene copy = s;
    try {
      set_parameter(copy, path, "1");
      ADD_FAILURE() << path << " was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("dynamics_step.yaml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("'" + path + "'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
    EXPECT_EQ(copy.model.forces.back().stiffness, 2.0e5);  // unchanged
  }
}

// A bad value gets the message the same value gets in the file (file, line, field), plus the
// parameter path that set it.
void expect_message_as_in_file(const Scene& scene, const std::string& path, const std::string& value,
                               const std::function<Scene()>& load_edited) {
  std::string from_override, from_file;
  try {
    Scene copy = scene;
    set_parameter(copy, path, value);
  } catch (const SceneError& e) {
    ASSERT_EQ(e.messages.size(), 1u) << e.what();
    from_override = e.messages[0];
  }
  try {
    load_edited();
  } catch (const SceneError& e) {
    ASSERT_EQ(e.messages.size(), 1u) << e.what();
    from_file = e.messages[0];
  }
  ASSERT_FALSE(from_file.empty());
  EXPECT_EQ(from_override, from_file + " (set by parameter " + path + " = '" + value + "')");
}

TEST(SetParameter, BadValueGetsTheFilesMessage) {
  const std::string path = kDir + "dynamics_step.yaml";
  const Scene s = load_scene(path);
  const std::string text = read(path);
  expect_message_as_in_file(s, "forces.tyre.stiffness", "stiff", [&] {
    return load_scene_text(edit(text, "stiffness: 2.0e5", "stiffness: stiff"), path);
  });
  expect_message_as_in_file(s, "analysis.dynamics.rtol", "2", [&] {
    return load_scene_text(edit(text, "rtol: 1.0e-8", "rtol: 2"), path);
  });
  expect_message_as_in_file(s, "forces.tyre.radius", "-0.3", [&] {
    return load_scene_text(edit(text, "radius: 0.30", "radius: -0.3"), path);
  });
  // A value in the model file: the message names model.yaml and the line of the value. (The
  // scene keeps the model text it read, so the edited file written later does not change it.)
  const std::string model_text = read(kDir + "model.yaml");
  const Scene m = load_scene(copy_case("bad_model", "dynamics_step.yaml", text, model_text));
  expect_message_as_in_file(m, "bodies.rod1.mass", "-2", [&] {
    return load_scene(copy_case("bad_model", "dynamics_step.yaml", text,
                                edit(model_text, "{name: rod1, mass: 2,", "{name: rod1, mass: -2,")));
  });
}

TEST(SetParameter, NewFieldIsCheckedLikeTheFile) {
  Scene s = load_scene(kDir + "dynamics_step.yaml");
  try {
    set_parameter(s, "forces.tyre.stifness", "1");
    ADD_FAILURE() << "a misspelt field was accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("dynamics_step.yaml:12: field 'stifness': unknown field in force"), std::string::npos) << m;
    EXPECT_NE(m.find("did you mean 'stiffness'"), std::string::npos) << m;
  }
}

TEST(SetParameter, SceneWithoutSourceSaysSo) {
  Scene s;
  s.file = "built-in-code";
  EXPECT_THROW(set_parameter(s, "gravity", "[0, 0, 0]"), SceneError);
}

}  // namespace
}  // namespace mbdae


namespace mbdae {
namespace {

// ---- --rtol alone scales the absolute tolerances a scene fixes (issue 21) ----------------------

const std::string kPendulum = std::string(MBDAE_SOURCE_DIR) + "/verification/engine/scenes/compound_pendulum.yaml";

// The compound pendulum over 2 s with its step's tolerances replaced by `tolerances` (YAML).
Scene pendulum_with(const std::string& tolerances) {
  const std::string text = edit(edit(read(kPendulum), "rtol: 3.0e-14, atol: 1.0e-14, newton_convergence: 0.001", tolerances),
                                "t_end: 10.5", "t_end: 2");
  return load_scene_text(text, kPendulum);
}

const nlohmann::ordered_json& dynamics_summary(const Result& r) { return r.summary["steps"].back(); }

TEST(RtolOverride, ScalesTheScenesAbsoluteTolerances) {
  const Scene scene = pendulum_with("rtol: 1.0e-8, atol: 1.0e-12, atol_velocity: 1.0e-11");
  RunOptions opt;
  opt.verbose = opt.progress = false;
  opt.rtol = 1e-4;
  const Result loose = run(scene, opt);
  ASSERT_TRUE(loose.ok()) << loose.message;
  const auto& tl = dynamics_summary(loose)["tolerances"];
  EXPECT_NEAR(tl["atol_position"].get<double>(), 1e-8, 1e-20);  // 1e-12 x 1e-4 / 1e-8
  EXPECT_NEAR(tl["atol_velocity"].get<double>(), 1e-7, 1e-19);
  EXPECT_NEAR(tl["scene_atol_scaled_by"].get<double>(), 1e4, 1e-8);
  EXPECT_EQ(dynamics_summary(loose)["atol"].get<double>(), tl["atol_position"].get<double>());
  // The scene's own rtol: the scene's atol, no factor reported.
  opt.rtol = 1e-8;
  const Result own = run(scene, opt);
  ASSERT_TRUE(own.ok()) << own.message;
  EXPECT_EQ(dynamics_summary(own)["tolerances"]["atol_position"].get<double>(), 1e-12);
  EXPECT_FALSE(dynamics_summary(own)["tolerances"].contains("scene_atol_scaled_by"));
  // A quick look (issue 21: rtol 1e-2) is a fraction of the scene's run, and rtol 1e-4 with the
  // atol scaled is cheaper than with the scene's atol kept (before issue 21). Measured (index3,
  // its position test per unit of the span, capped): 587 steps at rtol 1e-2 and 1398 at 1e-4
  // against 2679 at the scene's rtol; 1430 at 1e-4 with the scene's atol.
  opt.rtol = 1e-2;
  const Result quick = run(scene, opt);
  ASSERT_TRUE(quick.ok()) << quick.message;
  opt.rtol = 1e-4;
  opt.atol = 1e-12;
  const Result kept = run(scene, opt);
  ASSERT_TRUE(kept.ok()) << kept.message;
  const long steps_quick = dynamics_summary(quick)["statistics"]["steps"].get<long>();
  const long steps_loose = dynamics_summary(loose)["statistics"]["steps"].get<long>();
  const long steps_own = dynamics_summary(own)["statistics"]["steps"].get<long>();
  const long steps_kept = dynamics_summary(kept)["statistics"]["steps"].get<long>();
  std::printf("steps: rtol 1e-2 %ld; rtol 1e-4 with the atol scaled %ld, with the scene's atol %ld; the scene's "
              "rtol %ld\n", steps_quick, steps_loose, steps_kept, steps_own);
  EXPECT_LT(4 * steps_quick, steps_own);
  EXPECT_LT(steps_loose, steps_own);
  EXPECT_LT(steps_loose, steps_kept);
}

TEST(RtolOverride, GivenAtolIsKept) {
  const Scene scene = pendulum_with("rtol: 1.0e-8, atol: 1.0e-12");
  RunOptions opt;
  opt.verbose = opt.progress = false;
  opt.rtol = 1e-4;
  opt.atol = 1e-9;
  const Result r = run(scene, opt);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(dynamics_summary(r)["tolerances"]["atol_position"].get<double>(), 1e-9);
  EXPECT_FALSE(dynamics_summary(r)["tolerances"].contains("scene_atol_scaled_by"));
}

// The cylindrical cut (the cut-type recipe of docs/architecture.md, done once): a body on six
// tree coordinates, held by a cylindrical cut to ground about the vertical axis, falls freely
// along it and spins at its initial rate: z = z0 - g t^2 / 2, psi = w t, nothing across the axis.
TEST(CutTypes, CylindricalCutFallsAndSpinsFreelyAlongItsAxis) {
  const char* const text = R"(name: cylindrical
gravity: [0, 0, -9.81]
bodies:
  - {name: sleeve, mass: 2.0, inertia: {xx: 0.05, yy: 0.05, zz: 0.02}}
joints:
  - {name: free, parent: ground, child: sleeve, chain: [T1, T2, T3, R1, R2, R3], coordinates: [x, y, z, a, b, psi]}
coordinates:
  x: {initial: 0}
  y: {initial: 0}
  z: {initial: 1}
  a: {initial: 0}
  b: {initial: 0}
  psi: {initial: 0}
cuts:
  - {name: rail, type: cylindrical, body1: ground, body2: sleeve, axis1: [0, 0, 1]}
sensors:
  - {name: x, type: coordinate, coordinate: x}
  - {name: z, type: coordinate, coordinate: z}
  - {name: b, type: coordinate, coordinate: b}
  - {name: psi, type: coordinate, coordinate: psi}
analysis:
  - {type: dynamics, t_end: 1.0, output_step: 0.05, rtol: 1e-9, initial_velocities: {psi: 3.0}}
)";
  const Result r = run(load_scene_text(text, "cylindrical.yaml"), RunOptions{});
  ASSERT_TRUE(r.ok()) << r.message;
  const auto &t = r.column("t"), &x = r.column("x"), &z = r.column("z"), &b = r.column("b"), &psi = r.column("psi");
  double worst_z = 0, worst_psi = 0, worst_across = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    worst_z = std::max(worst_z, std::fabs(z[i] - (1.0 - 0.5 * 9.81 * t[i] * t[i])));
    worst_psi = std::max(worst_psi, std::fabs(psi[i] - 3.0 * t[i]));
    worst_across = std::max({worst_across, std::fabs(x[i]), std::fabs(b[i])});
  }
  std::printf("cylindrical cut over 1 s: |z - z_exact| %.2e m, |psi - w t| %.2e rad, across the axis %.2e\n",
              worst_z, worst_psi, worst_across);
  EXPECT_EQ(t.size(), 21u);
  EXPECT_LT(worst_z, 1e-7 * 4.905);  // 100 rtol of the fall
  EXPECT_LT(worst_psi, 1e-7 * 3.0);
  EXPECT_LT(worst_across, 1e-9);
}

}  // namespace
}  // namespace mbdae
