// The error estimate and the error target through the executable and the API
// (cases/error_estimate.h, cases/error_target.h): bad option values rejected before the output
// folder is claimed, the summary's keys and the warning, accuracy_not_met, and interrupts that
// end `interrupted` (130/143) with the run's rows kept.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/run/error_estimate.h"
#include "cases/run/error_target.h"
#include "cases/tests/run_command.h"

namespace fs = std::filesystem;

namespace mbdae {
namespace {

std::string exe() { return std::string("'") + MBDAE_EXE + "'"; }
std::string source(const std::string& p) { return std::string(MBDAE_SOURCE_DIR) + "/" + p; }
const std::string kFast = "verification/fast_mechanism/slider_crank_fast.yaml";
const std::string kStep = "cases/five_point_suspension/dynamics_step.yaml";

test_support::CommandResult shell(const std::string& cmd) { return test_support::run_command(cmd); }

using test_support::read_file;

class ErrorControlCli : public ::testing::Test {
 protected:
  fs::path out;
  void SetUp() override {
    out = fs::temp_directory_path() / ("mbdae_error_control_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out);
  }
  void TearDown() override { fs::remove_all(out); }
  test_support::CommandResult mbdae_run(const std::string& scene, const std::string& args) {
    return shell(exe() + " run '" + source(scene) + "' --out '" + out.string() + "' --quiet " + args);
  }
};

TEST_F(ErrorControlCli, BadValuesAreRejectedBeforeTheFolderIsClaimed) {
  const std::pair<std::string, std::string> cases[] = {
      {"--error-target -1", "--error-target: must be a positive error in the sensors' units, got '-1'"},
      {"--error-target 0", "--error-target: must be a positive error"},
      {"--error-target nan", "--error-target: 'nan' is not a finite number"},
      {"--error-target tight", "--error-target: expected a number, got 'tight'"},
      {"--error-target 1e-6 --error-sensors wheel_z,", "--error-sensors: expected sensor names separated by commas"},
      {"--error-sensors wheel_z", "--error-sensors: needs --error-target E"},
      {"--error-target 1e-6 --error-sensors wheel_zz", "--error-sensors: no output sensor named 'wheel_zz'; did you mean 'wheel_z'?"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = mbdae_run(kStep, args);
    EXPECT_EQ(r.code, 1) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << "\n" << r.output;
    EXPECT_FALSE(fs::exists(out)) << args << ": the output folder was claimed";
  }
}

// The scene's fields, read through the loader (the CLI exits 2 with these messages).
TEST(ErrorControlScene, FieldsAreChecked) {
  const std::string text = read_file(source(kStep));
  for (const auto& [field, message] : std::vector<std::pair<std::string, std::string>>{
           {"error_target: -1", "field 'error_target': must be a positive error in the sensors' units, got -1"},
           {"error_target: .nan", "field 'error_target'"},
           {"error_target: 1e-6, error_sensors: [whel_z]", "field 'error_sensors': no sensor named 'whel_z'; did you mean 'wheel_z'?"},
           {"error_sensors: [wheel_z]", "field 'error_target': missing"}}) {
    std::string t = text;
    const size_t at = t.find("type: dynamics,");
    ASSERT_NE(at, std::string::npos);
    t.insert(at + std::string("type: dynamics,").size(), " " + field + ",");
    try {
      load_scene_text(t, source(kStep));
      ADD_FAILURE() << field << ": accepted";
    } catch (const SceneError& e) {
      std::string all;
      for (const auto& m : e.messages) all += m + "\n";
      EXPECT_NE(all.find(message), std::string::npos) << field << "\n" << all;
    }
  }
  std::string t = text;
  t.insert(t.find("type: dynamics,") + 15, " error_target: 1e-7, error_sensors: [wheel_z],");
  const Scene scene = load_scene_text(t, source(kStep));
  const ErrorControl c = error_control(scene, ErrorControl{});
  EXPECT_DOUBLE_EQ(c.target, 1e-7);
  EXPECT_EQ(c.sensors, std::vector<std::string>{"wheel_z"});
}

// index3-positions (local errors per step) misses the promise on the fast mechanism at rtol 1e-6
// (1.5e4 to 2.6e4 rtol; index2-ggl keeps it since issue 21's error per unit of the span): the
// summary keeps error, scale, relative and exceeded per sensor, and stderr warns.
TEST_F(ErrorControlCli, EstimateReportsAndWarns) {
  const auto r = mbdae_run(kFast, "--formulation index3-positions --error-estimate");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("mbdae: warning: sensor pin_y: estimated global error"), std::string::npos) << r.output;
  const auto s = nlohmann::json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(s["status"], "ok");
  const auto& e = s["error_estimate"];
  EXPECT_EQ(e["method"], "tolerance_proportionality");
  EXPECT_EQ(e["comparison"]["status"], "ok");
  EXPECT_NEAR(e["comparison"]["rtol"].get<double>(), 1e-6 / 3, 1e-20);
  for (const auto& [name, v] : e["sensors"].items()) {
    EXPECT_GT(v["error"].get<double>(), 0) << name;
    EXPECT_DOUBLE_EQ(v["relative"].get<double>(), v["error"].get<double>() / v["scale"].get<double>()) << name;
    EXPECT_TRUE(v["exceeded"].get<bool>()) << name;
  }
  EXPECT_TRUE(e["constraints"]["position"].contains("relative"));
}

// index3's rounding floor on the fast mechanism (about 1e-6 of the scale from rtol 1e-8 on, this
// build): 1e-11 cannot be had; the second try (rtol 1e-13) does not halve the estimate.
TEST_F(ErrorControlCli, UnreachableTargetEndsAccuracyNotMet) {
  const auto r = mbdae_run(kFast, "--error-target 1e-11");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("error target 1e-11 not met"), std::string::npos) << r.output;
  const auto s = nlohmann::json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(s["status"], "accuracy_not_met");
  EXPECT_FALSE(s["error_target"]["met"].get<bool>());
  EXPECT_GE(s["error_target"]["tries"].size(), 2u);
  EXPECT_LE(s["error_target"]["tries"].size(), static_cast<size_t>(kErrorTargetMaxTries));
  for (const auto& t : s["error_target"]["tries"]) EXPECT_GT(t["cpu_seconds"]["run"].get<double>(), 0);
  EXPECT_TRUE(fs::exists(out / "results.csv"));  // the last try's rows
}

// SIGTERM while a run with an estimate goes on: exit 143, `interrupted`, whole rows. At rtol 1e-8
// (index2-ggl, about 4 s with its estimate here): at the scene's tolerances the run and its
// estimate took 1.8 s of wall time on 2026-11-27's machine and ended before the signal.
TEST_F(ErrorControlCli, SigtermDuringAnEstimateEndsInterrupted) {
  const auto r = shell("(" + exe() + " run '" + source("cases/five_point_suspension/dynamics_poster.yaml") +
                       "' --out '" + out.string() + "' --quiet --rtol 1e-8 --error-estimate & pid=$!; sleep 1.5; "
                       "kill -TERM $pid; "
                       "wait $pid; echo exit=$?)");
  EXPECT_NE(r.output.find("exit=143"), std::string::npos) << r.output;
  const auto s = nlohmann::json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(s["status"], "interrupted");
  const std::string csv = read_file(out / "results.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
}

// A stop request after the run itself has finished, while its estimate is not complete: the
// result is `interrupted` (not ok), with every row of the run.
struct StopAtEnd : Sink {
  std::atomic<bool>* stop;
  explicit StopAtEnd(std::atomic<bool>* s) : stop(s) {}
  void end(const Result&) override { *stop = true; }
};

TEST(ErrorEstimateApi, StopAfterTheRunEndsInterruptedWithItsRows) {
  const Scene scene = load_scene(source(kFast));
  std::atomic<bool> stop{false};
  RunOptions o;
  o.stop = &stop;
  StopAtEnd sink(&stop);
  ErrorEstimate e;
  const Result r = run_estimated(scene, o, {&sink}, e);
  EXPECT_EQ(r.status, "interrupted");
  EXPECT_EQ(r.summary["status"], "interrupted");
  EXPECT_EQ(r.rows(), 201u);  // t in [0, 0.02] every 1e-4 s: the whole run
  EXPECT_FALSE(r.summary.contains("error_estimate"));
}

// A run whose rtol / 3 leaves rtol's range (1e-14) is compared at 3 rtol instead, labelled.
TEST(ErrorEstimateApi, ClampedComparisonToleranceIsLabelled) {
  const Scene scene = load_scene(source(kFast));
  RunOptions o;
  o.rtol = 1e-14;
  o.formulation = "index2-ggl";
  const Result r = run(scene, o);
  ASSERT_TRUE(r.ok()) << r.message;
  const ErrorEstimate e = estimate_global_error(scene, o, r);
  EXPECT_NEAR(e.comparison_rtol, 3e-14, 1e-27);
  EXPECT_NEAR(e.factor, 3.0, 1e-12);
  EXPECT_NEAR(e.to_json()["factor"].get<double>(), 3.0, 1e-12);
  EXPECT_NEAR(e.to_json()["comparison"]["rtol"].get<double>(), 3e-14, 1e-27);
}

// The scene run with `formulation` at `rtol`, expected to succeed.
Result run_with(const Scene& scene, const char* formulation, double rtol) {
  RunOptions o;
  o.rtol = rtol;
  o.formulation = formulation;
  Result r = run(scene, o);
  EXPECT_TRUE(r.ok()) << r.message;
  return r;
}

// The last step of the scene run with `formulation` at `rtol`, and the summary's notes (none: []).
std::pair<nlohmann::ordered_json, nlohmann::ordered_json> last_step_and_notes(const Scene& scene, const char* formulation,
                                                                              double rtol) {
  const Result r = run_with(scene, formulation, rtol);
  return {r.summary["steps"].back(), r.summary.value("notes", nlohmann::ordered_json::array())};
}

// The fast mechanism: index3's position tolerance sits at the rounding floor from about rtol
// 1e-7 on (docs/formulation.md, "Index 3 at tight tolerances"); the run says so in a note. At
// rtol 1e-4 it does not, nor does index2-ggl at 1e-8 (its floor is at about 1e-10).
TEST(ErrorControlNotes, RoundingFloorIsNoted) {
  const Scene scene = load_scene(source(kFast));
  auto notes = [&](const char* formulation, double rtol) {
    const Result r = run_with(scene, formulation, rtol);
    const double fraction = r.summary["steps"].back()["statistics"]["rounding_floor_fraction"].get<double>();
    return std::make_pair(r.summary.contains("notes") ? r.summary["notes"].size() : 0u, fraction);
  };
  const auto tight = notes("index3-no-handover", 1e-9);
  EXPECT_EQ(tight.first, 1u);
  EXPECT_GT(tight.second, 0.5);
  const auto loose = notes("index3", 1e-4);
  EXPECT_EQ(loose.first, 0u);
  EXPECT_LT(loose.second, 0.5);
  EXPECT_EQ(notes("index2-ggl", 1e-8).first, 0u);
}

// Below rtol 1e-6 a dynamics step's index3 runs as index2-ggl (formulation_registry.h): the step
// names the formulation asked and the one that ran, and the summary says why. At 1e-6, and at a
// scene's own fixed tolerances, index3 runs as asked; index3-no-handover keeps it at every rtol.
TEST(ErrorControlNotes, Index3HandsOverBelowOneMillionth) {
  const Scene scene = load_scene(source(kFast));
  auto step_of = [&](const char* formulation, double rtol) { return last_step_and_notes(scene, formulation, rtol); };
  const auto [tight, tight_notes] = step_of("index3", 1e-8);
  EXPECT_EQ(tight["formulation"], "index2-ggl");
  EXPECT_EQ(tight["formulation_asked"], "index3");
  ASSERT_EQ(tight_notes.size(), 1u);
  EXPECT_NE(tight_notes[0].get<std::string>().find("index3 runs as index2-ggl below rtol 1e-06"), std::string::npos);
  const auto [at, at_notes] = step_of("index3", 1e-6);
  EXPECT_EQ(at["formulation"], "index3");
  EXPECT_FALSE(at.contains("formulation_asked"));
  EXPECT_EQ(step_of("index3-no-handover", 1e-8).first["formulation"], "index3-no-handover");
  Scene fixed = scene;  // the scene's own tight tolerances
  fixed.steps.back().rtol = 1e-8;
  fixed.steps.back().atol = 1e-10;
  RunOptions o;
  const Result r = run(fixed, o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.summary["steps"].back()["formulation"], "index3");
}

// index1 hands over below rtol 1e-9, where its error stops at the velocities' rounding floor
// (docs/formulation.md); index1-no-handover keeps index1.
TEST(ErrorControlNotes, Index1HandsOverBelowOneBillionth) {
  const Scene scene = load_scene(source(kFast));
  auto step_of = [&](const char* formulation, double rtol) { return last_step_and_notes(scene, formulation, rtol); };
  const auto [tight, tight_notes] = step_of("index1", 1e-10);
  EXPECT_EQ(tight["formulation"], "index2-ggl");
  EXPECT_EQ(tight["formulation_asked"], "index1");
  ASSERT_FALSE(tight_notes.empty());
  EXPECT_NE(tight_notes[0].get<std::string>().find("index1 runs as index2-ggl below rtol 1e-09"), std::string::npos);
  EXPECT_NE(tight_notes[0].get<std::string>().find("index1-no-handover keeps index1"), std::string::npos);
  const auto [at, at_notes] = step_of("index1", 1e-9);
  EXPECT_EQ(at["formulation"], "index1");
  EXPECT_FALSE(at.contains("formulation_asked"));
  EXPECT_EQ(step_of("index1-no-handover", 1e-10).first["formulation"], "index1-no-handover");
}

}  // namespace
}  // namespace mbdae
