// Plane cutting of a polyhedral mesh in place, without remeshing (paper section 10,
// "Cutting"; thesis Fig. 4.1). Every element the blade crosses is split into its connected
// pieces on each side; the new faces in the plane are boundary faces tagged `Cut` (the two
// sides are no longer coupled there); a face shared with a neighbour that the blade crosses is
// split so that both sides still share identical sub-faces; slivers are merged into a
// neighbour; only the faces an operation created or changed are re-integrated; and every
// operation is validated on the region it touched.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/plane.h"
#include "polydg/mesh/poly_mesh.h"
#include "polydg/physics/checks/check_reports.h"

namespace polydg {

/// The blade of a cut: its plane {x : normal . x = offset} (normal need not be unit length;
/// its minus side is normal . x < offset), or, when `polygon` is not empty, the convex planar
/// polygon with those corners, which lies in that plane.
struct Blade : Plane {
  std::vector<Vec3> polygon;  ///< empty: the whole plane

  /// Throws std::invalid_argument for a zero or non-finite normal or a non-finite offset.
  static Blade plane(const Vec3& normal, double offset);
  /// The plane of the corners with the polygon as blade. Throws std::invalid_argument if there
  /// are fewer than 3 corners, or they are not coplanar, not convex or degenerate.
  static Blade fromPolygon(std::vector<Vec3> corners);
  bool finite() const { return !polygon.empty(); }
};

/// Default sliver fraction, shared with meshing (MeshingOptions::sliverTau).
inline constexpr double kDefaultSliverFraction = 0.01;

struct CutOptions {
  /// +1: delete the pieces on the plus side (normal . x > offset) of the cut, -1: the minus
  /// side, 0: keep both. With a finite blade only pieces of split elements are removed.
  int removeSide = 0;
  /// Sliver pieces (isSliver(), mesh/merge_elements.h, with T = sliverFraction * the editor's
  /// reference volume: volume below T or 6 volume / area below T^(1/3)) are merged into the
  /// neighbour across their largest shared face (0: no merging).
  double sliverFraction = kDefaultSliverFraction;
  CheckLevel checks = CheckLevel::Local;
  /// Degree of the DG basis used by the DG checks.
  int checkDegree = 1;
};

/// Where the elements after an operation come from: element e of the result covers all or part
/// of the elements sources(e) of the mesh before it (a piece: its parent; a sliver merged into
/// a neighbour: the neighbour's sources first, then the sliver's). Elements the operation did
/// not change keep their id and come from themselves.
struct ElementLineage {
  std::unordered_map<std::uint32_t, std::vector<ElementId>> changed;  ///< ids not from themselves
  std::vector<ElementId> sources(ElementId e) const {
    const auto it = changed.find(e.value);
    return it == changed.end() ? std::vector<ElementId>{e} : it->second;
  }
};

/// One element to refine: split by each plane in turn, every piece made so far by the next
/// (three mid-planes: 1-to-8; one plane: 1-to-2). The new faces are interior faces.
struct ElementRefinement {
  ElementId element;
  std::vector<Plane> planes;  ///< 1 to 3
};

struct RefineOptions {
  /// A piece below this fraction of its element's volume / 2^planes is merged into the
  /// neighbour it shares most area with (0: never).
  double sliverFraction = kDefaultSliverFraction;
  CheckLevel checks = CheckLevel::Local;
  int checkDegree = 1;
};

/// What one operation did.
struct OperationReport {
  std::string op;                   ///< "cut", "cut_polygon", "merge" or "refine"
  std::size_t elementsSplit = 0;    ///< elements the blade (refine: their planes) divided
  std::size_t piecesCreated = 0;    ///< elements made from them (before sliver merging)
  std::size_t elementsRemoved = 0;  ///< pieces deleted by removeSide
  double volumeRemoved = 0.0;
  /// Pieces below this volume (the sliver fraction times the editor's reference volume) are
  /// slivers; 0 when merging was off.
  double sliverThreshold = 0.0;
  std::size_t slivers = 0, sliversMerged = 0, isolatedSlivers = 0;
  std::size_t facesReintegrated = 0;  ///< faces whose moments this operation computed
  std::size_t facesTotal = 0;         ///< faces of the mesh after it
  /// Finite blade: elements the blade's plane crosses at the polygon's edge, left whole.
  std::vector<ElementId> leftWhole;
  OperationCheck check;
  ElementLineage lineage;
  /// The elements the operation made or whose faces changed (ids after it, ascending): every
  /// other element has its id, shape and faces of before.
  std::vector<ElementId> touched;
  double seconds = 0.0;
};

}  // namespace polydg
