// The state a MeshEditor keeps between operations, and the steps its operations (cut.cpp,
// refine.cpp) share. Private to cut/.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "cut/element_grid.h"
#include "edit.h"
#include "piece_splitter.h"
#include "polydg/cut/cut.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/plane.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

struct MeshEditor::State {
  PolyMesh mesh;
  std::unique_ptr<MomentCache> moments;
  ElementGrid grid;
  double referenceVolume = 0.0;
  double volume = 0.0;
  std::vector<char> region;  ///< scratch for the DG region, by element (kept all zero)
  /// The planes each vertex lies on by construction (indices into `planes`): the plane of the
  /// cut that made it, and the planes both ends of its edge lay on. A later cut by one of them
  /// sees it on the plane (its rounded position may not be).
  std::vector<cut_detail::PlaneTags> vertexPlane;
  std::vector<Plane> planes;  ///< the plane of every cut so far
  /// Faces integrated by caches this editor has replaced with ones of higher degree.
  std::size_t retiredIntegrations = 0;
};

namespace cut_detail {

/// Points an operation made on edges: (a, b) -> p, mesh vertex ids, a < b.
using EdgePoints = std::map<std::pair<std::uint32_t, std::uint32_t>, VertexId>;

/// The id of `plane` among the editor's planes (added if new).
std::uint32_t planeIdOf(MeshEditor::State& s, const Plane& plane);

/// Faces the splitter split that an element left whole still uses: that element takes all the
/// parts.
void attachSplitFaceParts(Edit& edit, Splitter& splitter);

/// Tags the new points (ids from `oldVertices` on) with the earlier planes both ends of their
/// edge lie on: a later cut by one of them sees them on it.
void tagEdgePoints(MeshEditor::State& s, const EdgePoints& points, std::size_t oldVertices);

/// Inserts the points into the edges they divide on every face of `elements` (no T-junctions).
void insertEdgePoints(Edit& edit, const std::vector<ElementId>& elements, const EdgePoints& points);

/// The end of an operation: compaction, the grid and the volume brought up to date, lineage,
/// checks and volume balance. `volumeBefore` is the volume before it.
void finishOperation(MeshEditor::State& s, Edit& edit, double volumeBefore, CheckLevel level,
                     int degree, double sliverThreshold, OperationReport& report);

}  // namespace cut_detail
}  // namespace polydg
