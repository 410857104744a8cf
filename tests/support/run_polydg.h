// Running the polydg binary from a test as a user would: its exit code and all it printed.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace polydg::testing {

struct CommandResult {
  int exitCode = -1;
  std::string out;  ///< stdout and stderr together
};

/// Runs `polydg ARGUMENTS` through the shell (POLYDG_BINARY, set by polydg_add_test).
inline CommandResult runPolydg(const std::string& arguments) {
  const std::string command = std::string(POLYDG_BINARY) + " " + arguments + " 2>&1";
  CommandResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) r.out += buffer.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace polydg::testing
