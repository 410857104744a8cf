// A triangle surface (the input of meshing) and its basic properties: edge topology, whether it
// is closed and consistently oriented, its bounding box and enclosed volume.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg {

/// A triangle soup with shared vertices: #V positions and #T triangles of vertex indices.
struct TriangleSurface {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Edge-based facts about a surface.
struct SurfaceTopology {
  std::size_t edges = 0;
  std::size_t boundaryEdges = 0;        ///< used by one triangle
  std::size_t nonManifoldEdges = 0;     ///< used by three or more triangles
  std::size_t misorientedEdges = 0;     ///< used twice in the same direction
  std::size_t degenerateTriangles = 0;  ///< two equal vertex indices or zero area
  std::size_t components = 0;           ///< connected through shared edges
  /// Vertices whose triangles form more than one fan through the edges pairs of them share (two
  /// parts of the surface touching at a point): counted on edges used by exactly two triangles.
  std::size_t singularVertices = 0;
  /// Closed: every edge used by exactly two triangles in opposite directions.
  bool closed() const {
    return boundaryEdges == 0 && nonManifoldEdges == 0 && misorientedEdges == 0;
  }
};

SurfaceTopology analyzeTopology(const TriangleSurface& surface);

/// Bounding box of the vertices (empty box for an empty surface).
Box3 bounds(const TriangleSurface& surface);

/// Signed enclosed volume, sum of signed tetrahedra from the bounding-box centre to each
/// triangle (positive for outward orientation). Meaningful for closed surfaces.
double enclosedVolume(const TriangleSurface& surface);

/// Total triangle area.
double surfaceArea(const TriangleSurface& surface);

/// A mesh of one element bounded by the surface's triangles, each a face tagged `Surface`.
/// The surface should be closed and oriented outward (not checked here; see checkGeometry()).
PolyMesh singleElementMesh(const TriangleSurface& surface);

}  // namespace polydg
