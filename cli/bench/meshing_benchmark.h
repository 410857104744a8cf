// The meshing benchmark: elements, volume error and time per phase against cell count for
// generated models of known size (a ~100k-triangle sphere and a torus knot of similar size) and
// bundled ones, with the cost of validating the result (geometric checks and local DG checks).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "polydg/mesh/meshing.h"

namespace polydg::bench {

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
/// "torus_knot" ((2,3) knot tube, 100,000 triangles). Throws std::invalid_argument for another
/// name.
TriangleSurface benchmarkModel(const std::string& name);

/// The run of `model` (`surface`) meshed at `cells` cells, from the pipeline's report.
MeshingBenchmarkRun meshingBenchmarkRun(const std::string& model, const TriangleSurface& surface,
                                        int cells, const MeshingReport& report);

/// The meshing benchmark with the cost of validating the result: the meshing pipeline
/// (meshSurface() with default options; its phases include the geometric validation
/// "validate") followed by the local DG checks (degree 1) of every element, with the degree 2
/// moments they need.
struct MeshingCostRun {
  MeshingBenchmarkRun meshing;
  double geometryCheckSeconds = 0.0;  ///< the "validate" phase of meshing
  double dgCheckSeconds = 0.0;        ///< moments + localDgChecks(), wall
  std::size_t dgElements = 0;
  bool dgPassed = false;
};

/// Meshes `surface` (named `model` in the run) with `cells` cells along its longest side.
/// Throws InputError as meshSurface() does.
MeshingCostRun runMeshingCostCase(const std::string& model, const TriangleSurface& surface,
                                  int cells);

}  // namespace polydg::bench
