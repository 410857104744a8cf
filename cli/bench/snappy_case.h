// An OpenFOAM case that has snappyHexMesh mesh a surface at the resolution of `polydg mesh
// --cells N` (the openfoam suite): blockMesh's background cells are polydg's grid cells, one
// more layer around them, and snappyHexMesh refines nothing, so both meshers start from the
// same cells; surfaceFeatureExtract gives snappyHexMesh the surface's feature edges.
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include "cli/bench/surface_distance.h"
#include "polydg/mesh/surface.h"

namespace polydg::bench {

/// How the case is set up.
struct SnappySetup {
  /// The surface's name: constant/triSurface/NAME.stl, and the patch snappyHexMesh makes.
  std::string surface;
  /// blockMesh's one block: polydg's grid (Grid::withCellsAlongLongest) with one more cell on
  /// each of its six sides, cells of edge `cellSize`.
  Vec3 blockMin, blockMax;
  std::array<int, 3> blockCells{};
  double cellSize = 0.0;
  /// snappyHexMesh's locationInMesh: the block cell centre deepest inside the surface, `depth`
  /// from it (at least half a cell's diagonal: its cell lies wholly inside).
  Vec3 locationInMesh;
  double depth = 0.0;
  /// Refinement level of the surface and its features (0: the block's cells, as polydg's grid).
  int surfaceLevel = 0;
  /// surfaceFeatureExtract: an edge whose triangles meet at less than this angle (degrees) is a
  /// feature.
  double includedAngle = 150.0;
};

/// The setup for `surface` (closed; `distance` built on it) at `cells` cells along the longest
/// side of its bounding box, named `name` (a word: letters, digits, '_'). Throws InputError if
/// no block cell lies wholly inside the surface.
SnappySetup snappySetup(const TriangleSurface& surface, const SurfaceDistance& distance, int cells,
                        const std::string& name);

/// Writes the case into `dir` (created): system/controlDict (ASCII, 17 digits), fvSchemes,
/// fvSolution, blockMeshDict, surfaceFeatureExtractDict and snappyHexMeshDict (castellated
/// and snapped, no layers, OpenFOAM's default mesh quality controls written out), and
/// constant/triSurface/NAME.stl (ASCII, 17 significant digits). Throws InputError if a file
/// cannot be written.
void writeSnappyCase(const std::filesystem::path& dir, const TriangleSurface& surface,
                     const SnappySetup& setup);

}  // namespace polydg::bench
