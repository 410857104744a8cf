#include "cli/bench/meshing_benchmark.h"

#include <stdexcept>

#include "physics/checks/dg_checks.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/surface_shapes.h"
#include "util/stopwatch.h"

namespace polydg::bench {

TriangleSurface benchmarkModel(const std::string& name) {
  if (name == "sphere") return uvSphere(Vec3(0.01, 0.02, 0.03), 1.0, 224, 224);
  if (name == "torus_knot") return torusKnot(2, 3, 1.0, 0.45, 0.15, 1000, 50);
  throw std::invalid_argument("unknown benchmark model '" + name + "' (sphere, torus_knot)");
}

MeshingBenchmarkRun meshingBenchmarkRun(const std::string& model, const TriangleSurface& surface,
                                        int cells, const MeshingReport& report) {
  MeshingBenchmarkRun run;
  run.model = model;
  run.triangles = surface.triangles.size();
  run.cells = cells;
  run.elements = report.elements;
  run.hexahedra = report.hexahedra;
  run.polyhedra = report.polyhedra;
  run.slivers_merged = report.slivers.merged;
  run.volumeRelError = report.volumeRelError;
  run.valid = report.geometry.passed;
  run.phases = report.timings;
  run.secondsTotal = report.seconds;
  return run;
}

MeshingCostRun runMeshingCostCase(const std::string& model, const TriangleSurface& surface,
                                  int cells) {
  MeshingOptions options;
  options.cellsAlongLongest = cells;
  const MeshingResult result = meshSurface(surface, options);
  MeshingCostRun run;
  run.meshing = meshingBenchmarkRun(model, surface, cells, result.report);
  for (const auto& [phase, seconds] : result.report.timings)
    if (phase == "validate") run.geometryCheckSeconds += seconds;
  const Stopwatch t0;
  LocalDgCheckOptions checks;
  MomentCache moments(result.mesh, 2 * checks.basis.degree);
  moments.update();
  const LocalDgCheck check = localDgChecks(result.mesh, moments, checks);
  run.dgCheckSeconds = t0.seconds();
  run.dgElements = check.elements;
  run.dgPassed = check.passed();
  return run;
}

}  // namespace polydg::bench
