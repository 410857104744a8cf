// The meshing benchmark: elements, volume error and time per phase against cell count for
// generated models of known size (a ~100k-triangle sphere and a torus knot of similar size).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "polydg/mesh/meshing.h"

namespace polydg {

struct MeshingBenchmarkRun {
  std::string model;
  std::size_t triangles = 0;
  int cells = 0;  ///< cells along the longest side
  std::size_t elements = 0, hexahedra = 0, polyhedra = 0, slivers_merged = 0;
  double volumeRelError = 0.0;
  bool valid = false;
  double secondsTotal = 0.0;  ///< wall time of the whole pipeline (check ... validate)
  std::vector<std::pair<std::string, double>> phases;
};

/// The generated models of the benchmark, by name: "sphere" (UV sphere, 99,904 triangles) and
/// "torus_knot" ((2,3) knot tube, 100,000 triangles).
TriangleSurface benchmarkModel(const std::string& name);

/// The run of `model` (`surface`) meshed at `cells` cells, from the pipeline's report.
MeshingBenchmarkRun meshingBenchmarkRun(const std::string& model, const TriangleSurface& surface,
                                        int cells, const MeshingReport& report);

/// Meshes each model at each cell count and reports one run per pair; `onRun` (optional) is
/// called after each.
std::vector<MeshingBenchmarkRun> runMeshingBenchmark(
    const std::vector<std::string>& models, const std::vector<int>& cellCounts,
    const std::function<void(const MeshingBenchmarkRun&)>& onRun = {});

}  // namespace polydg
