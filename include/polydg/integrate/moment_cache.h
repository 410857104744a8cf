// A per-face cache of exact moments: each face is integrated once and its contribution used,
// with its sign, by both of its elements; invalidating a face recomputes that face only, and
// an element's moments are the sum of its faces' contributions.
#pragma once

#include <span>
#include <vector>

#include "polydg/integrate/moments.h"

namespace polydg {

/// Moments up to `degree` of every face and element of one mesh.
///   face f:    int_F (x - faceReferencePoint(f))^alpha dA     (area-positive)
///   element e: int_K (x - elementOrigin(e))^alpha dV,  elementOrigin = bounding-box centre
/// in the monomial order of integrate/monomials.h. The cache reads the mesh it was made with;
/// after the mesh changes, invalidate what changed (or call sync() after appending) and call
/// update(). Not thread-safe for concurrent mutation; update() itself runs in parallel.
class MomentCache {
 public:
  MomentCache(const PolyMesh& mesh, int degree);

  int degree() const { return degree_; }
  int stride() const { return stride_; }

  /// Recomputes every face marked dirty, then every element that uses a dirty face or was
  /// marked dirty itself. Returns the number of faces integrated by this call.
  std::size_t update();

  /// Marks a face (and the elements on both sides of it) for recomputation.
  void invalidateFace(FaceId f);
  /// Marks an element whose face list changed; its faces are not re-integrated.
  void invalidateElement(ElementId e);
  /// Marks every face and element, as after construction.
  void invalidateAll();
  /// Follows the mesh's size: picks up faces and elements appended since the last call (marks
  /// them dirty) and drops those removed from the end.
  void sync();
  /// The mesh the cache reads was moved to `mesh` (same vertices, faces and elements): the
  /// moments stay valid and the cache follows it from now on.
  void rebind(const PolyMesh& mesh) { mesh_ = &mesh; }

  // In-place edits (PolyMesh::removeFace / removeElement / reverseFace): call these right after
  // the mesh's operation, so the moments move with their face or element and only new or
  // changed ones are recomputed. Ids at or past the cached size (appended since the last sync)
  // carry no moments: moving one marks the destination dirty.

  /// Reserves room for this many faces and elements, so that growing the mesh in place does
  /// not copy every moment.
  void reserve(std::size_t faces, std::size_t elements);
  /// Face `from` was moved into slot `to`.
  void moveFace(FaceId from, FaceId to);
  /// Element `from` was moved into slot `to`.
  void moveElement(ElementId from, ElementId to);
  /// Face f was reversed with its first vertex kept: same moments, opposite normal.
  void reverseFace(FaceId f);

  /// Face f takes the moments `values` (this cache's stride) and unit `normal` computed for it
  /// elsewhere: by another cache, for a face with the same vertices and loops in another mesh
  /// (a copy of part of a mesh). The face is no longer dirty and nothing is integrated for it;
  /// its elements are marked, so update() sums their moments from their faces.
  void assignFace(FaceId f, std::span<const double> values, const Vec3& normal);

  std::span<const double> face(FaceId f) const {
    return {faceMoments_.data() + f.index() * stride_, static_cast<std::size_t>(stride_)};
  }
  std::span<const double> element(ElementId e) const {
    return {elementMoments_.data() + e.index() * stride_, static_cast<std::size_t>(stride_)};
  }
  const Vec3& faceNormal(FaceId f) const { return faceNormals_[f]; }
  const Vec3& elementOrigin(ElementId e) const { return elementOrigins_[e]; }
  double volume(ElementId e) const { return element(e)[0]; }
  double area(FaceId f) const { return face(f)[0]; }
  /// The element's centroid, from its first moments.
  Vec3 centroid(ElementId e) const;

  /// Faces integrated since construction (counts every recomputation).
  std::size_t facesIntegrated() const { return facesIntegrated_; }

 private:
  const PolyMesh* mesh_;
  int degree_;
  int stride_;
  std::vector<double> faceMoments_;
  std::vector<double> elementMoments_;
  FaceData<Vec3> faceNormals_;
  ElementData<Vec3> elementOrigins_;
  std::vector<FaceId> dirtyFaces_;
  std::vector<ElementId> dirtyElements_;
  std::vector<char> faceDirty_;
  std::vector<char> elementDirty_;
  std::size_t facesIntegrated_ = 0;
};

}  // namespace polydg
