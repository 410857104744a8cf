// polydg export: a simulation mesh in another program's format; today OpenFOAM's case folder
// (mesh/openfoam.h), which OpenFOAM's own checkMesh opens as it is, with checkMesh's figures
// computed beforehand in the report.
//
// Sample runs:
//   polydg export torus.vtu --format openfoam -o torus_case
//   polydg export bar.vtu --format openfoam -o bar_case --patch inlet=x=0
//       --patch outlet=below:-1,0,0,-4 --binary --report export.json   (one line)
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "model/files.h"
#include "polydg/model/model.h"
#include "polydg/model/report_json.h"

namespace polydg::cli {

namespace {

struct ExportCommandOptions {
  std::string input, output, format = "openfoam", report;
  ExportOptions exporting;
};

void run(const ExportCommandOptions& o, const CommonOptions& common) {
  if (!o.report.empty()) requireOutput(o.report, {o.input});
  const Model model = Model::read(o.input);
  const ExportReport r = model.exportOpenFoam(o.output, o.exporting);
  if (!o.report.empty()) {
    nlohmann::json report = toJson(r);
    report["command"] = "export";
    report["input"] = o.input;
    writeJsonFile(o.report, report);
  }
  if (common.quiet) return;
  const OpenFoamReport& f = r.foam;
  const OpenFoamQuality& q = f.quality;
  std::cout << o.output << ": " << f.cells << " cells, " << f.faces << " faces (" << f.internalFaces
            << " internal), " << f.points << " points; patches";
  for (const OpenFoamPatchReport& p : f.patches) std::cout << ' ' << p.name << " " << p.faces;
  std::cout << "\ncheckMesh's figures: max non-orthogonality " << q.maxNonOrthogonality
            << ", max skewness " << q.maxSkewness << ", max aspect ratio " << q.maxAspectRatio
            << "; ";
  const std::vector<std::string> failed = q.failedChecks();
  if (failed.empty()) {
    std::cout << "checkMesh will say Mesh OK\n";
    return;
  }
  std::cout << "checkMesh will fail";
  for (std::size_t k = 0; k < failed.size(); ++k) std::cout << (k ? ", " : " ") << failed[k];
  std::cout << " (" << q.skewFaces << " faces above skewness 4, " << q.skewBoundaryFaces
            << " of them on the boundary; " << q.nonOrthogonalityErrors
            << " faces at 90 degrees or more; " << q.wrongOrientedFaces
            << " wrongly oriented face pyramids); --report lists the worst\n";
  for (const std::string& a : q.advice()) std::cout << "  " << a << "\n";
}

}  // namespace

void addExportCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<ExportCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Write a simulation mesh for another program (an OpenFOAM case folder)");
  cmd->add_option("mesh", o->input, "simulation mesh (.vtu, or a tet mesh .ele/.msh)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--format", o->format, "openfoam: constant/polyMesh and system/")
      ->check(CLI::IsMember({"openfoam"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output, "the case folder (replaced if it is one)")->required();
  cmd->add_option_function<std::vector<std::string>>(
         "--patch",
         [o](const std::vector<std::string>& values) {
           for (const std::string& v : values) {
             const auto eq = v.find('=');
             if (eq == std::string::npos || eq == 0)
               throw CLI::ValidationError("--patch", "expected NAME=REGION, e.g. inlet=x=0");
             o->exporting.patches.push_back(
                 {v.substr(0, eq), parseRegion(v.substr(eq + 1), "--patch")});
           }
         },
         "a boundary patch NAME=REGION (REGION: x=V, plane:NX,NY,NZ,D, below:NX,NY,NZ,D or "
         "box:X0,Y0,Z0,X1,Y1,Z1, as the clamps'); before the default patches wall, cut0, cut1, "
         "... (one per cut) and cut; repeatable")
      ->type_name("NAME=REGION")
      ->allow_extra_args(false);
  cmd->add_flag("--binary", o->exporting.binary, "OpenFOAM's binary format instead of ASCII");
  cmd->add_option("--report", o->report, "write the figures as JSON to this file");
  cmd->callback([o, &common, &exitCode] {
    run(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
