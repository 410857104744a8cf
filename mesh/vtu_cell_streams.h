// The cell arrays of writeVtu's file (Cells/connectivity, offsets, types, faces, faceoffsets)
// and polydg's restore arrays, generated chunk by chunk from a few integers per cell instead of
// held whole, so that writing a mesh takes memory in proportion to its cells, not its file.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/point_groups.h"
#include "mesh/vtk_format.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// The records (simple polygons) that stand for each face in the file, in the face's own
/// orientation: the face's one loop, or the triangles of triangulateFace for a face with holes.
class FaceRecords {
 public:
  /// Triangulates the faces with holes (throws std::runtime_error as triangulateFace does).
  explicit FaceRecords(const PolyMesh& mesh);

  std::size_t count(FaceId f) const {
    if (!isHoled_[f.index()]) return 1;
    const std::size_t i = holed(f);
    return holedBegin_[i + 1] - holedBegin_[i];
  }
  /// Record k (< count(f)) of face f.
  std::span<const VertexId> record(FaceId f, std::size_t k) const {
    if (!isHoled_[f.index()]) return {mesh_.face(f).vertices.data(), mesh_.face(f).vertices.size()};
    return {triangles_[holedBegin_[holed(f)] + k].data(), 3};
  }

 private:
  /// The position in holed_ of face f, which has holes (or no loop, and then no record).
  std::size_t holed(FaceId f) const;

  const PolyMesh& mesh_;
  /// Per face, whether it has other than one loop: a bit per face, so that counting records
  /// reads no face.
  std::vector<bool> isHoled_;
  std::vector<FaceId> holed_;            ///< the faces of other than one loop, in id order
  std::vector<std::size_t> holedBegin_;  ///< holed_[i]'s: triangles_[holedBegin_[i] .. [i + 1])
  std::vector<std::array<VertexId, 3>> triangles_;
};

/// Running ends of per-cell counts: the run of cell c is [begin(c), end(c)). Stored in 32 bits
/// when the total fits, in 64 otherwise.
class RunningEnds {
 public:
  RunningEnds() = default;
  /// The ends of `counts` (counts[c] for cell c), computed in the storage of `counts`.
  explicit RunningEnds(std::vector<std::uint32_t> counts);

  std::size_t size() const { return narrow_.size() + wide_.size(); }
  std::uint64_t end(std::size_t c) const { return wide_.empty() ? narrow_[c] : wide_[c]; }
  std::uint64_t begin(std::size_t c) const { return c == 0 ? 0 : end(c - 1); }
  std::uint64_t total() const { return size() == 0 ? 0 : end(size() - 1); }
  /// The cell whose run holds position `at` (< total()): the first cell c with end(c) > at.
  std::size_t cellAt(std::uint64_t at) const;

 private:
  std::vector<std::uint32_t> narrow_;
  std::vector<std::uint64_t> wide_;
};

/// The cells of writeVtu's file and the arrays that describe them (their layout is documented
/// at writeVtu in polydg/mesh/vtu_io.h). Cell c is element elements()[c]: elements in increasing
/// order of their point count, stably (see kElementArray). Point ids are VTU points (see
/// PointGroups), not mesh vertices.
///
/// It holds each element's corners (those of a flagged grid box are read from its first two
/// sides instead, see ElementCorners) and their points, the cell order and the running ends of
/// each cell's connectivity, face records and `faces` run; the arrays are made from them a
/// range at a time when written. It keeps a reference to `mesh`, which must outlive it, and the
/// arrays it hands out refer to it, so it can be neither copied nor moved.
class CellStreams {
 public:
  /// Throws std::runtime_error if a face with holes cannot be triangulated. `boxes` (empty, or
  /// one per element): elements known to be whole grid cells (six single-loop sides of four
  /// corners, eight corners in all), counted without numbering their corners and, where their
  /// first two sides are opposite (as slicing makes them), with corners read from those sides,
  /// not held; std::logic_error if one is not a grid cell.
  explicit CellStreams(const PolyMesh& mesh, std::span<const char> boxes = {});
  CellStreams(const CellStreams&) = delete;
  CellStreams& operator=(const CellStreams&) = delete;

  std::size_t numCells() const { return order_.size(); }
  /// Per cell, the element written as it.
  std::span<const ElementId> elements() const { return order_; }
  /// Each element's corners in order of first use by its face records.
  const ElementCorners& corners() const { return corners_; }
  const PointGroups& points() const { return points_; }

  // The arrays, as vtk_format::GeneratedInts: values made on demand from several threads at
  // once, the largest known beforehand.
  vtk_format::GeneratedInts connectivity() const;  ///< per cell, its corners' points
  vtk_format::GeneratedInts offsets() const;       ///< per cell, its end in connectivity
  vtk_format::GeneratedInts types() const;         ///< per cell, VTK_POLYHEDRON
  /// Per cell, its number of face records, then per record its number of points and the points.
  vtk_format::GeneratedInts faces() const;
  vtk_format::GeneratedInts faceOffsets() const;   ///< per cell, its end in faces
  vtk_format::GeneratedInts faceGroup() const;     ///< per record, its face
  vtk_format::GeneratedInts faceReversed() const;  ///< per record, 1 if reversed, else 0
  vtk_format::GeneratedInts faceOrigin() const;    ///< per face, its FaceOrigin
  vtk_format::GeneratedInts element() const;       ///< per cell, its element
  vtk_format::GeneratedInts pointVertex() const;   ///< per point, its vertex

 private:
  /// The largest values of the arrays whose largest is not an end or a count.
  struct Largest {
    std::int64_t point = 0, recordsPerCell = 0, recordSize = 0, face = 0, reversed = 0;
    std::int64_t origin = 0, vertex = 0;
    std::int64_t cornerVertex = 0;  ///< of the vertices that are corners (the points, if unsplit)
  };

  /// Each element's corners, counted in a first pass (which also checks the flagged boxes and
  /// finds those read from their sides) and, for the elements other than those, written in
  /// place in a second, so that no list per element is held between them; the first pass also
  /// finds the largest values of the records and of the corners' vertices.
  void findCorners(std::span<const char> boxes);
  /// One value per face record, value(use) for each record of the face use `use`.
  template <class Value>
  vtk_format::GeneratedInts perRecord(std::int64_t largest, Value value) const;

  const PolyMesh& mesh_;
  FaceRecords records_;
  ElementCorners corners_;
  PointGroups points_;
  std::vector<ElementId> order_;
  RunningEnds connectivityEnd_, recordEnd_, faceEnd_;
  Largest largest_;
};

}  // namespace polydg
