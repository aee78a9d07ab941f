// The repair process of core/output_guard.h, driven by hand: the writer's death is the end of
// its channel without "done". A write announced and left halfway is cut back to its start; a
// finished write, or a writer that said "done", is left as it is; a reader's flock waits.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/output_guard.h"

namespace fs = std::filesystem;

namespace mbdae {
namespace {

class OutputGuardTest : public ::testing::Test {
 protected:
  fs::path path;
  int fd = -1;
  void SetUp() override {
    path = fs::temp_directory_path() / ("mbdae_guard_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    ASSERT_GE(fd, 0);
  }
  void TearDown() override {
    if (fd >= 0) ::close(fd);
    fs::remove(path);
  }
  void put(const std::string& s) { ASSERT_EQ(::write(fd, s.data(), s.size()), static_cast<ssize_t>(s.size())); }
  // The writer dies: its end of the channel closes without "done"; wait for the repair.
  static void die(OutputGuard& g) {
    ::close(g.channel);
    int status = -1;
    ASSERT_EQ(::waitpid(g.pid, &status, 0), g.pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  }
};

TEST_F(OutputGuardTest, WriteStoppedHalfwayIsCutBack) {
  OutputGuard g = start_output_guard(fd);
  ASSERT_GT(g.pid, 0);
  announce_write(g, 0, 6);
  put("t,x\n");
  announce_write(g, 4, 16);
  put("0,1\n1,2\n");  // then 4 more bytes that never come
  put("2,");
  die(g);
  EXPECT_EQ(fs::file_size(path), 4u);  // back to the size before the unfinished write
}

TEST_F(OutputGuardTest, FinishedWriteIsKept) {
  OutputGuard g = start_output_guard(fd);
  ASSERT_GT(g.pid, 0);
  announce_write(g, 0, 8);
  put("t,x\n0,1\n");
  die(g);
  EXPECT_EQ(fs::file_size(path), 8u);
}

TEST_F(OutputGuardTest, DoneLeavesTheFileAlone) {
  OutputGuard g = start_output_guard(fd);
  ASSERT_GT(g.pid, 0);
  announce_write(g, 0, 100);
  put("t,x\n");  // the writer cut it back itself (a failed write) and ends normally
  end_output_guard(g);
  EXPECT_EQ(g.pid, -1);
  EXPECT_EQ(fs::file_size(path), 4u);
}

// The repair process shares the file's open description and so its flock: a reader that takes
// the lock after the writer is gone gets the repaired file.
TEST_F(OutputGuardTest, ReaderLockWaitsForTheRepair) {
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  OutputGuard g = start_output_guard(fd);
  ASSERT_GT(g.pid, 0);
  announce_write(g, 0, 50);
  put("t,x\n0,");
  ::close(fd);  // the writer's descriptor is gone, the repair process still holds the lock
  fd = -1;
  const int reader = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(reader, 0);
  EXPECT_NE(::flock(reader, LOCK_SH | LOCK_NB), 0);
  ::close(g.channel);
  ASSERT_EQ(::flock(reader, LOCK_SH), 0);
  EXPECT_EQ(fs::file_size(path), 0u);
  ::close(reader);
  ::waitpid(g.pid, nullptr, 0);
}

}  // namespace
}  // namespace mbdae
