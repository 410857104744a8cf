// Running the polydg binary from a test as a user would: its exit code and all it printed, and
// a fixture giving each test its own scratch folder.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace polydg::testing {

struct CommandResult {
  int exitCode = -1;
  std::string out;  ///< stdout and stderr together
};

/// Runs `command` through the shell (/bin/sh), collecting what it prints on stdout and stderr.
inline CommandResult runShell(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen(("(" + command + ") 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) r.out += buffer.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// Runs `polydg ARGUMENTS` through the shell (POLYDG_BINARY, set by polydg_add_test).
inline CommandResult runPolydg(const std::string& arguments) {
  return runShell(std::string(POLYDG_BINARY) + " " + arguments);
}

/// A file of testdata/ (POLYDG_TESTDATA_DIR, set by polydg_add_test).
inline std::string testData(const std::string& name) {
  return std::string(POLYDG_TESTDATA_DIR) + "/" + name;
}

/// A test with its own empty folder, polydg_SUITE_TEST in the temporary directory, removed
/// after the test.
class CommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("polydg_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
            std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  nlohmann::json readJson(const std::string& name) const {
    std::ifstream in(path(name));
    return nlohmann::json::parse(in);
  }
  std::filesystem::path dir_;
};

}  // namespace polydg::testing
