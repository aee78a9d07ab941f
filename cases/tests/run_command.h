// Support of the executable tests: a shell command line run with its exit code and its output
// (stdout and stderr together), a file read whole, and a fresh folder per test.
#pragma once

#include <sys/wait.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace mbdae::test_support {

struct CommandResult {
  int code = -1;  // the exit code, -1 if killed by a signal
  std::string output;
};

inline CommandResult run_command(const std::string& cmd) {
  CommandResult r;
  FILE* p = popen(("(" + cmd + ") 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The whole content of a file, bytes as they are (empty if it cannot be read).
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh folder per test (`dir`, removed afterwards) and the run's output folder `out` inside it:
// the fixture base of the tests that drive the executable. `prefix` keeps suites apart.
class RunFolderTest : public ::testing::Test {
 protected:
  explicit RunFolderTest(std::string prefix) : prefix_(std::move(prefix)) {}
  std::filesystem::path dir, out;
  void SetUp() override {
    dir = std::filesystem::temp_directory_path() /
          (prefix_ + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    out = dir / "out";
  }
  void TearDown() override { std::filesystem::remove_all(dir); }

 private:
  std::string prefix_;
};

}  // namespace mbdae::test_support
