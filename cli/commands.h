// The polydg subcommands: each registers its typed options on the CLI11 app and runs through
// the library. Exit codes: 0 success, 1 a check failed (e.g. an invalid mesh), 2 bad input.
#pragma once

#include <CLI/CLI.hpp>

namespace polydg::cli {

/// Shared by every subcommand.
struct CommonOptions {
  bool quiet = false;
};

void addInfoCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addCheckCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addMeshCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addSolveCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addBenchCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
/// `polydg run PIPELINE.json`: a JSON pipeline of steps on one input or many (cli/run.cpp).
void addRunCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
/// `polydg cut MESH.vtu -o OUT.vtu --plane ...`: validated plane cuts in place (cli/cut.cpp).
void addCutCommand(CLI::App& app, const CommonOptions& common, int& exitCode);

/// True for files read as simulation meshes (VTU) rather than surfaces.
bool isVolumeMeshPath(const std::string& path);

}  // namespace polydg::cli
