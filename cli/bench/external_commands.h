// Whole commands run through the shell and timed: the suites that set polydg beside another
// program (tetgen in the meshing suite, OpenFOAM in the openfoam suite) time both as a user
// runs them, start-up and file writing included.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace polydg::bench {

/// Wall time of `command` run by std::system (through /bin/sh), or -1 if it did not exit 0.
double commandSeconds(const std::string& command);

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
