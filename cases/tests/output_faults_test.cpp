// Faults around a run's output, through the real executable: a file size limit, a file system
// that fills, folders in the way, two runs into one folder, SIGTERM and SIGKILL during a run,
// command-line overrides out of range, names that need CSV quoting. After each fault the files
// are parsed: whole rows only, valid JSON, and never "ok" or exit 0 over an incomplete file.
#include <gtest/gtest.h>

#include <algorithm>

#include <fcntl.h>
#include <sys/file.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/tests/run_command.h"

namespace fs = std::filesystem;

namespace {

// A free pendulum: it swings for the whole (long) run, 3 columns per row, one of them quoted.
const char* kSwing = R"(name: swing
bodies:
  - name: arm
    mass: 1.0
    com: [0.5, 0, 0]
    inertia: {xx: 0.01, yy: 0.1, zz: 0.1}
joints:
  - {name: pivot, parent: ground, child: arm, anchor: [0, 0, 1], chain: [R2], coordinates: [theta]}
coordinates:
  theta: {initial_deg: 30}
sensors:
  - {name: angle, type: coordinate, coordinate: theta}
  - {name: 'a,b"c', type: coordinate_rate, coordinate: theta}
analysis:
  - {type: dynamics, t_end: T_END, output_step: 0.001}
)";

using CliResult = mbdae::test_support::CommandResult;
CliResult shell(const std::string& cmd) { return mbdae::test_support::run_command(cmd); }

std::string sh_quote(const fs::path& p) { return "'" + p.string() + "'"; }
std::string exe() { return std::string("'") + MBDAE_EXE + "'"; }

using mbdae::test_support::read_file;

// The rows of a CSV written by mbdae: every line ends with '\n', the header is the expected one
// and every row has three numbers with increasing times. Returns the number of rows.
long check_whole_rows(const fs::path& csv) {
  const std::string text = read_file(csv);
  EXPECT_FALSE(text.empty()) << csv;
  if (text.empty()) return 0;
  EXPECT_EQ(text.back(), '\n') << csv << " ends inside a row";
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, R"(t,angle,"a,b""c")");
  long rows = 0;
  double last_t = -1;
  while (std::getline(in, line)) {
    double v[3];
    char* p = line.data();
    for (int k = 0; k < 3; ++k) {
      char* end = nullptr;
      v[k] = std::strtod(p, &end);
      const char expected = k < 2 ? ',' : '\0';
      if (end == p || *end != expected) {
        ADD_FAILURE() << csv << ": row " << rows + 1 << " is not whole: '" << line << "'";
        return rows;
      }
      p = end + (k < 2 ? 1 : 0);
    }
    EXPECT_GT(v[0], last_t) << line;
    last_t = v[0];
    ++rows;
  }
  return rows;
}

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(read_file(p)); }

class OutputFaults : public mbdae::test_support::RunFolderTest {
 protected:
  OutputFaults() : RunFolderTest("mbdae_faults_") {}
  // The swinging pendulum over [0, t_end]; returns the scene's path.
  std::string scene(const std::string& t_end, const std::string& name = "swing.yaml") {
    std::string text = kSwing;
    text.replace(text.find("T_END"), 5, t_end);
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
  // Starts `mbdae run SCENE --out OUT --quiet` in the background (with `--sensitivity PATH` if
  // given); stderr to dir/NAME.log.
  pid_t start(const std::string& scene_path, const std::string& log, const char* sensitivity = nullptr) {
    const pid_t pid = fork();
    if (pid == 0) {
      const int fd = ::open((dir / log).c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      if (sensitivity)
        execl(MBDAE_EXE, MBDAE_EXE, "run", scene_path.c_str(), "--out", out.c_str(), "--quiet", "--sensitivity",
              sensitivity, (char*)nullptr);
      else
        execl(MBDAE_EXE, MBDAE_EXE, "run", scene_path.c_str(), "--out", out.c_str(), "--quiet", (char*)nullptr);
      _exit(127);
    }
    return pid;
  }
  // Waits until the run has written at least `bytes` of rows.
  // Waits (up to 120 s: the sanitizer build on a loaded machine is slow) until the run `pid` has
  // written `bytes` of rows. On a timeout the run is killed and reaped, so that no run is left
  // behind by a failed test.
  bool wait_for_rows(pid_t pid, size_t bytes) {
    const fs::path partial = out / "results.csv.partial";
    for (int k = 0; k < 12000; ++k) {
      std::error_code ec;
      if (fs::exists(partial, ec) && fs::file_size(partial, ec) >= bytes) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    return false;
  }
  // SIGKILLs run `pid` and waits until the repair of `partial` (cut back to whole rows) is done:
  // a reader's flock waits for it (core/output_guard.h).
  void kill_and_wait_for_repair(pid_t pid, const fs::path& partial) {
    kill(pid, SIGKILL);
    int sig = 0;
    wait_exit(pid, &sig);
    EXPECT_EQ(sig, SIGKILL);
    const int reader = ::open(partial.c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(reader, 0);
    EXPECT_EQ(::flock(reader, LOCK_SH), 0);
    ::close(reader);
  }
  static int wait_exit(pid_t pid, int* signal = nullptr) {
    int status = 0;
    waitpid(pid, &status, 0);
    if (signal) *signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

// ulimit -f: the write fails with EFBIG (SIGXFSZ is ignored), exit 4, the file keeps whole rows
// and its .partial name, the summary says output_failed.
TEST_F(OutputFaults, FileSizeLimit) {
  const CliResult r =
      shell("ulimit -f 100; exec " + exe() + " run " + sh_quote(scene("10")) + " --out " + sh_quote(out) + " --quiet");
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_NE(r.output.find("results.csv.partial: File too large"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
  const long rows = check_whole_rows(out / "results.csv.partial");
  EXPECT_GT(rows, 1000);
  EXPECT_LE(fs::file_size(out / "results.csv.partial"), 100u * 1024u);
  const auto summary = read_json(out / "summary.json");
  EXPECT_EQ(summary["status"], "output_failed");
  EXPECT_NE(summary["message"].get<std::string>().find("File too large"), std::string::npos);
}

// A file system that fills, by the output layer's injection hook (MBDAE_OUTPUT_FAULT_BYTES).
TEST_F(OutputFaults, FullFileSystemByInjection) {
  const CliResult r = shell("MBDAE_OUTPUT_FAULT_BYTES=50000 " + exe() + " run " + sh_quote(scene("10")) + " --out " +
                            sh_quote(out) + " --quiet");
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "results.csv"));
  EXPECT_GT(check_whole_rows(out / "results.csv.partial"), 100);
  EXPECT_LE(fs::file_size(out / "results.csv.partial"), 50000u);
  EXPECT_EQ(read_json(out / "summary.json")["status"], "output_failed");
}

// A real full file system: a 64 kB tmpfs in a private mount namespace (skipped where the test
// cannot make one).
TEST_F(OutputFaults, FullTmpfs) {
  if (shell("unshare -rm true").code != 0) GTEST_SKIP() << "no user and mount namespaces here";
  fs::create_directories(out);
  const CliResult r = shell("unshare -rm sh -c \"mount -t tmpfs -o size=64k tmpfs " + sh_quote(out) + " && " + exe() +
                            " run " + sh_quote(scene("10")) + " --out " + sh_quote(out) + " --quiet; s=\\$?; cp -r " +
                            sh_quote(out) + " " + sh_quote(dir / "copy") + "; exit \\$s\"");
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "copy" / "results.csv"));
  EXPECT_GT(check_whole_rows(dir / "copy" / "results.csv.partial"), 100);
  if (fs::exists(dir / "copy" / "summary.json")) {  // the summary may not fit either
    EXPECT_EQ(read_json(dir / "copy" / "summary.json")["status"], "output_failed");
  }
}

// Folders in the way and names the file system refuses are found before any solving (exit 2).
TEST_F(OutputFaults, OutputFolderProblemsBeforeSolving) {
  fs::create_directories(out / "results.csv");
  CliResult r = shell(exe() + " run " + sh_quote(scene("10")) + " --out " + sh_quote(out) + " --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("holds a folder named 'results.csv'"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  fs::remove_all(out);
  fs::create_directories(out / "summary.json.partial");
  r = shell(exe() + " run " + sh_quote(scene("10")) + " --out " + sh_quote(out) + " --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("holds a folder named 'summary.json.partial'"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "results.csv.partial"));
  const fs::path too_long = dir / std::string(300, 'x');
  r = shell(exe() + " run " + sh_quote(scene("10")) + " --out " + sh_quote(too_long) + " --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("File name too long"), std::string::npos) << r.output;
}

// Two runs into one folder: the second is refused while the first runs; the first's rows are
// not mixed with anything.
TEST_F(OutputFaults, ConcurrentRunsIntoOneFolder) {
  const pid_t first = start(scene("10000"), "first.log");
  ASSERT_TRUE(wait_for_rows(first, 20000));
  const CliResult r = shell(exe() + " run " + sh_quote(scene("1", "other.yaml")) + " --out " + sh_quote(out) + " --quiet");
  EXPECT_EQ(r.code, 4) << r.output;
  EXPECT_NE(r.output.find("is in use by another run"), std::string::npos) << r.output;
  kill(first, SIGTERM);
  EXPECT_EQ(wait_exit(first), 128 + SIGTERM);
  EXPECT_GT(check_whole_rows(out / "results.csv"), 100);
  EXPECT_EQ(read_json(out / "summary.json")["status"], "interrupted");
}

// SIGTERM and SIGINT: the rows so far, a valid summary with status interrupted, exit 128 + the
// signal; and a previous run's summary is gone as soon as the new run starts.
TEST_F(OutputFaults, SigtermAndSigintDuringRun) {
  for (const int sig : {SIGTERM, SIGINT}) {
    fs::remove_all(out);
    fs::create_directories(out);
    std::ofstream(out / "summary.json") << R"({"status": "ok"})";
    const pid_t pid = start(scene("10000"), "run.log");
    ASSERT_TRUE(wait_for_rows(pid, 50000));
    EXPECT_FALSE(fs::exists(out / "summary.json"));  // the old "ok" is not left behind
    kill(pid, sig);
    EXPECT_EQ(wait_exit(pid), 128 + sig) << read_file(dir / "run.log");
    const long rows = check_whole_rows(out / "results.csv");
    const auto summary = read_json(out / "summary.json");
    EXPECT_EQ(summary["status"], "interrupted");
    EXPECT_EQ(summary["steps"][0]["statistics"]["output_rows"].get<long>(), rows);
    EXPECT_LT(summary["steps"][0]["t_reached"].get<double>(), 10000.0);
    EXPECT_FALSE(fs::exists(out / "results.csv.partial"));
  }
}

// SIGKILL at several moments, right after the file grew (so often inside a write that the kernel
// stops at a page boundary): after the repair process is done (a reader's flock waits for it,
// core/output_guard.h), only whole rows on disk, no summary claiming anything.
TEST_F(OutputFaults, SigkillLeavesWholeRows) {
  for (int k = 0; k < 5; ++k) {
    fs::remove_all(out);
    const pid_t pid = start(scene("10000"), "run.log");
    ASSERT_TRUE(wait_for_rows(pid, 20000 + 37000 * k));
    ASSERT_NO_FATAL_FAILURE(kill_and_wait_for_repair(pid, out / "results.csv.partial"));
    EXPECT_GT(check_whole_rows(out / "results.csv.partial"), 100);
    EXPECT_FALSE(fs::exists(out / "results.csv"));
    EXPECT_FALSE(fs::exists(out / "summary.json"));
  }
}

// The same with sensitivities: sensitivities.csv is written as its rows come (each after its
// sample), through .partial, so a killed run keeps whole rows of both files.
TEST_F(OutputFaults, SigkillLeavesWholeSensitivityRows) {
  const pid_t pid = start(scene("10000"), "run.log", "bodies.arm.mass");
  ASSERT_TRUE(wait_for_rows(pid, 60000));
  ASSERT_NO_FATAL_FAILURE(kill_and_wait_for_repair(pid, out / "sensitivities.csv.partial"));
  const long results = check_whole_rows(out / "results.csv.partial");
  const std::string text = read_file(out / "sensitivities.csv.partial");
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, R"x(t,d(angle)/d(bodies.arm.mass),"d(a,b""c)/d(bodies.arm.mass)")x");
  long rows = 0;
  while (std::getline(in, line)) {
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 2) << "row " << rows + 1 << ": '" << line << "'";
    ++rows;
  }
  EXPECT_GT(rows, 100);
  EXPECT_LE(rows, results);
  EXPECT_FALSE(fs::exists(out / "sensitivities.csv"));
}

// Overrides out of the scene fields' ranges are refused with the scene fields' messages.
TEST_F(OutputFaults, OverridesCheckedLikeSceneFields) {
  const std::string swing = scene("1");
  struct Case {
    std::string option, value, field, message;
  };
  const std::vector<Case> cases = {
      {"--rtol", "1e-300", "rtol", "out of range [1e-14, 0.5], got 1e-300"},
      {"--rtol", "1", "rtol", "out of range [1e-14, 0.5], got 1"},
      {"--atol", "0", "atol", "out of range (0, 1], got 0"},
      {"--output-step", "1e-12", "output_step", "too small: more than 1e8 output rows over [0, 1]"},
  };
  for (const Case& c : cases) {
    const CliResult cli = shell(exe() + " run " + sh_quote(swing) + " --out " + sh_quote(out) + " --quiet " + c.option +
                                " " + c.value);
    EXPECT_EQ(cli.code, 1) << cli.output;
    EXPECT_NE(cli.output.find("mbdae: " + c.option + ": " + c.message), std::string::npos) << cli.output;
    // The same value in the scene file: the same message.
    std::string text = read_file(swing);
    text.replace(text.find("output_step: 0.001"), 18, c.field + ": " + c.value + (c.field == "output_step" ? "" : ", output_step: 0.001"));
    std::ofstream(dir / "field.yaml") << text;
    const CliResult field = shell(exe() + " check " + sh_quote(dir / "field.yaml"));
    EXPECT_EQ(field.code, 2) << field.output;
    EXPECT_NE(field.output.find("field '" + c.field + "': " + c.message), std::string::npos) << field.output;
  }
  EXPECT_FALSE(fs::exists(out));  // refused before anything was written
}

// A header name with a comma and a quote, read back by Python's csv module (RFC 4180).
TEST_F(OutputFaults, QuotedNamesReadBackByPythonCsv) {
  const CliResult r = shell(exe() + " run " + sh_quote(scene("0.01")) + " --out " + sh_quote(out) + " --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(check_whole_rows(out / "results.csv"), 11);
  const CliResult py = shell("/usr/bin/python3 -c \"import csv,sys; r=list(csv.reader(open(sys.argv[1]))); "
                             "print(len(r[0]), r[0][2], len(r))\" " + sh_quote(out / "results.csv"));
  EXPECT_EQ(py.output, "3 a,b\"c 12\n");
}

}  // namespace
