// Merging elements of a PolyMesh: a general "merge these groups" operation, and sliver merging
// (tiny elements joined to the neighbour they share the most area with; the result may be
// non-convex, which DG allows).
#pragma once

#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// A new mesh in which the elements of each group form one element: `group[e]` is element e's
/// group, 0 .. groups-1, and new element g is group g. Faces between members of a group are
/// removed; all other faces are kept as they are, in their order. Vertices are kept (same ids).
/// The same mesh as PolyMesh::mergeElementGroups on a copy, built in parallel.
PolyMesh mergeElements(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                       std::size_t groups);

/// The counts of a sliver merge (see SliverMergeReport).
struct SliverMergeSummary {
  double threshold = 0.0;
  std::size_t slivers = 0, merged = 0, isolated = 0;
};

struct SliverMergeReport {
  double threshold = 0.0;            ///< absolute volume below which an element is a sliver
  std::size_t slivers = 0;           ///< elements below the threshold before merging
  std::size_t merged = 0;            ///< slivers merged into a neighbour
  std::size_t isolated = 0;          ///< slivers with no neighbour at all, left as they are
  std::vector<std::uint32_t> group;  ///< new element of each old element
};

/// Merges every element with volume below `volumeThreshold` into the neighbour across the
/// largest total shared face area, smallest first, until no sliver with a neighbour is left
/// (a merged pair that is still below the threshold keeps merging). Deterministic.
PolyMesh mergeSlivers(PolyMesh mesh, double volumeThreshold, SliverMergeReport* report = nullptr);

}  // namespace polydg
