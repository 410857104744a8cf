// Whole commands run through the shell and timed: the suites that set polydg beside another
// program (tetgen and Gmsh in the meshing suite, OpenFOAM in the openfoam suite) time both as a
// user runs them, start-up and file writing included, and the meshing suite measures their
// peak memory too.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace polydg::bench {

/// Wall time of `command` run by std::system (through /bin/sh), or -1 if it did not exit 0.
double commandSeconds(const std::string& command);

/// What one run of a command cost.
struct CommandCost {
  double seconds = 0.0;          ///< wall time, from its start to its exit
  std::size_t peakRssBytes = 0;  ///< the largest peak resident set of any one of its processes
};

/// Runs `command` through /bin/sh (standard input, output and error this process's, as
/// std::system does) and measures it; empty if it did not exit 0 or could not be started.
///
/// The peak is the command's alone. A process's ru_maxrss starts at the peak resident set of
/// the memory it was forked with (Linux keeps it across exec), so a shell started from this
/// process would report at least this process's own peak. The command therefore runs in a
/// shell forked by another, freshly started shell; that outer shell is ended once the inner one
/// has started (this process adopts it as a child subreaper, PR_SET_CHILD_SUBREAPER, restored
/// afterwards), and the inner one's ru_maxrss from wait4() covers the command's processes and
/// nothing else. The time starts when the inner shell is released to run the command. Not
/// thread-safe (the subreaper setting is the process's); run one command at a time.
std::optional<CommandCost> measureCommand(const std::string& command);

/// What `command` (run through /bin/sh by popen) writes on its standard output, or empty if it
/// did not exit 0.
std::optional<std::string> commandOutput(const std::string& command);

/// The last line of the file `log` that is not blank (empty if there is none), to say why a
/// command whose output went there failed.
std::string lastLine(const std::filesystem::path& log);

/// The middle value of `values` (the upper one of the two middle values for an even count).
/// `values` must not be empty.
double median(std::vector<double> values);

/// `text` in single quotes for /bin/sh, each quote inside written as '\''.
std::string shellQuoted(const std::string& text);

/// The running polydg executable, through /proc/self/exe (Linux); empty if that link cannot be
/// read.
std::optional<std::filesystem::path> polydgExecutable();

/// Whether `program` is a command the shell finds (`command -v`).
bool commandExists(const std::string& program);

}  // namespace polydg::bench
