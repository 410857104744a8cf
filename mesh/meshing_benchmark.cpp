#include "mesh/meshing_benchmark.h"

#include <stdexcept>

#include "mesh/surface_shapes.h"

namespace polydg {

TriangleSurface benchmarkModel(const std::string& name) {
  if (name == "sphere") return uvSphere(Vec3(0.01, 0.02, 0.03), 1.0, 224, 224);
  if (name == "torus_knot") return torusKnot(2, 3, 1.0, 0.45, 0.15, 1000, 50);
  throw std::invalid_argument("unknown benchmark model '" + name + "' (sphere, torus_knot)");
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
      const MeshingReport& r = result.report;
      MeshingBenchmarkRun run;
      run.model = model;
      run.triangles = surface.triangles.size();
      run.cells = cells;
      run.elements = r.elements;
      run.hexahedra = r.hexahedra;
      run.polyhedra = r.polyhedra;
      run.slivers_merged = r.slivers.merged;
      run.volumeRelError = r.volumeRelError;
      run.valid = r.validation.passed;
      run.phases = r.timings;
      for (const auto& [phase, seconds] : r.timings) run.secondsTotal += seconds;
      if (onRun) onRun(run);
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

}  // namespace polydg
