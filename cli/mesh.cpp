// polydg mesh: a surface file in, a polyhedral DG simulation mesh (VTU) out, checked
// geometrically and by the element-local DG checks (degree 1): Model::fromSurface(); with --tets
// the file holds that mesh split into tets (tetrahedralize()) for the tet methods.
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/progress.h"
#include "model/files.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/report_json.h"
#include "util/stopwatch.h"

namespace polydg::cli {

namespace {

struct MeshCommandOptions {
  std::string input, output, report;
  MeshOptions mesh;
  bool skipDg = false;
};

void printTets(const TetOutputReport& t) {
  std::cout << "  written as tets: " << t.split.tets << " tets, " << t.vertices << " vertices ("
            << t.split.steinerPoints << " Steiner points); " << t.split.coneElements
            << " elements as cones, " << t.split.tetgenElements << " by TetGen; volume " << t.volume
            << " (relative difference " << t.volumeRelDifference << " from the polyhedral mesh's), "
            << t.split.seconds << " s\n";
}

void printSummary(const MeshReport& report) {
  const MeshingReport& r = report.meshing;
  std::cout << (report.output.empty() ? std::string("(not written)") : report.output) << ": "
            << r.elements << " elements (" << r.hexahedra << " hexahedra, " << r.polyhedra
            << " polyhedra, " << r.nonconvex << " non-convex), " << r.faces << " faces; grid "
            << r.grid.cells[0] << "x" << r.grid.cells[1] << "x" << r.grid.cells[2] << " of "
            << r.grid.cellSize << "\n"
            << "  volume " << r.outputVolume << " (input " << r.inputVolume << ", relative error "
            << r.volumeRelError << "), slivers merged " << r.slivers.merged << ", validation "
            << (r.geometry.passed ? "passed" : "FAILED") << "\n";
  for (const std::string& repair : r.repairs) std::cout << "  repair: " << repair << "\n";
  if (report.tets) printTets(*report.tets);
  if (report.coarseCellSize > 0.0) {
    std::cout << "  octree: " << report.levels << " levels below cells of " << report.coarseCellSize
              << "; elements per level";
    for (std::size_t n : report.elementsPerLevel) std::cout << ' ' << n;
    std::cout << "; octree built in " << report.refineSeconds << " s\n";
  }
  if (report.dg.local) {
    const LocalDgCheck& c = *report.dg.local;
    std::cout << "  DG checks (degree " << c.degree << ", " << c.elements
              << " elements: all but congruent grid cells): patch test error "
              << c.maxPatchTestError << ", rigid-mode failures " << c.elementsWithWrongRigidModes
              << ", " << report.dg.localSeconds << " s: " << (c.passed() ? "passed" : "FAILED")
              << "\n";
  }
  std::cout << "  time " << report.wallSeconds << " s (wall, reading and writing included)\n";
}

void run(const MeshCommandOptions& o, const CommonOptions& common, int& exitCode) {
  if (!o.mesh.cellSize && o.mesh.cells == 0)
    throw InputError("polydg mesh needs --cell H or --cells N");
  if (!isVolumeMeshPath(o.output)) throw InputError(o.output + ": the output must be a .vtu file");
  requireOutput(o.output, {o.input});
  if (!o.report.empty()) requireOutput(o.report, {o.input});

  const Stopwatch wall;
  SurfaceReadInfo info;
  TriangleSurface surface;
  try {
    surface = readSurface(o.input, &info);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  if (!common.quiet)
    for (const std::string& w : info.warnings) std::cerr << "polydg: warning: " << w << '\n';
  MeshReport report;
  report.readSeconds = wall.seconds();
  MeshOptions options = o.mesh;
  options.dgChecks = !o.skipDg;
  options.output = o.output;
  ProgressBar bar("slicing", common.quiet);
  options.progress = [&bar](double f) { bar.update(f); };
  try {
    Model::fromSurface(surface, options, report, o.input);
  } catch (const OutputError&) {
    throw;  // about the output, not the surface
  } catch (const InputError& e) {
    throw InputError(o.input + ": " + e.what());
  }
  bar.finish();
  report.wallSeconds = wall.seconds();
  if (!o.report.empty()) {
    nlohmann::json j = toJson(report);
    j["command"] = "mesh";
    j["input"]["file"] = o.input;
    j["input"]["warnings"] = info.warnings;
    writeJsonFile(o.report, j);
  }
  if (!common.quiet) printSummary(report);
  if (!report.passed()) {
    const auto failures = report.failures();
    std::cerr << "polydg: error: " << o.input << ": the new mesh failed its checks ("
              << (failures.empty() ? std::string("see the report") : failures.front())
              << "); nothing written\n";
  }
  exitCode = report.passed() ? 0 : 1;
}

}  // namespace

void addMeshCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<MeshCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Slice a closed surface with a grid into a polyhedral DG simulation mesh (VTU)");
  cmd->add_option("input", o->input, "surface file (OBJ, STL, PLY, OFF, glTF, ...)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "output simulation mesh (.vtu)")->required();
  auto* cell =
      cmd->add_option("--cell", o->mesh.cellSize, "grid cell edge length")->check(kPositive);
  auto* cells = cmd->add_option("--cells", o->mesh.cells,
                                "about N cells along the longest side of the bounding box")
                    ->check(CLI::Range(1, 4096));
  cell->excludes(cells);
  cmd->add_option("--report", o->report, "write a JSON report to this file");
  addChoice(*cmd, "--repair", o->mesh.repair, repairNames(),
            "repair broken input: fill closes holes, wrap alpha-wraps any soup");
  cmd->add_option(
         "--merge-slivers", o->mesh.sliverFraction,
         "merge slivers into a neighbour: volume below TAU cells, or 6 volume / area below "
         "TAU^(1/3) of a cell edge (thin slabs; 0: off)")
      ->check(finiteRange(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag("--adaptive", o->mesh.adaptive,
                "octree slicing: --cell/--cells give the finest cells, used where the surface "
                "passes; inside, cells as coarse as one level between face neighbours allows");
  cmd->add_flag("--no-dg", o->skipDg, "skip the DG checks (patch test, rigid modes) of the result");
  cmd->add_flag("--tets", o->mesh.tets,
                "write the output as tets (VTK_TETRA) for --method fem and fs-fem: each checked "
                "polyhedral element split into tets of exactly its volume (a cone from an "
                "interior point, or TetGen's tets where it is not star-shaped), conforming, the "
                "polyhedral mesh's vertices first");
  cmd->callback([o, &common, &exitCode] { run(*o, common, exitCode); });
}

}  // namespace polydg::cli
