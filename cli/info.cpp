// polydg info: counts, closedness, bounding box and enclosed volume of a surface or a VTU mesh
// (model/info.h).
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "model/files.h"
#include "polydg/model/info.h"

namespace polydg::cli {

namespace {

struct InfoOptions {
  std::string input, report;
};

void print(const std::string& path, const nlohmann::json& j) {
  std::cout << path << ": " << j["kind"].get<std::string>() << '\n';
  for (const auto& [key, value] : j.items()) {
    if (key == "kind") continue;
    std::cout << "  " << key << ": " << value.dump() << '\n';
  }
}

}  // namespace

void addInfoCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info", "Counts, closedness, bounding box and enclosed volume of a surface or VTU mesh");
  cmd->add_option("input", o->input, "surface file (any format polydg reads) or .vtu")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--report", o->report, "write the figures as JSON to this file");
  cmd->callback([o, &common, &exitCode] {
    if (!o->report.empty()) requireOutput(o->report, {o->input});
    const nlohmann::json j = isVolumeMeshPath(o->input) ? toJson(inspectVolumeMesh(o->input))
                                                        : toJson(inspectSurface(o->input));
    if (!o->report.empty()) {
      nlohmann::json report = j;
      report["command"] = "info";
      report["input"] = o->input;
      writeJsonFile(o->report, report);
    }
    if (!common.quiet) print(o->input, j);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
