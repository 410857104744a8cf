// Merging elements of a PolyMesh: a general "merge these groups" operation, and sliver merging
// (small or thin elements joined to the neighbour they share the most area with; the result may
// be non-convex, which DG allows). The sliver rule and the greedy merge here are the ones both
// slicing (mergeSlivers) and cutting (MeshEditor, cut/edit.cpp) run.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// A new mesh in which the elements of each group form one element: `group[e]` is element e's
/// group, 0 .. groups-1, or kDroppedElement, and new element g is group g. Faces between members
/// of a group, and faces of dropped elements, are removed; all other faces are kept as they are,
/// in their order. Vertices are kept (same ids). PolyMesh::mergeElementGroups on a copy; a
/// caller that owns the mesh merges in place instead.
PolyMesh mergeElements(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                       std::size_t groups);

/// The counts of a sliver merge (see SliverMergeReport).
struct SliverMergeSummary {
  double threshold = 0.0;
  std::size_t slivers = 0, merged = 0, isolated = 0;
};

struct SliverMergeReport {
  double threshold = 0.0;            ///< the volume threshold T of isSliver()
  std::size_t slivers = 0;           ///< elements that were slivers before merging
  std::size_t merged = 0;            ///< slivers merged into a neighbour
  std::size_t isolated = 0;          ///< slivers with no neighbour at all, left as they are
  std::vector<std::uint32_t> group;  ///< new element of each old element
};

/// The size the sliver rule compares, a length: min(V^(1/3), 6 V / A) for an element of volume V
/// and surface area A (all its faces). 6 V / A is the edge of the cube with the same volume to
/// area ratio: s for a cube of edge s, about 3 t for a slab of thickness t (whatever its other
/// two sides), 1.5 t for a needle of section t x t. It measures the element's thinnest direction,
/// which sets the stiffness' largest eigenvalue (~ 1 / t^2 in an orthonormal basis).
double sliverSize(double volume, double area);

/// The sliver rule of slicing and cutting: an element is a sliver under the volume threshold T
/// (the sliver fraction tau times the reference volume h^3, the grid cell's) when
/// sliverSize(V, A)^3 < T, i.e. when V < T (the volume rule) or 6 V / A < T^(1/3) = tau^(1/3) h
/// (a thin piece of any volume: for tau = 0.01, slabs thinner than 0.084 h). T = 0: no slivers.
bool isSliver(double volume, double area, double volumeThreshold);

/// The greedy sliver merge of slicing and cutting: the slivers among `candidates` (isSliver with
/// `volumeThreshold`), thinnest first (smallest sliverSize, then smallest id), each merged into
/// the neighbouring group across the largest total shared interior face area, and again while
/// the merged group is a sliver, until it is none or has no neighbour. `Groups` holds the
/// current grouping of elements (ids std::uint32_t):
///   std::optional<std::uint32_t> group(std::uint32_t e): the group now holding candidate e,
///     or nullopt to skip it;
///   double volume(std::uint32_t g), double area(std::uint32_t g): the group's volume and
///     surface area (boundary and interior faces, not those inside the group);
///   void sharedAreas(std::uint32_t g, std::map<std::uint32_t, double>& shared): the interior
///     face area g shares with each other group (`shared` is empty on entry);
///   std::uint32_t merge(std::uint32_t g, std::uint32_t target, double sharedArea): joins g
///     into target (sharedArea: the interior face area between them, which disappears) and
///     returns the group holding both.
/// Deterministic. Returns the counts (threshold, slivers, merged, isolated: slivers that merged
/// nothing because they had no neighbour).
template <class Groups>
SliverMergeSummary mergeSliverGroups(const std::vector<std::uint32_t>& candidates,
                                     double volumeThreshold, Groups& groups) {
  SliverMergeSummary r;
  r.threshold = volumeThreshold;
  std::vector<std::pair<double, std::uint32_t>> order;  // (sliverSize, element)
  for (std::uint32_t e : candidates) {
    const double v = groups.volume(e), a = groups.area(e);
    if (isSliver(v, a, volumeThreshold)) order.emplace_back(sliverSize(v, a), e);
  }
  std::sort(order.begin(), order.end());
  r.slivers = order.size();
  std::map<std::uint32_t, double> shared;
  for (const auto& [size, e] : order) {
    std::optional<std::uint32_t> g = groups.group(e);
    bool merged = false;
    while (g && isSliver(groups.volume(*g), groups.area(*g), volumeThreshold)) {
      shared.clear();
      groups.sharedAreas(*g, shared);
      if (shared.empty()) {
        if (!merged) ++r.isolated;
        break;
      }
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      g = groups.merge(*g, best->first, best->second);
      ++r.merged;
      merged = true;
    }
  }
  return r;
}

/// Merges the slivers of `mesh` (isSliver with `volumeThreshold`, the sliver fraction times the
/// grid cell's volume) by mergeSliverGroups: every element that is a sliver, until none with a
/// neighbour is left. Deterministic. `wholeCells` (empty, or one flag per element) marks whole
/// cells of a grid (sliceSurface): the caller knows they are no slivers (the threshold is well
/// below a cell's volume), so they are not measured unless a sliver joins them; the result is
/// the same as without the flags.
PolyMesh mergeSlivers(PolyMesh mesh, double volumeThreshold, SliverMergeReport* report = nullptr,
                      const std::vector<char>& wholeCells = {});

/// What mergeDegenerateElements() did.
struct DegenerateMergeReport {
  std::size_t merged = 0;            ///< merges of two groups of elements
  std::size_t dropped = 0;           ///< elements left out: flat, and sharing no face with another
  std::vector<std::uint32_t> group;  ///< new element of each old element, or kDroppedElement
};

/// Repairs what rounding exact geometry to doubles leaves where a part of the solid is thinner
/// than the coordinates resolve (a mesh made exactly, as slicing makes it, is otherwise valid):
/// the two elements of a degenerate interior face (isDegenerateFace) become one, and a group of
/// elements whose volume (the sum of its elements' signedVolume) is not positive joins the
/// neighbouring group it shares the most face area with, until it is positive. A group with no
/// neighbour left is dropped, with its faces (all on the boundary). The groups are numbered in
/// order of their first element. Deterministic; the mesh is returned as it is when nothing is
/// degenerate (the usual case). `wholeCells` (empty, or one flag per element) marks whole grid
/// cells that rounding left alone (sliceSurface): boxes of positive volume whose faces are not
/// degenerate, which are measured only if a group joins them; the result is the same as
/// without the flags.
PolyMesh mergeDegenerateElements(PolyMesh mesh, DegenerateMergeReport* report = nullptr,
                                 const std::vector<char>& wholeCells = {});

}  // namespace polydg
