#include "cli/bench/external_commands.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <system_error>

extern char** environ;

namespace polydg::bench {

double commandSeconds(const std::string& command) {
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status == 0 ? seconds : -1.0;
}

namespace {

/// The descriptors the outer shell of measureCommand() hands to the inner one: the inner shell
/// writes its process id to kPidFd, then waits until kGoFd reaches its end.
constexpr int kPidFd = 3, kGoFd = 4;

/// The outer shell: starts the inner shell ($1) as a child of its own and waits for it. It is
/// killed before the inner shell runs the command.
constexpr const char* kOuterShell = "/bin/sh -c \"$1\" polydg-measure\nexit $?";

/// A file descriptor, closed when it goes out of scope.
class Fd {
 public:
  explicit Fd(int fd = -1) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() { close(); }
  int get() const { return fd_; }
  /// Closes the descriptor held, then holds `fd`.
  void reset(int fd = -1) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
  }
  void close() { reset(); }

 private:
  int fd_;
};

/// A pipe's read and write ends, both above kGoFd (so that placing them on kPidFd and kGoFd in
/// the child clobbers neither) and closed on exec. False if the system refused.
bool openPipe(Fd& read, Fd& write) {
  int ends[2];
  if (::pipe2(ends, O_CLOEXEC) != 0) return false;
  for (int i = 0; i < 2; ++i) {
    const int high = ::fcntl(ends[i], F_DUPFD_CLOEXEC, kGoFd + 1);
    ::close(ends[i]);
    ends[i] = high;
  }
  read.reset(ends[0]);
  write.reset(ends[1]);
  return read.get() >= 0 && write.get() >= 0;
}

/// Makes this process the child subreaper (orphaned descendants become its children) while it
/// lives, then restores the setting it found.
class SubreaperScope {
 public:
  SubreaperScope() {
    ::prctl(PR_GET_CHILD_SUBREAPER, &previous_);
    ::prctl(PR_SET_CHILD_SUBREAPER, 1);
  }
  SubreaperScope(const SubreaperScope&) = delete;
  SubreaperScope& operator=(const SubreaperScope&) = delete;
  ~SubreaperScope() { ::prctl(PR_SET_CHILD_SUBREAPER, previous_); }

 private:
  int previous_ = 0;
};

/// waitpid/wait4 on `pid`, again when a signal interrupts it; false if it failed otherwise.
bool waitFor(pid_t pid, int& status, rusage* usage = nullptr) {
  while (::wait4(pid, &status, 0, usage) < 0)
    if (errno != EINTR) return false;
  return true;
}

/// The process id the inner shell writes (one line), or -1 if the pipe ends without one.
pid_t readPid(int fd) {
  std::string text;
  char c;
  for (;;) {
    const ssize_t n = ::read(fd, &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0 || c == '\n') break;
    text += c;
  }
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return -1;
  return static_cast<pid_t>(std::stol(text));
}

/// Spawns the outer shell running `inner`, with `pidWrite` on kPidFd and `goRead` on kGoFd;
/// its process id, or -1.
pid_t spawnOuterShell(const std::string& inner, const Fd& pidWrite, const Fd& goRead) {
  posix_spawn_file_actions_t actions;
  if (::posix_spawn_file_actions_init(&actions) != 0) return -1;
  ::posix_spawn_file_actions_adddup2(&actions, pidWrite.get(), kPidFd);
  ::posix_spawn_file_actions_adddup2(&actions, goRead.get(), kGoFd);
  const char* argv[] = {"sh", "-c", kOuterShell, "polydg-measure", inner.c_str(), nullptr};
  pid_t pid = -1;
  const int error =
      ::posix_spawn(&pid, "/bin/sh", &actions, nullptr, const_cast<char* const*>(argv), environ);
  ::posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

}  // namespace

std::optional<CommandCost> measureCommand(const std::string& command) {
  Fd pidRead, pidWrite, goRead, goWrite;
  if (!openPipe(pidRead, pidWrite) || !openPipe(goRead, goWrite)) return std::nullopt;
  const SubreaperScope subreaper;
  const std::string inner = "echo $$ >&3\nexec 3>&-\nread -r polydg_go <&4\nexec 4<&-\n" + command;
  const pid_t outer = spawnOuterShell(inner, pidWrite, goRead);
  if (outer < 0) return std::nullopt;
  pidWrite.close();
  goRead.close();
  const pid_t shell = readPid(pidRead.get());
  int status = 0;
  // The inner shell waits on kGoFd, so the outer one cannot have reaped it: killed, the outer
  // shell leaves it to this process.
  ::kill(outer, SIGKILL);
  waitFor(outer, status);
  if (shell < 0) return std::nullopt;
  const auto start = std::chrono::steady_clock::now();
  goWrite.close();
  rusage usage{};
  if (!waitFor(shell, status, &usage)) return std::nullopt;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return CommandCost{seconds, static_cast<std::size_t>(usage.ru_maxrss) * 1024};
}

std::optional<std::string> commandOutput(const std::string& command) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return std::nullopt;
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  const int status = ::pclose(pipe);
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return out;
}

std::string lastLine(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string last;
  for (std::string line; std::getline(in, line);)
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
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
