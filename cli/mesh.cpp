// polydg mesh: a surface file in, a polyhedral DG simulation mesh (VTU) out, checked
// geometrically and by the element-local DG checks (degree 1).
#include <chrono>
#include <exception>
#include <iostream>
#include <optional>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>

#include "cli/commands.h"
#include "cli/json_reports.h"
#include "cli/progress.h"
#include "cli/report.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/physics/validation.h"

namespace polydg::cli {

namespace {

struct MeshCommandOptions {
  std::string input;
  std::string output;
  std::string report;
  std::optional<double> cell;
  int cells = 0;
  RepairMode repair = RepairMode::None;
  double sliverTau = MeshingOptions{}.sliverTau;
  bool skipDg = false;
};

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The local DG checks of the new mesh (degree 1) and their wall time with the moments.
struct DgOutcome {
  LocalDgCheck check;
  double seconds = 0.0;
};

/// Checks every element except whole grid cells, of which one stands for all: they are
/// congruent boxes bounded by exact axis-aligned squares, so their local equations are the
/// same up to translation (the geometric validation still covers each one). Moments are
/// computed for the checked elements and their neighbours only.
DgOutcome runDgChecks(const PolyMesh& mesh) {
  const auto t0 = std::chrono::steady_clock::now();
  LocalDgCheckOptions options;
  options.only.assign(mesh.numElements(), 1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numElements(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e)
                        options.only[e] = isGridHexahedron(mesh, ElementId(e)) ? 0 : 1;
                    });
  // The first grid cell stands for all.
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    if (options.only[e] == 0) {
      options.only[e] = 1;
      break;
    }
  DgOutcome out;
  out.check = localDgChecksOfSelection(mesh, options);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

void printSummary(const std::string& output, const MeshingReport& r,
                  const std::optional<DgOutcome>& dg, double wallSeconds) {
  std::cout << output << ": " << r.elements << " elements (" << r.hexahedra << " hexahedra, "
            << r.polyhedra << " polyhedra, " << r.nonconvex << " non-convex), " << r.faces
            << " faces; grid " << r.grid.cells[0] << "x" << r.grid.cells[1] << "x"
            << r.grid.cells[2] << " of " << r.grid.cellSize << "\n"
            << "  volume " << r.outputVolume << " (input " << r.inputVolume << ", relative error "
            << r.volumeRelError << "), slivers merged " << r.slivers.merged << ", validation "
            << (r.validation.passed ? "passed" : "FAILED") << "\n";
  for (const std::string& repair : r.repairs) std::cout << "  repair: " << repair << "\n";
  if (dg) {
    const LocalDgCheck& c = dg->check;
    std::cout << "  DG checks (degree " << c.degree << ", " << c.elements
              << " elements: all but congruent grid cells): patch test error "
              << c.maxPatchTestError << ", rigid-mode failures " << c.elementsWithWrongRigidModes
              << ", " << dg->seconds << " s: " << (c.passed() ? "passed" : "FAILED") << "\n";
    for (const std::string& m : failureMessages(c)) std::cout << "  " << m << "\n";
  }
  std::cout << "  time " << wallSeconds << " s (wall, reading and writing included)\n";
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
      cmd->add_option("--cell", o->cell, "grid cell edge length")->check(CLI::PositiveNumber);
  auto* cells = cmd->add_option("--cells", o->cells,
                                "about N cells along the longest side of the bounding box")
                    ->check(CLI::Range(1, 4096));
  cell->excludes(cells);
  cmd->add_option("--report", o->report, "write a JSON report to this file");
  const std::map<std::string, RepairMode> repairs{
      {"none", RepairMode::None}, {"fill", RepairMode::Fill}, {"wrap", RepairMode::Wrap}};
  cmd->add_option("--repair", o->repair,
                  "repair broken input: none, fill (close holes), wrap "
                  "(alpha wrap any soup)")
      ->transform(CLI::CheckedTransformer(repairs, CLI::ignore_case));
  cmd->add_option("--merge-slivers", o->sliverTau,
                  "merge elements smaller than TAU x cell volume into a neighbour (0: off)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag("--no-dg", o->skipDg, "skip the DG checks (patch test, rigid modes) of the result");
  cmd->callback([o, &common, &exitCode, cmd] {
    if (!o->cell && o->cells == 0) throw UserError("polydg mesh needs --cell H or --cells N");
    if (!isVolumeMeshPath(o->output))
      throw UserError(o->output + ": the output must be a .vtu file");
    requireDistinct(o->output, o->input);
    if (!o->report.empty()) requireDistinct(o->report, o->input);

    const auto commandStart = std::chrono::steady_clock::now();
    const auto readStart = commandStart;
    const TriangleSurface surface = readSurface(o->input);
    const double readSeconds = secondsSince(readStart);
    MeshingOptions options;
    options.cellSize = o->cell;
    options.cellsAlongLongest = o->cells;
    options.repair = o->repair;
    options.sliverTau = o->sliverTau;
    options.validate = false;  // below, beside the writing
    ProgressBar bar("slicing", common.quiet);
    options.progress = [&bar](double f) { bar.update(f); };
    MeshingResult result;
    try {
      result = meshSurface(surface, options);
    } catch (const InputError& e) {
      throw UserError(o->input + ": " + e.what());
    }
    bar.finish();
    // The file is written (whatever the checks find: a failed check exits 1 with the file
    // there to look at) while the mesh is validated and DG-checked, the three side by side:
    // they only read the mesh, and the writer's serial part (formatting and I/O) fills the
    // gaps of the checks' parallel loops. The DG checks presume a geometrically valid mesh
    // (faces shared properly), so their outcome counts only if the validation passed.
    result.report.timings.insert(result.report.timings.begin(), {"read", readSeconds});
    std::optional<DgOutcome> dg;
    double writeSeconds = 0.0;
    tbb::task_group tasks;
    tasks.run([&] {
      const auto writeStart = std::chrono::steady_clock::now();
      writeVtu(result.mesh, o->output);
      writeSeconds = secondsSince(writeStart);
    });
    std::exception_ptr dgFailure;
    try {
      tbb::parallel_invoke([&] { validateMeshing(result); },
                           [&] {
                             if (o->skipDg) return;
                             try {
                               dg = runDgChecks(result.mesh);
                             } catch (...) {
                               dgFailure = std::current_exception();
                             }
                           });
    } catch (...) {
      tasks.wait();
      throw;
    }
    tasks.wait();
    if (!result.report.validation.passed)
      dg.reset();
    else if (dgFailure)
      std::rethrow_exception(dgFailure);
    // Phase times as measured; they overlap, so "total" adds up more than the wall time.
    if (dg) result.report.timings.emplace_back("dg_checks", dg->seconds);
    result.report.timings.emplace_back("write", writeSeconds);
    const bool passed = result.report.validation.passed && (!dg || dg->check.passed());
    if (!o->report.empty()) {
      nlohmann::json report = toJson(result.report);
      // The whole command, read to write; less than "total" where phases overlap.
      report["timings_s"]["wall"] = secondsSince(commandStart);
      // The two parts of "slice" (not added to "total"): plane splits, then the mesh build.
      report["timings_s"]["slice_split"] = result.report.slice.secondsSplitting;
      report["timings_s"]["slice_build"] = result.report.slice.secondsBuilding;
      report["command"] = "mesh";
      report["input"]["file"] = o->input;
      report["output"]["file"] = o->output;
      nlohmann::json& validation = report["validation"];
      validation["geometry_passed"] = result.report.validation.passed;
      validation["passed"] = passed;
      validation["dg_checked"] = dg.has_value();
      if (dg) {
        validation.update(toJson(dg->check, dg->seconds));
        for (const std::string& m : failureMessages(dg->check)) validation["messages"].push_back(m);
      } else {
        validation["patch_test_error"] = nullptr;
        validation["rigid_mode_failures"] = nullptr;
        validation["dg_seconds"] = nullptr;
        validation["dg_passed"] = nullptr;
        report["timings_s"]["dg_checks"] = nullptr;
      }
      writeReport(o->report, report);
    }
    if (!common.quiet) printSummary(o->output, result.report, dg, secondsSince(commandStart));
    exitCode = passed ? 0 : 1;
    (void)cmd;
  });
}

}  // namespace polydg::cli
