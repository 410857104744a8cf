#include "polydg/mesh/meshing_benchmark.h"

#include <stdexcept>

#include "polydg/mesh/surface_shapes.h"

namespace polydg {

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
  run.valid = report.validation.passed;
  run.phases = report.timings;
  run.secondsTotal = report.seconds;
  return run;
}

std::vector<MeshingBenchmarkRun> runMeshingBenchmark(
    const std::vector<std::string>& models, const std::vector<int>& cellCounts,
    const std::function<void(const MeshingBenchmarkRun&)>& onRun) {
  std::vector<MeshingBenchmarkRun> runs;
  for (const std::string& model : models) {
    const TriangleSurface surface = benchmarkModel(model);
    for (int cells : cellCounts) {
      MeshingOptions options;
      options.cellsAlongLongest = cells;
      const MeshingResult result = meshSurface(surface, options);
      MeshingBenchmarkRun run = meshingBenchmarkRun(model, surface, cells, result.report);
      if (onRun) onRun(run);
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

}  // namespace polydg
