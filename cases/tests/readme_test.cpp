// The README's first command (install, build, run) works as root without sudo and as a user
// with sudo: its install part is run by sh with stand-ins for apt-get (and sudo), which record
// how they were called.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

// The install part of the README's first sh block: up to the first " && cmake".
std::string install_command() {
  std::ifstream in(std::string(MBDAE_SOURCE_DIR) + "/README.md");
  std::string line;
  bool in_block = false;
  while (std::getline(in, line)) {
    if (line.rfind("```sh", 0) == 0) in_block = true;
    else if (in_block) return line.substr(0, line.find(" && cmake"));
  }
  return "";
}

void write_script(const fs::path& path, const std::string& body) {
  std::ofstream(path) << "#!/bin/sh\n" << body;
  fs::permissions(path, fs::perms::owner_all);
}

// Runs `command` with PATH = `bin` only; returns the exit code.
int run_with_path(const std::string& command, const fs::path& bin) {
  const fs::path script = bin.parent_path() / "cmd.sh";
  std::ofstream(script) << "PATH=" << bin.string() << "\n" << command << "\n";
  const int status = std::system(("/bin/sh " + script.string() + " 2>/dev/null").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Readme, InstallCommandWorksAsRootWithoutSudo) {
  const std::string command = install_command();
  ASSERT_NE(command.find("apt-get install"), std::string::npos) << command;
  const fs::path dir = fs::path(::testing::TempDir()) / "readme_root";
  fs::remove_all(dir);
  fs::create_directories(dir / "bin");
  write_script(dir / "bin" / "apt-get", "echo \"apt-get $1\" >> " + (dir / "log").string() + "\n");
  EXPECT_EQ(run_with_path(command, dir / "bin"), 0) << command;  // no sudo on PATH
  EXPECT_EQ(read(dir / "log"), "apt-get update\napt-get install\n");
}

TEST(Readme, InstallCommandUsesSudoWhereThereIsOne) {
  const std::string command = install_command();
  const fs::path dir = fs::path(::testing::TempDir()) / "readme_user";
  fs::remove_all(dir);
  fs::create_directories(dir / "bin");
  write_script(dir / "bin" / "apt-get", "echo \"apt-get $1\" >> " + (dir / "log").string() + "\n");
  write_script(dir / "bin" / "sudo", "echo sudo >> " + (dir / "log").string() + "\nexec \"$@\"\n");
  EXPECT_EQ(run_with_path(command, dir / "bin"), 0) << command;
  EXPECT_EQ(read(dir / "log"), "sudo\napt-get update\nsudo\napt-get install\n");
}

// docs/errors.md quotes what `mbdae` without arguments prints (the usage text), word for word.
TEST(Readme, ErrorsPageQuotesTheUsageText) {
  const fs::path out = fs::temp_directory_path() / ("mbdae_usage_" + std::to_string(::getpid()) + ".txt");
  const int status = std::system((std::string(MBDAE_EXE) + " 2> " + out.string()).c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string usage = read(out);
  fs::remove(out);
  ASSERT_NE(usage.find("usage: mbdae run"), std::string::npos) << usage;
  const std::string page = read(fs::path(MBDAE_SOURCE_DIR) / "docs" / "errors.md");
  EXPECT_NE(page.find("$ mbdae\n" + usage), std::string::npos)
      << "docs/errors.md does not quote the usage text as printed:\n" << usage;
}

}  // namespace
