// Scene loading at hostile sizes and shapes: linear time in the number of names, the file size
// limit and its MBDAE_MAX_SCENE_MB setting, a second YAML document, running out of memory.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cases/scene/scene.h"
#include "cases/tests/run_command.h"
#include "formulation/system.h"

namespace fs = std::filesystem;

namespace mbdae {
namespace {

// A chain of `bodies` pendulum links and `sensors` position sensors.
std::string big_scene(int bodies, int sensors) {
  std::ostringstream s;
  s << "name: big\nbodies:\n";
  for (int i = 0; i < bodies; ++i)
    s << "  - {name: b" << i << ", mass: 1.0, com: [0, 0, 0], inertia: {xx: 0.1, yy: 0.1, zz: 0.1}}\n";
  s << "joints:\n";
  for (int i = 0; i < bodies; ++i)
    s << "  - {name: j" << i << ", parent: " << (i ? "b" + std::to_string(i - 1) : std::string("ground")) << ", child: b"
      << i << ", anchor: [0, 0, 0], chain: [R2], coordinates: [q" << i << "]}\n";
  s << "coordinates:\n";
  for (int i = 0; i < bodies; ++i) s << "  q" << i << ": {initial: 0}\n";
  s << "sensors:\n";
  for (int i = 0; i < sensors; ++i) s << "  - {name: s" << i << ", type: position, body: b0, component: z}\n";
  s << "  - {name: last, type: expression, expression: \"s0 + s" << sensors - 1 << "\"}\n";
  s << "analysis:\n  - {type: assembly}\n";
  return s.str();
}

double cpu_seconds_to_check(const std::string& text) {
  const std::clock_t c0 = std::clock();
  const Scene scene = load_scene_text(text, "big.yaml");
  const System sys = build_system(scene.model);
  EXPECT_EQ(sys.sensors.size(), 100001u);
  return double(std::clock() - c0) / CLOCKS_PER_SEC;
}

// 100000 sensors: with the quadratic name lookups this took over 120 s (and 32000 took 9.6 s);
// linear, it takes about 2 s of CPU time. The bound (CPU time, not wall clock) leaves a wide
// margin for a slow machine and still fails a quadratic pass.
TEST(LoaderLimits, ManySensorsLoadInLinearTime) {
  const double cpu = cpu_seconds_to_check(big_scene(1, 100000));
  EXPECT_LT(cpu, 20.0);
  std::printf("100000 sensors: %.2f s CPU to load, validate and build\n", cpu);
}

TEST(LoaderLimits, SecondYamlDocumentRefused) {
  const std::string one = big_scene(1, 1);
  EXPECT_NO_THROW(load_scene_text("---\n" + one, "one.yaml"));  // an explicit start is one document
  EXPECT_NO_THROW(load_scene_text("# a comment\n%YAML 1.2\n---\n" + one + "...\n# the end\n", "one.yaml"));
  // Content after an end marker is a second document too.
  try {
    load_scene_text(one + "...\nname: other\n", "end.yaml");
    FAIL() << "content after '...' was accepted";
  } catch (const SceneError& e) {
    ASSERT_EQ(e.messages.size(), 1u);
    EXPECT_NE(e.messages[0].find("a second YAML document"), std::string::npos) << e.messages[0];
  }
  try {
    load_scene_text(one + "---\nname: other\n", "two.yaml");
    FAIL() << "a second document was accepted";
  } catch (const SceneError& e) {
    ASSERT_EQ(e.messages.size(), 1u);
    const int line = 1 + static_cast<int>(std::count(one.begin(), one.end(), '\n'));
    EXPECT_EQ(e.messages[0], "two.yaml:" + std::to_string(line) +
                                 ": a second YAML document ('---') is not read; a scene or model file holds one document");
  }
}

// yaml-cpp 0.7's LoadAll never returned on a file holding a lone ',' (the fuzz target's timeout
// artifact, 305 bytes, hung `mbdae check` for minutes at 2 GB): now a syntax error at once.
TEST(LoaderLimits, InvalidYamlThatHungTheParserIsASyntaxError) {
  for (const std::string text : {",", ",\n", "# comment\n,\n"}) {
    const std::clock_t c0 = std::clock();
    try {
      load_scene_text(text, "comma.yaml");
      FAIL() << "accepted: " << text;
    } catch (const SceneError& e) {
      ASSERT_EQ(e.messages.size(), 1u);
      EXPECT_NE(e.messages[0].find("YAML syntax error: no YAML value could be read from ','"), std::string::npos)
          << e.messages[0];
    }
    EXPECT_LT(double(std::clock() - c0) / CLOCKS_PER_SEC, 1.0);
  }
}

class LoaderFiles : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() / ("mbdae_limits_" + std::to_string(::getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override {
    unsetenv("MBDAE_MAX_SCENE_MB");
    fs::remove_all(dir);
  }
};

// The 16 MB default refuses a 17 MB scene; MBDAE_MAX_SCENE_MB=32 reads it.
TEST_F(LoaderFiles, FileSizeLimitConfigurable) {
  std::string text = big_scene(2, 2);
  text += "# " + std::string(17u << 20, 'x') + "\n";
  const fs::path p = dir / "large.yaml";
  std::ofstream(p) << text;
  try {
    load_scene(p.string());
    FAIL() << "a 17 MB file was read under the 16 MB default";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.messages.at(0), p.string() + ": cannot read the file (larger than 16 MB; set MBDAE_MAX_SCENE_MB to read larger files)");
  }
  setenv("MBDAE_MAX_SCENE_MB", "32", 1);
  EXPECT_EQ(load_scene(p.string()).model.bodies.size(), 2u);
  setenv("MBDAE_MAX_SCENE_MB", "lots", 1);
  try {
    load_scene(p.string());
    FAIL() << "a bad MBDAE_MAX_SCENE_MB was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(e.messages.at(0).find("MBDAE_MAX_SCENE_MB must be a positive number of megabytes, got 'lots'"),
              std::string::npos);
  }
}

// Out of memory is its own exit code (4) and message, in `check` and in `run`.
TEST_F(LoaderFiles, OutOfMemoryExitCode) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than ulimit -v allows";
#endif
  const fs::path p = dir / "bodies.yaml";
  std::ofstream(p) << big_scene(30000, 1);
  for (const std::string& command : {"check '" + p.string() + "'", "run '" + p.string() + "' --out '" + (dir / "out").string() + "' --quiet"}) {
    const auto r = test_support::run_command("ulimit -v 300000; exec '" + std::string(MBDAE_EXE) + "' " + command);
    EXPECT_EQ(r.code, 4) << r.output;
    EXPECT_NE(r.output.find("mbdae: out of memory"), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace mbdae
