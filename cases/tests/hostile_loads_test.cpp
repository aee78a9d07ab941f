// Issue 25, through the real executable: loads that fail cleanly (a load that turns NaN mid-run,
// one that grows without bound), scenes refused before the output folder is touched (a bad load
// expression, a load parameter named like a sensor, a torque on ground), and the messages of
// hostile files (deep nesting, NUL bytes) and of a full standard output. Each case asserts the
// exit code, the status, the message and that every file left is whole.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cases/tests/run_command.h"

namespace fs = std::filesystem;

namespace {

using mbdae::test_support::run_command;

std::string exe() { return std::string("'") + MBDAE_EXE + "'"; }

using mbdae::test_support::read_file;

// A crank (a disc on a revolute joint about z, no gravity) driven by `torque`, with a slider-crank
// loop: a rod from the crank pin to a slider on the x axis. Fast: 2 N m on J = 0.5 from 50 rad/s.
std::string slider_crank(const std::string& torque, const std::string& extra_forces = "",
                         const std::string& parameters = "", double t_end = 0.1) {
  std::ostringstream s;
  s << R"(name: slider_crank
gravity: [0, 0, 0]
bodies:
  - {name: crank, mass: 1.0, inertia: {xx: 0.3, yy: 0.3, zz: 0.5}, points: {pin: [0.1, 0, 0]}}
  - {name: rod, mass: 0.2, com: [0.2, 0, 0], inertia: {xx: 0.001, yy: 0.01, zz: 0.01}, points: {end: [0.4, 0, 0]}}
  - {name: slider, mass: 0.5, inertia: {xx: 0.01, yy: 0.01, zz: 0.01}}
joints:
  - {name: axle, parent: ground, child: crank, anchor: [0, 0, 0], chain: [R3], coordinates: [theta]}
  - {name: pin, parent: crank, child: rod, anchor: pin, chain: [R3], coordinates: [phi]}
  - {name: rail, parent: ground, child: slider, anchor: [0, 0, 0], chain: [T1], coordinates: [x]}
coordinates:
  theta: {initial: 0}
  phi: {initial: 0}
  x: {initial: 0.5}
cuts:
  - {name: wrist, type: revolute, body1: rod, point1: end, body2: slider, point2: origin, axis1: [0, 0, 1], axis2: [0, 0, 1]}
forces:
  - {name: motor, type: torque, body: crank, axis: [0, 0, 1], torque: ")"
    << torque << "\"" << (parameters.empty() ? "" : ", parameters: " + parameters) << "}\n"
    << extra_forces << R"(sensors:
  - {name: angle, type: coordinate, coordinate: theta}
  - {name: w, type: coordinate_rate, coordinate: theta}
  - {name: slide, type: position, body: slider, point: origin, component: x}
analysis:
  - {type: assembly, hold: [theta]}
  - {type: dynamics, t_end: )"
    << t_end << R"(, output_step: 0.001, initial_velocities: {theta: 50}}
)";
  return s.str();
}

class HostileLoads : public mbdae::test_support::RunFolderTest {
 protected:
  HostileLoads() : RunFolderTest("mbdae_hostile_") {}
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name, std::ios::binary) << text;
    return (dir / name).string();
  }
  mbdae::test_support::CommandResult run(const std::string& scene, const std::string& extra = "") {
    return run_command(exe() + " run '" + scene + "' --out '" + out.string() + "' --quiet " + extra);
  }
  // Every row of results.csv whole: the header's number of fields on every line, a final newline.
  size_t check_whole_csv(const fs::path& csv) {
    const std::string text = read_file(csv);
    EXPECT_FALSE(text.empty());
    if (text.empty()) return 0;
    EXPECT_EQ(text.back(), '\n') << "ends inside a row";
    std::istringstream in(text);
    std::string line;
    std::getline(in, line);
    const auto fields = std::count(line.begin(), line.end(), ',');
    size_t rows = 0;
    while (std::getline(in, line)) {
      EXPECT_EQ(std::count(line.begin(), line.end(), ','), fields) << line;
      ++rows;
    }
    return rows;
  }
  // A previous run's whole output: the next run that is refused must leave it as it was.
  void previous_run() {
    const auto r = run(write("good.yaml", slider_crank("2", "", "", 0.01)));
    ASSERT_EQ(r.code, 0) << r.output;
    ASSERT_TRUE(fs::exists(out / "summary.json"));
  }
  void expect_folder_unchanged(const std::string& summary, const std::string& csv) {
    EXPECT_EQ(read_file(out / "summary.json"), summary);
    EXPECT_EQ(read_file(out / "results.csv"), csv);
    EXPECT_FALSE(fs::exists(out / "results.csv.partial"));
  }
};

// sqrt(0.01 - t) turns NaN at t = 0.01: the run stops there with exit 3, status non_finite,
// naming the load, the time and the value; the rows before it are whole and the summary says so.
TEST_F(HostileLoads, LoadTurningNaNMidRunStopsAtOnce) {
  for (const char* expr : {"sqrt(0.01 - t)", "log(0.01 - t) + 2", "100 * asin(100 * t)"}) {
    SCOPED_TRACE(expr);
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = run(write("nan.yaml", slider_crank(expr)));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_LT(seconds, 30);
    EXPECT_NE(r.output.find("load 'motor' (torque = " + std::string(expr) + ")"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("is NaN at t = 0.01"), std::string::npos) << r.output;
    const auto summary = nlohmann::json::parse(read_file(out / "summary.json"));
    EXPECT_EQ(summary["status"], "non_finite");
    const fs::path csv = fs::exists(out / "results.csv") ? out / "results.csv" : out / "results.csv.partial";
    const size_t rows = check_whole_csv(csv);
    EXPECT_GE(rows, 9u);   // t = 0 ... 0.009 at least
    EXPECT_LE(rows, 11u);  // nothing past t = 0.01
  }
}

// exp(1000 t) overflows at t = 0.71 but makes the crank spin ever faster long before: the run
// ends in bounded time with a clear message (the stall watch or the load's overflow), exit 3.
TEST_F(HostileLoads, LoadGrowingWithoutBoundEndsInBoundedTime) {
  const auto t0 = std::chrono::steady_clock::now();
  // The default budget (1e8 steps) stops it after 2e5 steps (20 s on a loaded machine); a budget
  // of 1e6, given in the scene, keeps the test cheap.
  std::string text = slider_crank("exp(1000 * t)", "", "", 1.0);
  text.replace(text.find("initial_velocities"), 0, "max_steps: 1000000, ");
  const auto r = run(write("exp.yaml", text));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_LT(seconds, 120);
  const auto summary = nlohmann::json::parse(read_file(out / "summary.json"));
  const std::string status = summary["status"];
  EXPECT_TRUE(status == "step_limit" || status == "non_finite") << status;
  EXPECT_NE(r.output.find(status == "step_limit" ? "more than max_steps = 1e+06" : "t = "), std::string::npos)
      << r.output;
  const fs::path csv = fs::exists(out / "results.csv") ? out / "results.csv" : out / "results.csv.partial";
  EXPECT_GT(check_whole_csv(csv), 5u);
  RecordProperty("seconds", std::to_string(seconds));
  RecordProperty("end_status", status);
}

// A scene refused for its loads exits 2 and leaves the previous run's files as they were (and no
// lock file claims it): a bad expression, a parameter named like a sensor, a torque on ground, a
// point force on a body welded to ground, a load reading a sensor it may not read.
TEST_F(HostileLoads, RefusedLoadsLeaveTheFolderAsItWas) {
  previous_run();
  const std::string summary = read_file(out / "summary.json"), csv = read_file(out / "results.csv");
  struct Case {
    std::string scene, line, field, words;
  };
  const std::string bolt =
      "  - {name: kick, type: point_force, body: ground, point: origin, fx: 1}\n";
  const Case cases[] = {
      {slider_crank("2 * (w +"), ":18:", "torque", "expected"},
      {slider_crank("2 * speed"), ":18:", "torque", "unknown name 'speed'"},
      {slider_crank("2 * w", "", "{w: 3}"), ":18:", "parameters.w", "has the name of a sensor"},
      {slider_crank("2", bolt), ":19:", "body", "on ground does nothing"},
      {slider_crank("2", "  - {name: spin, type: torque, body: ground, axis: [0, 0, 1], torque: 1}\n"), ":19:", "body",
       "a torque on ground does nothing"},
  };
  for (const Case& c : cases) {
    const auto r = run(write("bad.yaml", c.scene));
    SCOPED_TRACE(c.words);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("bad.yaml" + c.line + " field '" + c.field + "'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    expect_folder_unchanged(summary, csv);
    // `mbdae check` says the same.
    const auto chk = run_command(exe() + " check '" + (dir / "bad.yaml").string() + "'");
    EXPECT_EQ(chk.code, 2) << chk.output;
  }
}

// Redundant constraints with `redundant_constraints: fail` are refused (exit 2) before the
// folder is touched too: every check of the system comes before the folder.
TEST_F(HostileLoads, SystemChecksComeBeforeTheFolder) {
  previous_run();
  const std::string summary = read_file(out / "summary.json"), csv = read_file(out / "results.csv");
  std::string text = slider_crank("2");
  text.replace(text.find("cuts:"), 5,
               "redundant_constraints: fail\ncuts:\n  - {name: again, type: revolute, body1: rod, point1: end, body2: "
               "slider, point2: origin, axis1: [0, 0, 1], axis2: [0, 0, 1]}");
  const auto r = run(write("redundant.yaml", text));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("redundant"), std::string::npos) << r.output;
  expect_folder_unchanged(summary, csv);
}

// Deeply nested YAML and NUL bytes: exit 2 with the file and the line.
TEST_F(HostileLoads, HostileYamlMessagesNameTheLine) {
  std::string deep = "name: deep\nbodies: ";
  for (int k = 0; k < 20000; ++k) deep += "[";
  const auto r1 = run_command(exe() + " check '" + write("deep.yaml", deep + "\n") + "'");
  EXPECT_EQ(r1.code, 2) << r1.output;
  EXPECT_NE(r1.output.find("deep.yaml:2:"), std::string::npos) << r1.output;
  EXPECT_EQ(r1.output.find("bad file"), std::string::npos) << r1.output;

  std::string nul = slider_crank("2");
  const size_t line5 = [&] {
    size_t p = 0;
    for (int k = 0; k < 4; ++k) p = nul.find('\n', p) + 1;
    return p;
  }();
  nul.insert(line5 + 10, std::string(1, '\0'));
  const auto r2 = run_command(exe() + " check '" + write("nul.yaml", nul) + "'");
  EXPECT_EQ(r2.code, 2) << r2.output;
  EXPECT_NE(r2.output.find("nul.yaml:5:"), std::string::npos) << r2.output;
}

// Standard output on a full device: `check` and `run` exit 4 and say so (they exited 0).
TEST_F(HostileLoads, FullStandardOutputIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string scene = write("good.yaml", slider_crank("2", "", "", 0.01));
  const auto chk = run_command(exe() + " check '" + scene + "' > /dev/full");
  EXPECT_EQ(chk.code, 4) << chk.output;
  EXPECT_NE(chk.output.find("cannot write to standard output"), std::string::npos) << chk.output;
  const auto r = run_command(exe() + " run '" + scene + "' --out '" + out.string() + "' > /dev/full");
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_NE(r.output.find("cannot write to standard output"), std::string::npos) << r.output;
  EXPECT_GT(check_whole_csv(out / "results.csv"), 5u);  // the files themselves are whole
}

}  // namespace
