// polydg export: a simulation mesh in another program's format; today OpenFOAM's case folder
// (mesh/openfoam.h), which OpenFOAM's own checkMesh opens as it is.
//
// Sample run:
//   polydg export torus.vtu --format openfoam -o torus_case
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "model/files.h"
#include "polydg/mesh/openfoam.h"
#include "polydg/model/model.h"
#include "util/stopwatch.h"

namespace polydg::cli {

namespace {

struct ExportCommandOptions {
  std::string input, output, format = "openfoam", report;
};

void run(const ExportCommandOptions& o, const CommonOptions& common) {
  if (!o.report.empty()) requireDistinct(o.report, o.input);
  const Stopwatch watch;
  const Model model = Model::read(o.input);
  const OpenFoamReport r = writeOpenFoamCase(model.mesh(), o.output);
  if (!o.report.empty()) {
    nlohmann::json patches = nlohmann::json::array();
    for (const OpenFoamPatchReport& p : r.patches)
      patches.push_back({{"name", p.name}, {"faces", p.faces}});
    writeJsonFile(o.report, {{"command", "export"},
                             {"input", o.input},
                             {"output", o.output},
                             {"format", o.format},
                             {"cells", r.cells},
                             {"points", r.points},
                             {"faces", r.faces},
                             {"internal_faces", r.internalFaces},
                             {"split_faces", r.splitFaces},
                             {"patches", patches},
                             {"seconds", watch.seconds()}});
  }
  if (!common.quiet) {
    std::cout << o.output << ": " << r.cells << " cells, " << r.faces << " faces ("
              << r.internalFaces << " internal), " << r.points << " points; patches";
    for (const OpenFoamPatchReport& p : r.patches) std::cout << ' ' << p.name << " " << p.faces;
    std::cout << "\n";
  }
}

}  // namespace

void addExportCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<ExportCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Write a simulation mesh for another program (an OpenFOAM case folder)");
  cmd->add_option("mesh", o->input, "simulation mesh (.vtu, or a tet mesh .ele/.msh)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--format", o->format, "openfoam: constant/polyMesh and system/ (ASCII)")
      ->check(CLI::IsMember({"openfoam"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output, "the case folder (replaced if it is one)")->required();
  cmd->add_option("--report", o->report, "write the figures as JSON to this file");
  cmd->callback([o, &common, &exitCode] {
    run(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
