// Checks of an input surface before slicing (closed, manifold, self-intersections, degenerate
// triangles, orientation, shells and cavities) and repairs of broken surfaces, with CGAL.
#pragma once

#include <atomic>
#include <cstddef>
#include <optional>
#include <string>

#include "polydg/mesh/surface.h"

namespace polydg {

/// What is wrong with a surface, as counts.
struct SurfaceDiagnosis {
  SurfaceTopology topology;
  std::size_t selfIntersections = 0;      ///< pairs of triangles that intersect improperly
  bool checkedSelfIntersections = false;  ///< only possible on a manifold (orientable) soup
  std::size_t shells = 0;                 ///< connected components (see orientToBoundVolume)

  bool closed() const { return topology.closed() || misorientedOnly(); }
  bool manifold() const { return topology.nonManifoldEdges == 0; }
  /// Closed except for inconsistent orientation, which re-orientation fixes.
  bool misorientedOnly() const {
    return topology.boundaryEdges == 0 && topology.nonManifoldEdges == 0 &&
           topology.misorientedEdges > 0;
  }
};

/// The self-intersections diagnose() counts for a surface closed edge by edge, manifold and
/// without singular vertices or degenerate triangles (analyzeTopology() says which), counted
/// on the soup: CGAL's box intersection, and CGAL's test of two faces of a mesh on each pair
/// (no mesh is built). Any soup can be given (the count then means nothing), so that the test
/// can start before the topology is known; nothing if `stop` turned true before it ended.
std::optional<std::size_t> selfIntersectionsOfClosedSurface(
    const TriangleSurface& surface, const std::atomic<bool>* stop = nullptr);

/// Whether diagnose() counts the self-intersections of a surface of this topology as
/// selfIntersectionsOfClosedSurface() does.
bool isClosedManifoldSoup(const SurfaceTopology& topology);

/// Counts the defects of `surface`. Self-intersections are looked for when the surface can be
/// made a manifold mesh (that is, when every edge has at most two triangles).
/// `topology` is analyzeTopology()'s result if the caller has it (computed if null);
/// `closedSurfaceCount`, selfIntersectionsOfClosedSurface()'s if the caller has it (used if the
/// topology is one it applies to).
SurfaceDiagnosis diagnose(const TriangleSurface& surface, const SurfaceTopology* topology = nullptr,
                          std::optional<std::size_t> closedSurfaceCount = std::nullopt);

/// Orients a closed, manifold, non-self-intersecting surface so that it bounds a volume: outer
/// shells outward, cavities inward (CGAL's orient_to_bound_a_volume, after making the
/// orientation consistent). `changed` says whether any triangle was flipped; `shells` and
/// `cavities` (optional) receive the number of closed components and of those nested at odd
/// depth (holes in the solid). A surface of one shell whose triangles are consistently
/// oriented already (`topology`, analyzeTopology()'s result, computed if null: closed, one
/// component, no singular vertex or degenerate triangle) takes a shortcut: the sign of its
/// enclosed volume, exact through interval arithmetic, says whether to flip every triangle or
/// none, far cheaper than CGAL's path; a volume within round-off of zero
/// takes CGAL's path.
TriangleSurface orientToBoundVolume(const TriangleSurface& surface, bool& changed,
                                    std::size_t* shells = nullptr, std::size_t* cavities = nullptr,
                                    const SurfaceTopology* topology = nullptr);

/// Removes triangles with repeated vertices or zero area, welding their edges away (CGAL's
/// remove_degenerate_faces on the soup made into a mesh). Returns how many were removed.
std::size_t removeDegenerateTriangles(TriangleSurface& surface);

/// Closes the holes of an orientable surface by triangulating each boundary loop (CGAL's hole
/// filling). Throws if the surface is non-manifold. `filled` receives the number of holes.
TriangleSurface fillHoles(const TriangleSurface& surface, std::size_t& filled);

/// CGAL's 3D alpha wrapping of any triangle soup: a closed, manifold, watertight surface that
/// encloses the input at distance `offset`, with no cavity narrower than about `alpha`.
TriangleSurface alphaWrap(const TriangleSurface& surface, double alpha, double offset);

}  // namespace polydg
