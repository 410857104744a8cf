// The meshing pipeline behind `polydg mesh`: check the input surface, orient or repair it,
// slice it with the grid, merge slivers, validate. One call, one report.
#pragma once

#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/merge_elements.h"
#include "polydg/mesh/slice.h"
#include "polydg/util/error.h"

namespace polydg {

enum class RepairMode { None, Fill, Wrap };

/// The range of lengths meshSurface() accepts: the largest side E of the surface's bounding box
/// and the cell size h must both lie in [kSmallestLength, kLargestLength] = [2^-100, 2^100]
/// (about 7.9e-31 to 1.27e30). Outside it meshSurface() refuses the surface (InputError) instead
/// of returning a mesh whose volumes and moments overflow or underflow in double precision.
///
/// Derivation. Downstream of meshing, lengths enter products only as differences from a local
/// origin (the bounding-box centre for the enclosed volume, an edge's endpoint for its crossing
/// with a grid plane, a face's first vertex and an element's reference point for moments);
/// absolute coordinates are only added to and compared (grid planes, exact rational
/// comparisons). The highest power of a length is in the element moments a degree-p DG basis
/// needs (p <= 3, physics/dg/dg_basis.h): int_K (x - o)^alpha dV with |alpha| = 2p = 6, at most
/// vol(K) diam(K)^6 <= diam(K)^9; below come face moments (diam^8), squared norms of area vectors
/// (diam^4) and volumes (diam^3). (The bases divide moments by diam^|alpha| before any other
/// product, so nothing of higher degree follows.) An element lies in the bounding box and in one
/// cell, so diam(K) <= sqrt(3) min(E, h).
/// - Overflow: at E = 2^100, (sqrt(3) E)^9 = 3^4.5 2^900 ~ 1.2e273, a factor ~2^116 (1e35) below
///   the largest double (1.8e308), left for sums over faces and elements and for shifting moments
///   between origins (binomial coefficients up to 20). Cell volumes h^3 (the sliver threshold)
///   bound h likewise.
/// - Underflow: a cell-sized element has degree-6 moments about its centre of about h^9 / 2^6; at
///   h = 2^-100 that is 2^-906, a factor 2^116 above the smallest normal double (2^-1022), which
///   keeps at full precision the moments of pieces down to 1e-35 of a cell (slivers), where
///   E = h = 1e-300 would give volumes of 1e-900, zero in double.
/// |coordinates| need no bound of their own: a surface that encloses volume has two distinct
/// values on each axis, so E >= ulp(C) ~ C 2^-52 for its largest |coordinate| C, and E <= 2^100
/// keeps C below 2^153 (~1e46), where sums like C + E are far from overflowing.
inline constexpr double kLargestLength = 0x1p100;
inline constexpr double kSmallestLength = 0x1p-100;

struct MeshingOptions {
  /// Cell edge length; if unset, `cellsAlongLongest` cells along the bounding box's longest side.
  std::optional<double> cellSize;
  int cellsAlongLongest = 0;
  RepairMode repair = RepairMode::None;
  /// Slivers by isSliver (polydg/mesh/merge_elements.h) with the volume threshold sliverTau *
  /// cell volume (volume below it, or 6 volume / area below its cube root) are merged into a
  /// neighbour. The default, 1% of a cell, removes the small and thin elements that make the DG
  /// stiffness ill-conditioned (the condition estimate stays within 100x of the regular grid's
  /// for every piece size, B4) while leaving nearly every boundary element as sliced. 0
  /// disables merging.
  double sliverTau = 0.01;
  /// Octree slicing (sliceSurfaceOctree): 0 slices with the uniform grid of the cell size; L > 0
  /// takes the cell size for the coarse cells and refines L levels at the surface (slivers
  /// are then measured against the finest cell).
  int octreeLevels = 0;
  ProgressFn progress;
  /// Validate the result and count its shapes at the end of meshSurface(). A caller that
  /// overlaps that work with something else (writing the mesh) turns this off and calls
  /// checkMeshing() itself.
  bool checkGeometry = true;
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
  GeometryCheck geometry;

  // Wall time per phase, seconds. Phases may overlap (the check runs beside the slicing of a
  // closed surface), so they can add up to more than `seconds`.
  std::vector<std::pair<std::string, double>> timings;
  /// Wall time of meshSurface() and checkMeshing() together, seconds.
  double seconds = 0.0;
};

struct MeshingResult {
  PolyMesh mesh;
  MeshingReport report;
  /// Octree slicing: each element's level (0: a coarse cell, MeshingOptions::octreeLevels: the
  /// finest); empty for the uniform grid.
  std::vector<int> elementLevels;
  /// Uniform grid: per element, 1 for a whole cell that rounding and merging left alone (see
  /// sliceSurface); may be empty.
  std::vector<char> wholeCells;
};

/// Runs the pipeline on a surface as read from a file. Throws InputError for input it refuses
/// (open, non-manifold or self-intersecting without a repair mode; empty; a non-finite
/// coordinate; a bounding box or cell size outside [kSmallestLength, kLargestLength], named as
/// overflow or underflow with the largest coordinate; a repair that failed).
MeshingResult meshSurface(const TriangleSurface& surface, const MeshingOptions& options);

/// The geometric validation of `result.mesh` and the output part of its report (elements,
/// faces, volume and its error, hexahedra, polyhedra, non-convex), timed as phase "validate".
/// meshSurface() ends with it unless MeshingOptions::validate is false.
void checkMeshing(MeshingResult& result);
/// The same for a mesh kept apart from its report (moved into a model before validation).
/// `wholeCells` (empty, or MeshingResult::wholeCells) spares measuring the shapes of the whole
/// cells, which are grid hexahedra, and testing their closure one by one (checkGeometry's
/// `boxes`); `volumes` (empty, or the mesh's signedVolumes()) spares computing the elements'
/// volumes.
void checkMeshing(const PolyMesh& mesh, MeshingReport& report,
                  const std::vector<char>& wholeCells = {}, std::span<const double> volumes = {});

}  // namespace polydg
