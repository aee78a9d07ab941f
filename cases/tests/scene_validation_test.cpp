// Scene validation: one test per rule. Each feeds a broken variant of a small valid scene and
// checks that the message names the file, the line and the field. A few go through the real
// executable (exit code 2 for a bad scene, 1 for bad usage, 0 for `check` of a good scene).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cases/scene/analysis_types.h"
#include "cases/scene/scene.h"
#include "cases/tests/run_command.h"
#include "core/errors.h"
#include "formulation/system.h"

namespace mbdae {
namespace {

namespace fs = std::filesystem;

// A pendulum arm with a bob welded to its tip, a spring, sensors and two analyses.
const char* const kValid = R"(name: pendulum
bodies:
  - name: arm
    mass: 1.0
    com: [0.5, 0, 0]
    inertia: {xx: 0.01, yy: 0.1, zz: 0.1}
    points:
      tip: [1, 0, 0]
  - name: bob
    mass: 0.5
joints:
  - name: pivot
    parent: ground
    child: arm
    anchor: [0, 0, 1]
    chain: [R2]
    coordinates: [theta]
  - name: tip_weld
    parent: arm
    child: bob
    anchor: tip
coordinates:
  theta: {initial_deg: 30}
forces:
  - {name: spring, type: spring_damper, body1: ground, body2: arm, point2: tip, stiffness: 10, free_length: 0.5}
sensors:
  - {name: angle, type: coordinate, coordinate: theta}
  - {name: tip_z, type: position, body: arm, point: tip, component: z}
  - {name: twice, type: expression, expression: "2 * angle"}
output: [angle, tip_z]
analysis:
  - {type: assembly}
  - {type: equilibrium, hold: [theta], release: [theta], unknowns: [spring.free_length]}
  - {type: dynamics, t_end: 1.0, output_step: 0.01, rtol: 1.0e-6, atol: 1.0e-8}
)";

const char* const kFile = "scene.yaml";

// kValid with the first occurrence of `from` replaced by `to`.
std::string with(const std::string& from, const std::string& to, std::string text = kValid) {
  const size_t p = text.find(from);
  EXPECT_NE(p, std::string::npos) << "'" << from << "' is not in the scene";
  if (p != std::string::npos) text.replace(p, from.size(), to);
  return text;
}

// 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const size_t p = text.find(needle);
  EXPECT_NE(p, std::string::npos) << "'" << needle << "' is not in the scene";
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(std::min(p, text.size())), '\n'));
}

std::vector<std::string> errors_of(const std::string& text, const std::string& path = kFile) {
  try {
    load_scene_text(text, path);
  } catch (const SceneError& e) {
    return e.messages;
  }
  return {};
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

// Expects exactly one message, at `line`, about `field`, containing `words`.
void expect_one(const std::string& text, int line, const std::string& field, const std::string& words) {
  const auto errors = errors_of(text);
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  const std::string prefix = std::string(kFile) + ":" + std::to_string(line) + ": field '" + field + "': ";
  EXPECT_EQ(errors[0].rfind(prefix, 0), 0u) << errors[0] << "\nexpected prefix: " << prefix;
  EXPECT_NE(errors[0].find(words), std::string::npos) << errors[0] << "\nexpected: " << words;
}

// Expects some message at `line` about `field` containing `words` (among possibly others).
void expect_some(const std::vector<std::string>& errors, const std::string& file, int line, const std::string& field,
                 const std::string& words) {
  const std::string prefix = file + ":" + std::to_string(line) + ": field '" + field + "': ";
  for (const auto& e : errors)
    if (e.rfind(prefix, 0) == 0 && e.find(words) != std::string::npos) return;
  ADD_FAILURE() << "no message '" << prefix << "..." << words << "...' in:\n" << joined(errors);
}

// ---- The valid scene and the example scenes --------------------------------------------------

TEST(SceneValidation, ValidSceneLoadsAndBuilds) {
  const auto errors = errors_of(kValid);
  ASSERT_TRUE(errors.empty()) << joined(errors);
  const Scene s = load_scene_text(kValid, kFile);
  const System sys = build_system(s.model);
  EXPECT_EQ(sys.sensors.size(), 3u);
}

TEST(SceneValidation, ExampleScenesAreValid) {
  const fs::path dir = fs::path(MBDAE_SOURCE_DIR) / "cases" / "five_point_suspension";
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml" || entry.path().filename() == "model.yaml") continue;
    ++scenes;
    try {
      const Scene s = load_scene(entry.path().string());
      build_system(s.model);
    } catch (const std::exception& e) {
      ADD_FAILURE() << entry.path() << ":\n" << e.what();
    }
  }
  EXPECT_GE(scenes, 1);
}

// ---- Field level: unknown, missing, wrong type ---------------------------------------------

TEST(SceneValidation, UnknownField) {
  const std::string t = with("    mass: 1.0\n", "    mas: 1.0\n");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "mas:"), "mas", "unknown field in body");
  expect_some(errors, kFile, line_of(t, "mas:"), "mas", "did you mean 'mass'?");
  expect_some(errors, kFile, line_of(t, "- name: arm"), "mass", "missing");
  EXPECT_EQ(errors.size(), 2u) << joined(errors);
}

TEST(SceneValidation, UnknownTopLevelField) {
  const std::string t = with("output:", "outptu:");
  expect_one(t, line_of(t, "outptu:"), "outptu", "unknown field in scene");
}

TEST(SceneValidation, MissingFieldOfJoint) {
  const std::string t = with("    child: arm\n", "");
  expect_one(t, line_of(t, "- name: pivot"), "child", "missing");
}

TEST(SceneValidation, MissingAnalysis) {
  std::string t = kValid;
  t = t.substr(0, t.find("analysis:"));
  expect_one(t, 1, "analysis", "missing");
}

TEST(SceneValidation, FieldGivenTwice) {
  const std::string t = with("    mass: 0.5\n", "    mass: 0.5\n    mass: 0.6\n");
  expect_one(t, line_of(t, "mass: 0.6"), "mass", "given twice");
}

TEST(SceneValidation, FieldDoesNotApplyToType) {
  const std::string t = with("stiffness: 10,", "stiffness: 10, radius: 0.3,");
  expect_one(t, line_of(t, "radius: 0.3"), "radius", "does not apply to a spring_damper force");
}

// The analysis types come from one table (cases/scene/analysis_types.h): their names in the message for
// an unknown one, their own fields in the message for a field of another type.
TEST(SceneValidation, AnalysisTypesFromTheRegistry) {
  std::string t = with("{type: assembly}", "{type: linearization}");
  expect_one(t, line_of(t, "linearization"), "type",
             "unknown analysis 'linearization' (" + analysis_type_names() + ")");
  EXPECT_NE(analysis_type_names().find("equilibrium"), std::string::npos);
  t = with("{type: assembly}", "{type: assembly, rtol: 1.0e-6}");
  expect_one(t, line_of(t, "rtol: 1.0e-6}"), "rtol",
             "does not apply to an assembly step (its fields: type, hold, t0, mode_check, mode_check_deg)");
  for (AnalysisStep::Type type : {AnalysisStep::Type::kAssembly, AnalysisStep::Type::kEquilibrium,
                                  AnalysisStep::Type::kKinematics, AnalysisStep::Type::kDynamics}) {
    const AnalysisType& a = analysis_type(type);
    EXPECT_EQ(find_analysis_type(a.name), &a);
    EXPECT_TRUE(a.stage != nullptr) << a.name;
    EXPECT_EQ(a.integrates, type == AnalysisStep::Type::kKinematics || type == AnalysisStep::Type::kDynamics);
  }
}

// Every true/false field is read by one reader: the same message, and an explicit false wins.
TEST(SceneValidation, TrueFalseFields) {
  std::string t = with("coordinate: theta}", "coordinate: theta, wrap: maybe}");
  expect_one(t, line_of(t, "wrap: maybe"), "wrap", "expected true or false, got 'maybe'");
  t = with("atol: 1.0e-8}", "atol: 1.0e-8, output_projection: yes}");
  expect_one(t, line_of(t, "output_projection"), "output_projection", "expected true or false, got 'yes'");
  t = with("output: [angle, tip_z]", "output: [angle, tip_z]\nanimation: {write: 1}");
  expect_one(t, line_of(t, "write: 1"), "write", "expected true or false, got '1'");
  EXPECT_TRUE(load_scene_text(with("output: [angle, tip_z]", "output: [angle, tip_z]\nanimation: {write: true}"),
                              kFile).animation.write);
  EXPECT_FALSE(load_scene_text(with("output: [angle, tip_z]", "output: [angle, tip_z]\nanimation: {write: false}"),
                               kFile).animation.write);
  EXPECT_TRUE(load_scene_text(with("coordinate: theta}", "coordinate: theta, wrap: true}"), kFile).model.sensors[0].wrap);
}

TEST(SceneValidation, WrongTypeNumber) {
  const std::string t = with("mass: 0.5", "mass: heavy");
  expect_one(t, line_of(t, "heavy"), "mass", "expected a number, got 'heavy'");
}

TEST(SceneValidation, WrongTypeList) {
  const std::string t = with("com: [0.5, 0, 0]", "com: [0.5, 0]");
  expect_one(t, line_of(t, "com:"), "com", "expected a list of 3 numbers");
}

TEST(SceneValidation, WrongTypeText) {
  const std::string t = with("parent: ground", "parent: [ground]");
  expect_one(t, line_of(t, "parent:"), "parent", "expected text");
}

TEST(SceneValidation, WrongTypeNameList) {
  const std::string t = with("output: [angle, tip_z]", "output: {angle: 1}");
  expect_one(t, line_of(t, "output:"), "output", "expected a list of names, got a mapping");
}

TEST(SceneValidation, WrongTypeSection) {
  const std::string t = with("name: pendulum\n", "name: pendulum\ncuts: {name: c}\n");
  expect_one(t, line_of(t, "cuts:"), "cuts", "expected a list, got a mapping");
}

TEST(SceneValidation, YamlSyntaxError) {
  const std::string t = with("theta: {initial_deg: 30}", "theta: {initial_deg: 30");
  const auto errors = errors_of(t);
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  EXPECT_NE(errors[0].find("YAML syntax error"), std::string::npos) << errors[0];
  EXPECT_EQ(errors[0].rfind(std::string(kFile) + ":", 0), 0u) << errors[0];
}

TEST(SceneValidation, SceneNotAMapping) {
  const auto errors = errors_of("- just\n- a list\n");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("must be a YAML mapping"), std::string::npos) << errors[0];
}

// ---- Numbers ---------------------------------------------------------------------------------

TEST(SceneValidation, ZeroMass) {
  const std::string t = with("mass: 0.5", "mass: 0");
  expect_one(t, line_of(t, "mass: 0\n"), "mass", "must be positive");
}

TEST(SceneValidation, NegativeMass) {
  const std::string t = with("mass: 1.0", "mass: -1.0");
  expect_one(t, line_of(t, "mass: -1.0"), "mass", "must be positive");
}

TEST(SceneValidation, InertiaNotPositiveSemiDefinite) {
  const std::string t = with("xx: 0.01", "xx: -0.01");
  expect_one(t, line_of(t, "inertia:"), "inertia", "not positive semi-definite");
}

TEST(SceneValidation, InertiaNotSymmetric) {
  const std::string t = with("{xx: 0.01, yy: 0.1, zz: 0.1}", "[[0.01, 0.001, 0], [0, 0.1, 0], [0, 0, 0.1]]");
  expect_one(t, line_of(t, "inertia:"), "inertia", "not symmetric");
}

TEST(SceneValidation, InertiaNotARigidBody) {
  const std::string t = with("{xx: 0.01, yy: 0.1, zz: 0.1}", "{xx: 0.01, yy: 0.01, zz: 0.1}");
  expect_one(t, line_of(t, "inertia:"), "inertia", "triangle inequality");
}

TEST(SceneValidation, NanAnchor) {
  const std::string t = with("anchor: [0, 0, 1]", "anchor: [0, .nan, 1]");
  expect_one(t, line_of(t, ".nan"), "anchor", "'.nan' is not a finite number");
}

TEST(SceneValidation, InfiniteParameter) {
  const std::string t = with("stiffness: 10", "stiffness: -.inf");
  expect_one(t, line_of(t, "-.inf"), "stiffness", "is not a finite number");
}

TEST(SceneValidation, OverflowingNumber) {
  const std::string t = with("free_length: 0.5", "free_length: 1e999");
  expect_one(t, line_of(t, "1e999"), "free_length", "is not a finite number");
}

TEST(SceneValidation, NanInitialValue) {
  const std::string t = with("initial_deg: 30", "initial_deg: nan");
  expect_one(t, line_of(t, "initial_deg: nan"), "initial_deg", "not a finite number");
}

TEST(SceneValidation, NegativeStiffness) {
  const std::string t = with("stiffness: 10", "stiffness: -10");
  expect_one(t, line_of(t, "stiffness: -10"), "stiffness", "must not be negative");
}

// ---- Time spans and tolerances ------------------------------------------------------------------

TEST(SceneValidation, EmptyTimeSpan) {
  const std::string t = with("t_end: 1.0", "t0: 2.0, t_end: 1.0");
  expect_one(t, line_of(t, "t_end: 1.0"), "t_end", "time span is empty");
}

TEST(SceneValidation, NonPositiveOutputStep) {
  const std::string t = with("output_step: 0.01", "output_step: 0");
  expect_one(t, line_of(t, "output_step: 0"), "output_step", "must be positive");
}

TEST(SceneValidation, PenaltyFormulation) {
  const std::string ok = with("atol: 1.0e-8}", "atol: 1.0e-8, formulation: penalty, penalty: 1.0e9}");
  EXPECT_TRUE(errors_of(ok).empty()) << joined(errors_of(ok));
  const std::string t = with("atol: 1.0e-8}", "atol: 1.0e-8, formulation: penalty, penalty: 0}");
  expect_one(t, line_of(t, "penalty: 0"), "penalty", "must be positive");
}

TEST(SceneValidation, NewtonSolve) {
  const std::string ok = with("atol: 1.0e-8}", "atol: 1.0e-8, newton_solve: reduced}");
  EXPECT_TRUE(errors_of(ok).empty()) << joined(errors_of(ok));
  const std::string t = with("atol: 1.0e-8}", "atol: 1.0e-8, newton_solve: sparse}");
  expect_one(t, line_of(t, "newton_solve"), "newton_solve", "expected full or reduced, got 'sparse'");
}

TEST(SceneValidation, TooManyOutputRows) {
  const std::string t = with("output_step: 0.01", "output_step: 1.0e-12");
  expect_one(t, line_of(t, "output_step:"), "output_step", "more than 1e8 output rows");
}

TEST(SceneValidation, EmptySweepSpan) {
  const std::string t = with("stiffness: 10, free_length: 0.5}",
                             "stiffness: 10, free_length: 0.5}\n"
                             "  - {name: push, type: point_force, body: arm,\n"
                             "     fz: {type: sweep, amplitude: 1, f0: 1, f1: 2, t0: 1, t1: 1}}");
  expect_one(t, line_of(t, "fz:"), "t1", "time span is empty");
}

TEST(SceneValidation, RelativeToleranceOutOfRange) {
  const std::string t = with("rtol: 1.0e-6", "rtol: 0.9");
  expect_one(t, line_of(t, "rtol: 0.9"), "rtol", "out of range [1e-14, 0.5]");
}

TEST(SceneValidation, AbsoluteToleranceOutOfRange) {
  const std::string t = with("atol: 1.0e-8", "atol: -1.0e-8");
  expect_one(t, line_of(t, "atol: -1.0e-8"), "atol", "out of range (0, 1]");
}

TEST(SceneValidation, NegativeMaxStep) {
  const std::string t = with("atol: 1.0e-8", "atol: 1.0e-8, max_step: -1");
  expect_one(t, line_of(t, "max_step"), "max_step", "must not be negative");
}

TEST(SceneValidation, UnknownAssemblyModeCheck) {
  const std::string t = with("{type: assembly}", "{type: assembly, mode_check: warning}");
  expect_one(t, line_of(t, "mode_check"), "mode_check", "expected warn, fail or off, got 'warning'");
}

TEST(SceneValidation, AssemblyModeCheckAngleOutOfRange) {
  const std::string t = with("{type: assembly}", "{type: assembly, mode_check_deg: 0}");
  expect_one(t, line_of(t, "mode_check_deg"), "mode_check_deg", "out of range (0, 180]");
}

TEST(SceneValidation, ModeCheckOnlyForAssembly) {
  const std::string t = with("atol: 1.0e-8", "atol: 1.0e-8, mode_check: fail");
  expect_one(t, line_of(t, "mode_check"), "mode_check", "does not apply to");
}

TEST(SceneValidation, InitialVelocityOfUnknownCoordinate) {
  const std::string t = with("atol: 1.0e-8}", "atol: 1.0e-8, initial_velocities: {thta: 1.0}}");
  expect_one(t, line_of(t, "initial_velocities"), "initial_velocities", "no joint coordinate named 'thta'; did you mean 'theta'?");
}

TEST(SceneValidation, InitialVelocityNotANumber) {
  const std::string t = with("atol: 1.0e-8}", "atol: 1.0e-8, initial_velocities: {theta: fast}}");
  expect_one(t, line_of(t, "initial_velocities"), "initial_velocities.theta", "expected a number, got 'fast'");
}

TEST(SceneValidation, InitialVelocitiesNotAMapping) {
  const std::string t = with("atol: 1.0e-8}", "atol: 1.0e-8, initial_velocities: [theta, 1]}");
  expect_one(t, line_of(t, "initial_velocities"), "initial_velocities", "expected a mapping of coordinate names to rates");
}

TEST(SceneValidation, InitialVelocityOfDrivenCoordinate) {
  std::string t = with("theta: {initial_deg: 30}", "theta: {initial_deg: 30, mode: driven, drive: 0.5}");
  t = with("  - {type: equilibrium, hold: [theta], release: [theta], unknowns: [spring.free_length]}\n", "", t);
  t = with("atol: 1.0e-8}", "atol: 1.0e-8, initial_velocities: {theta: 1.0}}", t);
  expect_one(t, line_of(t, "initial_velocities"), "initial_velocities", "coordinate 'theta' is driven");
}

// A step drive (a jump of a position) inside a dynamics step is no motion; at the step's start,
// or as a ramp, it is.
TEST(SceneValidation, StepDriveInsideADynamicsStep) {
  std::string t = with("theta: {initial_deg: 30}",
                       "theta: {initial_deg: 30, mode: driven, drive: {type: step, time: 0.5, before: 0.5, after: 0.6}}");
  t = with("  - {type: equilibrium, hold: [theta], release: [theta], unknowns: [spring.free_length]}\n", "", t);
  expect_one(t, line_of(t, "mode: driven"), "drive", "coordinate 'theta' is driven by a step (from 0.5 to 0.6 at t = 0.5) "
                                                     "inside a dynamics step (t = 0 to 1)");
  EXPECT_NO_THROW(load_scene_text(with("time: 0.5,", "time: 0.0,", t), kFile));
  EXPECT_NO_THROW(load_scene_text(with("{type: step, time: 0.5, before: 0.5, after: 0.6}",
                                       "{type: piecewise_linear, points: [[0.5, 0.5], [0.6, 0.6]]}", t),
                                  kFile));
}

TEST(SceneValidation, InitialVelocitiesOnlyForDynamics) {
  const std::string t = with("{type: assembly}", "{type: assembly, initial_velocities: {theta: 1.0}}");
  expect_one(t, line_of(t, "initial_velocities"), "initial_velocities", "does not apply to");
}

// ---- References ------------------------------------------------------------------------------

TEST(SceneValidation, UnknownParentBody) {
  const std::string t = with("parent: ground", "parent: grund");
  const auto errors = errors_of(t);
  ASSERT_EQ(errors.size(), 1u) << joined(errors);  // the bodies cut off are not reported again
  expect_some(errors, kFile, line_of(t, "parent: grund"), "parent", "no body named 'grund'; did you mean 'ground'?");
}

TEST(SceneValidation, UnknownChildBody) {
  const std::string t = with("child: bob", "child: bobb");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "child: bobb"), "child", "no body named 'bobb'");
  EXPECT_EQ(errors.size(), 1u) << joined(errors);  // 'bob' having no joint follows from it
}

TEST(SceneValidation, UnknownAnchorPoint) {
  const std::string t = with("anchor: tip", "anchor: tap");
  expect_one(t, line_of(t, "anchor: tap"), "anchor", "body 'arm' has no point 'tap'");
}

TEST(SceneValidation, UnknownForcePoint) {
  const std::string t = with("point2: tip", "point2: top");
  expect_one(t, line_of(t, "point2: top"), "point2", "body 'arm' has no point 'top'");
}

TEST(SceneValidation, UnknownForceBody) {
  const std::string t = with("body2: arm", "body2: leg");
  expect_one(t, line_of(t, "body2: leg"), "body2", "no body named 'leg'");
}

TEST(SceneValidation, UnknownSensorBody) {
  const std::string t = with("type: position, body: arm", "type: position, body: arn");
  expect_one(t, line_of(t, "body: arn"), "body", "no body named 'arn'; did you mean 'arm'?");
}

TEST(SceneValidation, UnknownSensorCoordinate) {
  const std::string t = with("coordinate: theta}", "coordinate: phi}");
  expect_one(t, line_of(t, "coordinate: phi"), "coordinate", "no joint coordinate named 'phi'");
}

TEST(SceneValidation, UnknownSensorForce) {
  const std::string t = with("  - {name: twice", "  - {name: pull, type: force_value, force: sprung}\n  - {name: twice");
  expect_one(t, line_of(t, "force: sprung"), "force", "no force named 'sprung'; did you mean 'spring'?");
}

TEST(SceneValidation, ExpressionUnknownName) {
  const std::string t = with("2 * angle", "2 * angel + tip_y");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "angel"), "expression", "unknown name 'angel'");
  expect_some(errors, kFile, line_of(t, "angel"), "expression", "unknown name 'tip_y'");
  EXPECT_EQ(errors.size(), 2u) << joined(errors);
}

TEST(SceneValidation, ExpressionUsesLaterSensor) {
  const std::string t = with("  - {name: twice, type: expression, expression: \"2 * angle\"}",
                             "  - {name: twice, type: expression, expression: \"2 * later\"}\n"
                             "  - {name: later, type: coordinate, coordinate: theta}");
  expect_one(t, line_of(t, "2 * later"), "expression", "sensor 'later' is listed after this one");
}

TEST(SceneValidation, ExpressionSyntax) {
  const std::string t = with("2 * angle", "2 * (angle");
  expect_one(t, line_of(t, "2 * (angle"), "expression", "expected ')'");
}

TEST(SceneValidation, ExpressionTooDeep) {
  std::string e;
  for (int k = 0; k < 70; ++k) e += "angle+(";
  e += "angle";
  for (int k = 0; k < 70; ++k) e += ")";
  const std::string t = with("2 * angle", e);
  expect_one(t, line_of(t, "angle+("), "expression", "nested too deeply");
}

TEST(SceneValidation, UnknownOutputColumn) {
  const std::string t = with("output: [angle, tip_z]", "output: [angle, tip_x]");
  expect_one(t, line_of(t, "output:"), "output", "no sensor named 'tip_x'");
}

TEST(SceneValidation, UnknownHoldCoordinate) {
  const std::string t = with("hold: [theta]", "hold: [theta, psi]");
  expect_one(t, line_of(t, "psi"), "hold", "no joint coordinate named 'psi'");
}

TEST(SceneValidation, ReleaseNotHeld) {
  const std::string t = with("hold: [theta]", "hold: []");
  expect_one(t, line_of(t, "hold: []"), "release", "released but not held");
}

TEST(SceneValidation, UnknownForceInUnknowns) {
  const std::string t = with("unknowns: [spring.free_length]", "unknowns: [sprang.free_length]");
  expect_one(t, line_of(t, "sprang"), "unknowns", "no force named 'sprang'");
}

TEST(SceneValidation, UnknownParameterInUnknowns) {
  const std::string t = with("unknowns: [spring.free_length]", "unknowns: [spring.radius]");
  expect_one(t, line_of(t, "spring.radius"), "unknowns", "'radius' is not a parameter of force 'spring'");
}

TEST(SceneValidation, ReleasedCountMatchesUnknowns) {
  const std::string t = with("unknowns: [spring.free_length]", "unknowns: [spring.free_length, spring.stiffness]");
  expect_one(t, line_of(t, "unknowns:"), "release", "one released coordinate is needed per unknown parameter");
}

TEST(SceneValidation, HoldOfLockedCoordinate) {
  const std::string t = with("theta: {initial_deg: 30}", "theta: {initial_deg: 30, mode: locked}");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "hold: [theta]"), "hold", "coordinate 'theta' is locked");
  expect_some(errors, kFile, line_of(t, "hold: [theta]"), "release", "coordinate 'theta' is locked");
  EXPECT_EQ(errors.size(), 2u) << joined(errors);
}

TEST(SceneValidation, UnknownQuietSensor) {
  const std::string t = with("atol: 1.0e-8", "atol: 1.0e-8, quiet_until: 0.5, quiet_sensors: [tip_q]");
  expect_one(t, line_of(t, "tip_q"), "quiet_sensors", "no sensor named 'tip_q'");
}

TEST(SceneValidation, JointCoordinateWithoutEntry) {
  const std::string t = with("coordinates: [theta]", "coordinates: [theta2]");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "[theta2]"), "coordinates", "coordinate 'theta2' has no entry");
  expect_some(errors, kFile, line_of(t, "theta: {"), "coordinates.theta", "belongs to no joint");
}

TEST(SceneValidation, CoordinateUsedTwice) {
  const std::string t = with("    anchor: tip\n", "    anchor: tip\n    chain: [R1]\n    coordinates: [theta]\n");
  expect_one(t, line_of(t, "coordinates: [theta]\ncoordinates"), "coordinates", "already used by joint 'pivot'");
}

TEST(SceneValidation, RemoveUnknownName) {
  const std::string t = with("output:", "remove: [nothing]\noutput:");
  expect_one(t, line_of(t, "remove:"), "remove", "nothing named 'nothing' to remove");
}

// ---- Names and the joint tree ------------------------------------------------------------------

TEST(SceneValidation, DuplicateBodyName) {
  const std::string t = with("  - name: bob\n    mass: 0.5\n", "  - name: bob\n    mass: 0.5\n  - name: arm\n    mass: 2\n");
  const int second = line_of(t, "  - name: arm\n    mass: 2");
  expect_one(t, second, "name", "defined twice in this file");
}

TEST(SceneValidation, DuplicateNamesInModelFile) {
  const fs::path dir = fs::temp_directory_path() / ("mbdae_sv_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string model = "bodies:\n  - {name: a, mass: 1}\n  - {name: a, mass: 2}\n"
                            "joints:\n  - {name: j, parent: ground, child: a, chain: [T3], coordinates: [z]}\n"
                            "coordinates: {z: {initial: 0}}\n";
  std::ofstream(dir / "model.yaml") << model;
  const auto errors = errors_of("model: model.yaml\nanalysis: {type: assembly}\n", (dir / "scene.yaml").string());
  expect_some(errors, (dir / "model.yaml").string(), 3, "name", "body 'a' is defined twice (first at line 2)");
  EXPECT_EQ(errors.size(), 1u) << joined(errors);
  fs::remove_all(dir);
}

TEST(SceneValidation, GroundIsReserved) {
  const std::string t = with("  - name: bob\n", "  - name: ground\n");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "- name: ground"), "name", "'ground' is reserved");
}

TEST(SceneValidation, TreeLoop) {
  const std::string t = with("    anchor: tip\n", "    anchor: tip\n  - {name: back, parent: bob, child: arm}\n");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "{name: back"), "child", "body 'arm' is already the child of joint 'pivot'");
  EXPECT_EQ(errors.size(), 1u) << joined(errors);
}

TEST(SceneValidation, TreeLoopWithoutGround) {
  const std::string t = with("    parent: ground\n    child: arm\n", "    parent: bob\n    child: arm\n");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "parent: bob"), "parent", "the joint tree has a loop: 'arm' -> 'bob' -> 'arm'");
  EXPECT_EQ(errors.size(), 1u) << joined(errors);
}

TEST(SceneValidation, BodyWithoutPathToGround) {
  const std::string t = with("  - name: bob\n    mass: 0.5\n", "  - name: bob\n    mass: 0.5\n  - name: loose\n    mass: 1\n");
  expect_one(t, line_of(t, "name: loose"), "name", "body 'loose' has no joint to a parent (no path to ground)");
}

TEST(SceneValidation, JointToItself) {
  const std::string t = with("    parent: arm\n    child: bob\n", "    parent: bob\n    child: bob\n");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "parent: bob"), "parent", "joins body 'bob' to itself");
  EXPECT_EQ(errors.size(), 1u) << joined(errors);
}

TEST(SceneValidation, ChainInterleaves) {
  const std::string t = with("chain: [R2]\n    coordinates: [theta]", "chain: [R2, T1, R3]\n    coordinates: [theta, x, y]");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "chain:"), "chain", "interleaves rotations and translations");
}

TEST(SceneValidation, UnknownElementaryJoint) {
  const std::string t = with("chain: [R2]", "chain: [R4]");
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "chain:"), "chain", "unknown elementary joint 'R4'");
}

TEST(SceneValidation, CutWithinOneRigidBody) {
  const std::string t = with("forces:", "cuts:\n  - {name: c, type: ball, body1: arm, point1: tip, body2: bob}\nforces:");
  expect_one(t, line_of(t, "{name: c,"), "body2", "joins two parts of the same rigid body");
}

// A weld cut's reference direction along its axis leaves the cut frame undefined. This rule
// was the build's alone (`mbdae check` passed the scene, the run refused it); now the model
// rules (formulation/model_rules.h) decide for both.
TEST(SceneValidation, WeldCutReferenceAlongItsAxis) {
  const std::string t = with("forces:", "cuts:\n  - {name: c, type: weld, body1: ground, body2: arm, point2: tip, "
                                        "axis1: [0, 0, 1], ref1: [0, 0, 2], ref2: [1, 0, 0]}\nforces:");
  expect_one(t, line_of(t, "{name: c,"), "ref1", "cut 'c': ref1 is parallel to axis1");
}

// build_system applies the same rules to a model made in code (no scene file, no loader):
// its first problem, with the item's location and field.
TEST(SceneValidation, BuildRefusesAModelByTheSameRules) {
  Scene s = load_scene_text(kValid, kFile);
  s.model.sensors[0].target = "thetta";
  s.model.sensors[0].where = {"made-in-code", 42};
  try {
    build_system(s.model);
    ADD_FAILURE() << "build_system accepted a sensor of an unknown coordinate";
  } catch (const ModelError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("made-in-code:42: field 'coordinate': ", 0), 0u) << m;
    EXPECT_NE(m.find("no joint coordinate named 'thetta'; did you mean 'theta'?"), std::string::npos) << m;
  }
}

TEST(SceneValidation, WheelContactOnGround) {
  const std::string t = with("stiffness: 10, free_length: 0.5}",
                             "stiffness: 10, free_length: 0.5}\n"
                             "  - {name: tyre, type: wheel_contact, body: ground, stiffness: 1e5, radius: 0.3}");
  expect_one(t, line_of(t, "name: tyre"), "body", "a wheel contact needs a moving body, not ground");
}

TEST(SceneValidation, WheelContactOnLockedBody) {
  std::string t = with("stiffness: 10, free_length: 0.5}",
                       "stiffness: 10, free_length: 0.5}\n"
                       "  - {name: tyre, type: wheel_contact, body: bob, stiffness: 1e5, radius: 0.3}");
  t = with("theta: {initial_deg: 30}", "theta: {initial_deg: 30, mode: locked}", t);
  t = with("hold: [theta], release: [theta], unknowns: [spring.free_length]", "hold: []", t);
  expect_one(t, line_of(t, "name: tyre"), "body", "wheel contact on 'bob', which is fixed to ground");
}

TEST(SceneValidation, UnregisteredForceLaw) {
  const std::string t = with("stiffness: 10, free_length: 0.5}",
                             "stiffness: 10, free_length: 0.5}\n"
                             "  - {name: custom, type: user, body1: ground, body2: arm, law: no_such_law}");
  expect_one(t, line_of(t, "no_such_law"), "law", "no force law named 'no_such_law' is registered");
}

TEST(SceneValidation, ModelFileMissing) {
  const auto errors = errors_of("model: no_such_model.yaml\nanalysis: {type: assembly}\n");
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  expect_some(errors, kFile, 1, "model", "cannot read model file");
}

TEST(SceneValidation, ModelFileNotRegular) {
  const auto errors = errors_of("model: /dev/zero\nanalysis: {type: assembly}\n");
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  expect_some(errors, kFile, 1, "model", "not a regular file");
}

// ---- Several errors at once ----------------------------------------------------------------

TEST(SceneValidation, AllErrorsOfAFileAreReported) {
  std::string t = kValid;
  t = with("mass: 0.5", "mass: -2", t);                       // field check
  t = with("anchor: [0, 0, 1]", "anchor: [0, 0, .inf]", t);  // not finite
  t = with("anchor: tip", "anchor: tap", t);                 // unknown point
  t = with("coordinate: theta}", "coordinate: phi}", t);     // unknown coordinate
  t = with("2 * angle", "2 * angel", t);                     // expression name
  t = with("output: [angle, tip_z]", "output: [angle, tip_x]", t);
  t = with("rtol: 1.0e-6", "rtol: 5", t);
  t = with("t_end: 1.0", "t0: 3, t_end: 1.0", t);
  const auto errors = errors_of(t);
  expect_some(errors, kFile, line_of(t, "mass: -2"), "mass", "must be positive");
  expect_some(errors, kFile, line_of(t, ".inf"), "anchor", "not a finite number");
  expect_some(errors, kFile, line_of(t, "anchor: tap"), "anchor", "no point 'tap'");
  expect_some(errors, kFile, line_of(t, "coordinate: phi"), "coordinate", "no joint coordinate named 'phi'");
  expect_some(errors, kFile, line_of(t, "angel"), "expression", "unknown name 'angel'");
  expect_some(errors, kFile, line_of(t, "output:"), "output", "no sensor named 'tip_x'");
  expect_some(errors, kFile, line_of(t, "rtol: 5"), "rtol", "out of range");
  expect_some(errors, kFile, line_of(t, "t_end: 1.0"), "t_end", "time span is empty");
  EXPECT_EQ(errors.size(), 8u) << joined(errors);
  // Sorted by line.
  int last = 0;
  for (const auto& e : errors) {
    const int line = std::stoi(e.substr(std::string(kFile).size() + 1));
    EXPECT_GE(line, last) << joined(errors);
    last = line;
  }
}

// ---- The executable ------------------------------------------------------------------------

struct CliResult {
  int code = -1;
  std::string output;
};

CliResult run(const std::string& args) {
  const auto r = test_support::run_command(std::string("'") + MBDAE_EXE + "' " + args);
  return {r.code, r.output};
}

class Executable : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("mbdae_cli_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& text) {
    const fs::path p = dir / "scene.yaml";
    std::ofstream(p) << text;
    return p.string();
  }
};

TEST_F(Executable, CheckValidSceneExitsZero) {
  const CliResult r = run("check '" + write(kValid) + "'");
  EXPECT_EQ(r.code, 0) << r.output;
}

TEST_F(Executable, NegativeMassExitsTwo) {
  const std::string t = with("mass: 0.5", "mass: -0.5");
  const std::string path = write(t);
  const CliResult r = run("run '" + path + "' --out '" + (dir / "out").string() + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":" + std::to_string(line_of(t, "mass: -0.5")) + ": field 'mass': must be positive"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out" / "summary.json")) << "validation must come before any solve";
}

TEST_F(Executable, UnknownBodyExitsTwo) {
  const std::string t = with("body2: arm", "body2: leg");
  const std::string path = write(t);
  const CliResult r = run("check '" + path + "'");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":" + std::to_string(line_of(t, "body2: leg")) + ": field 'body2'"), std::string::npos)
      << r.output;
}

TEST_F(Executable, SeveralErrorsExitTwoWithAllMessages) {
  std::string t = with("mass: 0.5", "mass: 0");
  t = with("rtol: 1.0e-6", "rtol: 1", t);
  t = with("    parent: ground\n    child: arm\n", "    parent: bob\n    child: arm\n", t);
  const std::string path = write(t);
  const CliResult r = run("run '" + path + "' --out '" + (dir / "out").string() + "' --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  for (const std::string& needle :
       {path + ":" + std::to_string(line_of(t, "mass: 0\n")) + ": field 'mass'",
        path + ":" + std::to_string(line_of(t, "rtol: 1")) + ": field 'rtol'",
        path + ":" + std::to_string(line_of(t, "parent: bob")) + ": field 'parent': the joint tree has a loop"})
    EXPECT_NE(r.output.find(needle), std::string::npos) << needle << "\n" << r.output;
}

TEST_F(Executable, MissingFileExitsTwo) {
  const CliResult r = run("check '" + (dir / "nothing.yaml").string() + "'");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot read the file"), std::string::npos) << r.output;
}

// The diagnosis of a drive past the mechanism's travel and the assembly-mode warning reach the
// command line (docs/extreme-cases.md): on stderr, the same text as summary.json's.
TEST_F(Executable, DrivePastTheTravelSaysWhyOnStderr) {
  const std::string scene = std::string(MBDAE_SOURCE_DIR) + "/verification/studies/extreme/kinematics_past_travel.yaml";
  const CliResult r = run("run '" + scene + "' --out '" + (dir / "out").string() + "'");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("mbdae: the mechanism cannot reach q4 = -1.9291"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the constraint Jacobian becomes singular"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("last reached configuration"), std::string::npos) << r.output;
}

TEST_F(Executable, AssemblyModeWarningOnStderrAlsoWhenQuiet) {
  const std::string scene = std::string(MBDAE_SOURCE_DIR) + "/verification/studies/extreme/rough_guess_60deg_plus.yaml";
  const CliResult r = run("run '" + scene + "' --out '" + (dir / "out").string() + "' --quiet");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("mbdae: warning: assembly converged far from the guess"), std::string::npos) << r.output;
}

// An option's value that is itself an option is refused, naming what the option expects (the
// next word was taken as the value and the one after it refused as an unknown argument).
TEST_F(Executable, OptionValueThatIsAnOptionIsRefused) {
  const std::string scene = "run '" + write(kValid) + "'";
  const std::pair<std::string, std::string> cases[] = {
      {" --sensitivity --out d", "mbdae: --sensitivity: expects a parameter path, got '--out'"},
      {" --out --rtol 1e-6", "mbdae: --out: expects a folder, got '--rtol'"},
      {" --out d --rtol --quiet", "mbdae: --rtol: expects a number, got '--quiet'"},
      {" --out d --formulation --quiet", "mbdae: --formulation: expects a formulation, got '--quiet'"},
      {" --out d --error-target 1e-6 --error-sensors --quiet",
       "mbdae: --error-sensors: expects sensor names separated by commas, got '--quiet'"},
      {" --out d --animation-rate --quiet", "mbdae: --animation-rate: expects a number, got '--quiet'"},
  };
  for (const auto& [args, message] : cases) {
    const CliResult r = run(scene + args);
    EXPECT_EQ(r.code, 1) << args << "\n" << r.output;
    EXPECT_EQ(r.output.substr(0, r.output.find('\n')), message) << args << "\n" << r.output;
  }
  const CliResult negative = run(scene + " --out '" + (dir / "out").string() + "' --quiet --rtol -1e-6");
  EXPECT_NE(negative.output.find("mbdae: --rtol: out of range"), std::string::npos) << negative.output;
}

TEST_F(Executable, UsageErrorExitsOne) {
  EXPECT_EQ(run("").code, 1);
  EXPECT_EQ(run("run '" + write(kValid) + "'").code, 1);  // no --out
  EXPECT_EQ(run("run '" + write(kValid) + "' --out x --rtol 2").code, 1);
}

}  // namespace
}  // namespace mbdae
