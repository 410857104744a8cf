// polydg cut: plane and polygon cuts of a simulation mesh in place, each operation validated
// (Model::cut()); the output is written only if every operation passed and something is left.
//
// Sample runs:
//   polydg cut mesh.vtu -o half.vtu --plane "0,0,1,0.5" --remove-side + --report cut.json
//   polydg cut mesh.vtu -o slit.vtu --polygon "0,0,0.5;1,0,0.5;1,1,0.5;0,1,0.5"
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/progress.h"
#include "model/files.h"
#include "polydg/model/report_json.h"

namespace polydg::cli {

namespace {

struct CutCommandOptions {
  std::string input, output, report;
  std::vector<Blade> blades;  ///< --plane ... in order, then --polygon
  std::optional<Blade> polygon;
  int removeSide = 0;
  std::optional<double> sliverFraction;
  CheckLevel checks = CheckLevel::Local;
};

std::string describe(const Blade& blade) {
  std::ostringstream s;
  if (blade.finite()) {
    s << "polygon with " << blade.polygon.size() << " corners";
  } else {
    s << "plane " << blade.normal.x() << "," << blade.normal.y() << "," << blade.normal.z() << ","
      << blade.offset;
  }
  return s.str();
}

void run(const CutCommandOptions& o, bool quiet, int& exitCode) {
  if (!isVolumeMeshPath(o.input))
    throw InputError(o.input + ": cut reads simulation meshes (.vtu); make one with 'polydg mesh'");
  if (!isVolumeMeshPath(o.output)) throw InputError(o.output + ": the output must be a .vtu file");
  requireOutput(o.output, {o.input});
  if (!o.report.empty()) requireOutput(o.report, {o.input});
  std::vector<Blade> blades = o.blades;
  if (o.polygon) blades.push_back(*o.polygon);
  if (blades.empty()) throw InputError("nothing to cut with: give --plane or --polygon");

  Model model = Model::read(o.input);
  MeshCheckOptions geometry;
  geometry.local = false;
  geometry.rigidModes = GlobalCheck::Never;
  const MeshCheck before = model.check(geometry);
  if (!before.passed())
    throw InputError(o.input + ": the mesh is invalid (" + before.failures().front() +
                     "); run 'polydg check' on it");
  nlohmann::json report{{"command", "cut"},
                        {"input",
                         {{"path", o.input},
                          {"elements", before.geometry->elements},
                          {"volume", before.geometry->volume}}},
                        {"provenance", toJson(model.provenance())}};
  report["operations"] = nlohmann::json::array();
  ProgressBar progress("cutting", quiet || blades.size() < 2);
  std::string failure;
  for (std::size_t i = 0; i < blades.size(); ++i) {
    CutRequest request;
    request.blade = blades[i];
    request.removeSide = o.removeSide;
    request.sliverFraction = o.sliverFraction;
    request.checks = o.checks;
    const OperationReport r = model.cut(request);
    report["operations"].push_back(toJson(r));
    progress.update(double(i + 1) / double(blades.size()));
    if (!r.leftWhole.empty())
      std::cerr << "polydg: warning: operation " << i + 1 << " (" << describe(blades[i])
                << "): " << r.leftWhole.size()
                << " element(s) at the polygon's edge left whole and listed in the report's "
                   "left_whole ("
                << r.elementsSplit
                << " split); a finer mesh or a larger polygon splits more of them\n";
    if (!r.check.passed) {
      failure = "operation " + std::to_string(i + 1) + " (" + r.op + ", " + describe(blades[i]) +
                ") failed its " + toString(r.check.level) + " validation: " + r.check.failure;
      break;
    }
  }
  progress.finish();
  std::size_t components = 0;
  if (failure.empty()) connectedComponents(model.mesh(), components);
  report["output"] = {{"path", failure.empty() ? o.output : std::string()},
                      {"elements", model.mesh().numElements()},
                      {"components", components},
                      {"volume", failure.empty() ? nlohmann::json(model.volume()) : nullptr}};
  report["passed"] = failure.empty();
  if (!failure.empty()) report["failure"] = failure;
  if (failure.empty()) model.write(o.output);
  if (!o.report.empty()) writeJsonFile(o.report, report);
  if (!failure.empty()) {
    std::cerr << "polydg: error: " << failure << "; nothing written\n";
    exitCode = 1;
    return;
  }
  if (!quiet)
    std::cout << o.output << ": " << model.mesh().numElements() << " elements, " << components
              << " component(s), volume " << model.volume() << " (input " << before.geometry->volume
              << "), " << blades.size() << " operation(s)\n";
  exitCode = 0;
}

}  // namespace

void addCutCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<CutCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "cut",
      "Cut a simulation mesh with planes or a convex polygon, in place, validating each "
      "operation");
  cmd->add_option("mesh", o->input, "simulation mesh (.vtu)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "output mesh (.vtu)")->required();
  cmd->add_option_function<std::vector<std::string>>(
         "--plane",
         [o](const std::vector<std::string>& planes) {
           for (const std::string& p : planes) {
             const Plane plane = parsePlane(p, "--plane");
             o->blades.push_back(Blade::plane(plane.normal, plane.offset));
           }
         },
         "the plane {x : n.x = d} as \"nx,ny,nz,d\"; repeat to cut several times, in order")
      ->type_name("NX,NY,NZ,D")
      ->allow_extra_args(false);
  cmd->add_option_function<std::string>(
         "--polygon",
         [o](const std::string& text) { o->polygon = parsePolygon(text, "--polygon"); },
         "a convex planar polygon blade \"x1,y1,z1;x2,y2,z2;...\" (after the planes)")
      ->type_name("X,Y,Z;...");
  addChoice(*cmd, "--remove-side", o->removeSide, removeSideNames(),
            "delete what lies on this side of each plane: + (n.x > d) or -");
  cmd->add_option_function<double>(
         "--merge-slivers", [o](double f) { o->sliverFraction = f; },
         "merge sliver pieces: volume below this fraction of the mesh's reference volume V (its "
         "grid cell, or the median element of a mesh polydg did not slice), or 6 volume / area "
         "below (TAU V)^(1/3); 0: never; default: the mesh's sliver rule, 0.01 unless meshed "
         "otherwise")
      ->check(finiteRange(0.0, 1.0));
  addChoice(*cmd, "--validate", o->checks, checkLevelNames(), "checks after each operation");
  cmd->add_option("--report", o->report, "write a JSON report to this file");
  cmd->callback([o, &common, &exitCode] { run(*o, common.quiet, exitCode); });
}

}  // namespace polydg::cli
