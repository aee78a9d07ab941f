// No global mutable state: the suspension's Dynamics I (equilibrium, then the ground step with
// tyre lift-off and re-contact) run in 4 threads at once gives each thread the single-threaded
// Result bit for bit. Two threads share one Scene, two load their own. Also built with
// ThreadSanitizer (-DMBDAE_TSAN=ON, .ci/run). The same with results.csv written by each thread,
// each file with its own repair process (core/output_guard.h, whose list of ended processes is
// the one state shared between runs).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "cases/mbdae.h"
#include "cases/output/sinks.h"

namespace mbdae {
namespace {

const std::string kScene = std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/dynamics_step.yaml";

RunOptions quiet() {
  RunOptions o;
  o.verbose = false;
  o.progress = false;
  return o;
}

// The summary without its CPU times (the only entries that may differ between runs).
nlohmann::ordered_json without_cpu(nlohmann::ordered_json j) {
  if (j.is_object()) {
    j.erase("cpu_seconds");
    for (auto& [k, v] : j.items()) v = without_cpu(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_cpu(v);
  }
  return j;
}

TEST(Threads, FourDynamicsRunsAtOnceEqualTheSingleThreadedRun) {
  const Scene shared = load_scene(kScene);
  const Result reference = run(shared, quiet());
  ASSERT_TRUE(reference.ok()) << reference.message;
  ASSERT_GT(reference.rows(), 1000u);  // 1.5 s at 1 ms
  std::vector<Result> results(4);
  std::vector<std::thread> threads;
  for (int k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      if (k < 2) {
        results[k] = run(shared, quiet());
      } else {
        const Scene own = load_scene(kScene);
        results[k] = run(own, quiet());
      }
    });
  for (auto& t : threads) t.join();
  for (int k = 0; k < 4; ++k) {
    const Result& r = results[k];
    ASSERT_TRUE(r.ok()) << "thread " << k << ": " << r.message;
    EXPECT_EQ(r.columns, reference.columns);
    ASSERT_EQ(r.data.size(), reference.data.size());
    for (size_t c = 0; c < r.data.size(); ++c)
      EXPECT_TRUE(r.data[c] == reference.data[c]) << "thread " << k << ", column " << r.columns[c];
    EXPECT_TRUE(r.q == reference.q) << "thread " << k;
    EXPECT_EQ(without_cpu(r.summary), without_cpu(reference.summary)) << "thread " << k;
  }
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Threads, FourCsvFilesAtOnceEqualTheSingleThreadedFile) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("mbdae_threads_csv_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Scene scene = load_scene(kScene);
  {
    CsvSink csv((dir / "reference.csv").string());
    ASSERT_TRUE(run(scene, quiet(), {&csv}).ok());
  }
  const std::string reference = read_text(dir / "reference.csv");
  ASSERT_GT(reference.size(), 50000u);  // page-crossing writes: each run starts its repair process
  std::vector<std::thread> threads;
  std::vector<int> ok(4, 0);
  for (int k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      CsvSink csv((dir / ("thread" + std::to_string(k) + ".csv")).string());
      ok[k] = run(scene, quiet(), {&csv}).ok();
    });
  for (auto& t : threads) t.join();
  for (int k = 0; k < 4; ++k) {
    EXPECT_TRUE(ok[k]) << "thread " << k;
    EXPECT_TRUE(read_text(dir / ("thread" + std::to_string(k) + ".csv")) == reference) << "thread " << k;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mbdae
