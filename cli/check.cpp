// polydg check: geometric validation of a simulation mesh (VTU); non-zero exit if invalid.
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/json_reports.h"
#include "cli/report.h"
#include "mesh/validate.h"
#include "mesh/vtu_io.h"

namespace polydg::cli {

namespace {

struct CheckOptions {
  std::string input;
  std::string report;
  double planarityTolerance = ValidationOptions{}.planarityTolerance;
};

}  // namespace

void addCheckCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* cmd = app.add_subcommand(
      "check", "Validate a simulation mesh: closed, positive, planar, properly shared elements");
  cmd->add_option("mesh", options->input, "simulation mesh (.vtu)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--report", options->report, "write the validation as JSON to this file");
  cmd->add_option("--planarity-tolerance", options->planarityTolerance,
                  "largest vertex distance from a face's plane, relative to the face size")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->callback([options, &common, &exitCode] {
    if (!isVolumeMeshPath(options->input))
      throw UserError(options->input +
                      ": check reads simulation meshes (.vtu); for a surface use 'polydg info'");
    const PolyMesh mesh = readVtu(options->input);
    ValidationOptions vo;
    vo.planarityTolerance = options->planarityTolerance;
    const ValidationReport r = validate(mesh, vo);
    if (!options->report.empty()) {
      requireDistinct(options->report, options->input);
      nlohmann::json report{{"command", "check"}, {"input", options->input}};
      report.update(toJson(r));
      report["validation"] = toJson(r);
      writeReport(options->report, report);
    }
    if (!common.quiet) {
      std::cout << options->input << ": " << (r.passed ? "valid" : "INVALID") << ", "
                << r.elements << " elements, " << r.faces << " faces (" << r.interiorFaces
                << " interior), " << r.components << " component(s), volume " << r.volume
                << '\n';
      for (const std::string& m : r.messages) std::cout << "  " << m << '\n';
    }
    exitCode = r.passed ? 0 : 1;
  });
}

}  // namespace polydg::cli
