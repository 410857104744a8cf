// The meshing pipeline behind `polydg mesh`: check the input surface, orient or repair it,
// slice it with the grid, merge slivers, validate. One call, one report.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "polydg/mesh/merge_elements.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/validate.h"
#include "polydg/util/error.h"

namespace polydg {

enum class RepairMode { None, Fill, Wrap };

struct MeshingOptions {
  /// Cell edge length; if unset, `cellsAlongLongest` cells along the bounding box's longest side.
  std::optional<double> cellSize;
  int cellsAlongLongest = 0;
  RepairMode repair = RepairMode::None;
  /// Elements smaller than sliverTau * cell volume are merged into a neighbour. The default,
  /// 1% of a cell, removes the slivers that make the DG stiffness ill-conditioned while
  /// leaving nearly every boundary element as sliced. 0 disables merging.
  double sliverTau = 0.01;
  ProgressFn progress;
  /// Validate the result and count its shapes at the end of meshSurface(). A caller that
  /// overlaps that work with something else (writing the mesh) turns this off and calls
  /// validateMeshing() itself.
  bool validate = true;
};

struct MeshingReport {
  // Input (after reading, before any change).
  std::size_t inputVertices = 0, inputTriangles = 0;
  bool inputClosed = false;
  bool inputManifold = false;
  std::size_t selfIntersections = 0;
  bool selfIntersectionsChecked = false;
  double inputVolume = 0.0;  ///< enclosed volume of the surface that was sliced
  std::size_t shells = 0, cavities = 0;
  std::vector<std::string> repairs;  ///< what was done to the input, one line each
  double volumeBeforeRepair = 0.0;   ///< when a repair ran: the input's enclosed volume before

  Grid grid;
  SliceStats slice;
  SliverMergeSummary slivers;

  // Output.
  std::size_t elements = 0, hexahedra = 0, polyhedra = 0, nonconvex = 0;
  std::size_t faces = 0, interiorFaces = 0, boundaryFaces = 0;
  double outputVolume = 0.0;
  double volumeRelError = 0.0;
  ValidationReport validation;

  // Wall time per phase, seconds. Phases may overlap (the check runs beside the slicing of a
  // closed surface), so they can add up to more than `seconds`.
  std::vector<std::pair<std::string, double>> timings;
  /// Wall time of meshSurface() and validateMeshing() together, seconds.
  double seconds = 0.0;
};

struct MeshingResult {
  PolyMesh mesh;
  MeshingReport report;
};

/// Runs the pipeline on a surface as read from a file. Throws InputError for input it refuses
/// (open, non-manifold or self-intersecting without a repair mode; empty; a repair that failed).
MeshingResult meshSurface(const TriangleSurface& surface, const MeshingOptions& options);

/// The geometric validation of `result.mesh` and the output part of its report (elements,
/// faces, volume and its error, hexahedra, polyhedra, non-convex), timed as phase "validate".
/// meshSurface() ends with it unless MeshingOptions::validate is false.
void validateMeshing(MeshingResult& result);
/// The same for a mesh kept apart from its report (moved into a model before validation).
void validateMeshing(const PolyMesh& mesh, MeshingReport& report);

}  // namespace polydg
