// The output layer (core/output.h): RFC 4180 header fields, whole rows after a failed write,
// the final name only for a complete file, checked renames and JSON writes, the folder lock.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/output.h"

namespace fs = std::filesystem;

namespace mbdae {
namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class Output : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("mbdae_output_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override {
    unsetenv("MBDAE_OUTPUT_FAULT_BYTES");
    fs::remove_all(dir);
  }
};

TEST(CsvField, QuotesPerRfc4180) {
  EXPECT_EQ(csv_field("wheel_z"), "wheel_z");
  EXPECT_EQ(csv_field("a,b\"c"), "\"a,b\"\"c\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csv_field("\""), "\"\"\"\"");
}

TEST_F(Output, CompleteFileGetsItsName) {
  const std::string path = (dir / "r.csv").string();
  {
    CsvWriter csv;
    csv.open(path, {"t", "x,y"});
    for (int k = 0; k < 3; ++k) {
      const double row[2] = {0.5 * k, 1.0 / 3.0};
      csv.row(row);
    }
    csv.close();
  }
  EXPECT_FALSE(fs::exists(path + ".partial"));
  EXPECT_EQ(read_text(path), "t,\"x,y\"\n0,0.333333333333333\n0.5,0.333333333333333\n1,0.333333333333333\n");
}

// A file system that fills after 1000 bytes: the error names the file and the OS error, the
// file is cut back to its last whole row and keeps its .partial name.
TEST_F(Output, FailedWriteLeavesWholeRowsUnderThePartialName) {
  setenv("MBDAE_OUTPUT_FAULT_BYTES", "1000", 1);
  const std::string path = (dir / "r.csv").string();
  CsvWriter csv;
  csv.open(path, {"t", "x"});
  std::string error;
  try {
    for (int k = 0; k < 100000; ++k) {
      const double row[2] = {1e-3 * k, 0.1 * k};
      csv.row(row);
      if (k % 10 == 9) csv.flush();
    }
  } catch (const OutputError& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("cannot write " + path + ".partial: No space left on device"), std::string::npos) << error;
  EXPECT_THROW(csv.close(), OutputError);
  EXPECT_FALSE(fs::exists(path));
  const std::string text = read_text(path + ".partial");
  ASSERT_FALSE(text.empty());
  EXPECT_LE(text.size(), 1000u);
  EXPECT_EQ(text.back(), '\n');
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "t,x");
  int rows = 0;
  while (std::getline(in, line)) {
    const double row[2] = {1e-3 * rows, 0.1 * rows};
    std::ostringstream expected;
    expected.precision(15);
    expected << row[0] << "," << row[1];
    EXPECT_EQ(line, expected.str());
    ++rows;
  }
  EXPECT_GT(rows, 10);
  EXPECT_EQ(rows % 10, 0);  // flushed every 10 rows: only whole flushes reached the disk
}

TEST_F(Output, RenameOntoAFolderIsReported) {
  const std::string path = (dir / "r.csv").string();
  CsvWriter csv;
  csv.open(path, {"t"});
  fs::create_directories(dir / "r.csv" / "inside");
  try {
    csv.close();
    FAIL() << "the rename onto a folder was not reported";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot rename " + path + ".partial to " + path + ": "), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::exists(path + ".partial"));
}

TEST_F(Output, JsonWriteFailureLeavesNoFile) {
  setenv("MBDAE_OUTPUT_FAULT_BYTES", "10", 1);
  const std::string path = (dir / "s.json").string();
  EXPECT_THROW(write_json_file(path, {{"status", "ok"}, {"long", std::string(100, 'x')}}), OutputError);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".partial"));
  unsetenv("MBDAE_OUTPUT_FAULT_BYTES");
  write_json_file(path, {{"status", "ok"}});
  EXPECT_EQ(read_text(path), "{\n  \"status\": \"ok\"\n}\n");
}

TEST_F(Output, FolderProblemsAreInputErrors) {
  fs::create_directories(dir / "out" / "results.csv");
  EXPECT_THROW(prepare_output_folder((dir / "out").string(), {"results.csv"}), ModelError);
  EXPECT_THROW(prepare_output_folder((dir / std::string(300, 'x')).string(), {"results.csv"}), ModelError);
  EXPECT_NO_THROW(prepare_output_folder((dir / "fresh").string(), {"results.csv", "summary.json"}));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "fresh"), fs::directory_iterator()), 0);  // probes removed
}

// flock locks belong to open file descriptions: a second lock in the same process conflicts too.
TEST_F(Output, OneRunPerFolder) {
  std::ofstream(dir / "summary.json") << "{\"status\": \"ok\"}";
  {
    const OutputFolderLock first = claim_output_folder(dir.string(), {"results.csv", "summary.json"});
    EXPECT_FALSE(fs::exists(dir / "summary.json"));  // a previous run's summary is gone
    try {
      OutputFolderLock second(dir.string());
      FAIL() << "a busy folder was locked twice";
    } catch (const OutputError& e) {
      EXPECT_NE(std::string(e.what()).find("is in use by another run (process " + std::to_string(::getpid()) + ")"),
                std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(OutputFolderLock again(dir.string()));  // released with the first
}

}  // namespace
}  // namespace mbdae
