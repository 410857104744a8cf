// The polydg subcommands. Each registers its typed options on the CLI11 app and, when run,
// calls the model (model/model.h) and writes its report: no command composes checks or solves
// itself. Exit codes: 0 success, 1 a check failed or an operation left nothing (nothing
// written), 2 bad input (polydg::InputError and option errors).
#pragma once

#include <CLI/CLI.hpp>

namespace polydg::cli {

/// Shared by every subcommand.
struct CommonOptions {
  bool quiet = false;
};

void addInfoCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addMeshCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addCheckCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addSolveCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addCutCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
/// `polydg run PIPELINE.json`: a JSON pipeline of steps on one input or many.
void addRunCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
/// `polydg simulate MESH.vtu --scene SCENE.json -o OUTDIR`: dynamics (model/scene.h).
void addSimulateCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
/// `polydg export MESH --format openfoam -o CASE`: the mesh as an OpenFOAM case.
void addExportCommand(CLI::App& app, const CommonOptions& common, int& exitCode);
void addBenchCommand(CLI::App& app, const CommonOptions& common, int& exitCode);

}  // namespace polydg::cli
