#include "cli/bench/external_commands.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <system_error>

namespace polydg::bench {

double commandSeconds(const std::string& command) {
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status == 0 ? seconds : -1.0;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

std::string shellQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::optional<std::filesystem::path> polydgExecutable() {
  std::error_code ec;
  std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return std::nullopt;
  return self;
}

bool commandExists(const std::string& program) {
  return std::system(("command -v " + shellQuoted(program) + " > /dev/null 2>&1").c_str()) == 0;
}

}  // namespace polydg::bench
