// One editing operation on a MeshEditor's state (the edit transaction): topology changes with
// ids kept stable, moments re-integrated for what changed, then compaction. With the
// operations built on it: decoupling a face, merging the slivers a cut made. Private to cut/.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <span>
#include <unordered_map>
#include <vector>

#include <boost/container/small_vector.hpp>

#include "cut/element_grid.h"
#include "cut/mesh_editor.h"
#include "mesh/plane_split.h"
#include "polydg/cut/cut.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg::cut_detail {

/// Plane ids of one vertex (usually none, one or two).
using PlaneTags = boost::container::small_vector<std::uint32_t, 2>;

/// A set of ids that follows swap-with-last renumbering; iteration order is insertion order
/// up to the swaps made by erase.
template <class Id>
class IdSet {
 public:
  bool contains(Id id) const { return where_.count(id.value) != 0; }
  void insert(Id id) {
    if (where_.emplace(id.value, ids_.size()).second) ids_.push_back(id);
  }
  void erase(Id id) {
    const auto it = where_.find(id.value);
    if (it == where_.end()) return;
    const std::size_t i = it->second;
    where_.erase(it);
    if (i + 1 != ids_.size()) {
      ids_[i] = ids_.back();
      where_[ids_[i].value] = i;
    }
    ids_.pop_back();
  }
  /// The id `from` is now `to` (`to` is not in the set).
  void move(Id from, Id to) {
    const auto it = where_.find(from.value);
    if (it == where_.end()) return;
    const std::size_t i = it->second;
    where_.erase(it);
    where_[to.value] = i;
    ids_[i] = to;
  }
  const std::vector<Id>& ids() const { return ids_; }
  std::vector<Id> sorted() const {
    std::vector<Id> out = ids_;
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::vector<Id> ids_;
  std::unordered_map<std::uint32_t, std::size_t> where_;
};

/// The loops of a face reversed with each loop's first vertex kept first (same reference
/// point, opposite normal).
void reversedLoops(const Face& face, std::vector<VertexId>& vertices,
                   std::vector<std::uint32_t>& loopEnd);
/// The polygon's loops reversed (opposite normal).
PiecePolygon reversedPolygon(const PiecePolygon& p);

/// One editing operation on an editor's state: topology changes with ids kept stable (dead
/// faces and elements are only marked), then compaction by swap-with-last, with the moments,
/// the grid and the operation's id sets following every move.
class Edit {
 public:
  Edit(PolyMesh& mesh, MomentCache& cache, ElementGrid& grid)
      : mesh_(mesh), cache_(cache), grid_(grid), oldElements_(mesh.numElements()) {}

  PolyMesh& mesh() { return mesh_; }
  MomentCache& cache() { return cache_; }

  /// Records a pre-existing element's volume before it changes or dies.
  void touch(ElementId e) {
    if (e.index() >= oldElements_) return;
    if (oldVolume_.emplace(e.value, cache_.volume(e)).second) changed_.insert(e);
  }
  /// A new element made of part of `parent` (lineage).
  ElementId addElement(std::span<const FaceUse> uses, ElementId parent) {
    const ElementId e = mesh_.addElementFromFaces(uses);
    created_.insert(e);
    sources_[e.value] = sourcesOf(parent);
    return e;
  }
  FaceId addFace(std::span<const VertexId> vertices, std::span<const std::uint32_t> loopEnd,
                 FaceOrigin origin) {
    const FaceId f = mesh_.addFace(vertices, loopEnd, origin);
    newFaces_.insert(f);
    pendingFaces_.push_back(f);
    return f;
  }
  /// Face f changed shape in place (same polygon, more vertices): re-integrate it.
  void refresh(FaceId f) {
    pendingFaces_.push_back(f);
    for (ElementId e : {mesh_.face(f).front, mesh_.face(f).back})
      if (e.valid()) {
        touch(e);
        if (!created_.contains(e)) changed_.insert(e);
      }
  }
  /// Detaches every face of e and marks e dead (its volume is recorded first).
  FaceList detachAll(ElementId e) {
    touch(e);
    FaceList uses = mesh_.element(e).faces;
    for (const FaceUse& use : uses) mesh_.detachFace(e, use.face);
    markDead(e);
    return uses;
  }
  void markDead(ElementId e) {
    created_.erase(e);
    changed_.erase(e);
    leftWhole_.erase(e);
    deadElements_.push_back(e);
  }
  void markDeadIfUnused(FaceId f) {
    const Face& face = mesh_.face(f);
    if (!face.front.valid() && !face.back.valid()) deadFaces_.push_back(f);
  }
  /// Removes element e; faces it shared become boundary faces of the other side, tagged Cut.
  /// Its moments must be up to date. Returns its volume.
  double removeAndExpose(ElementId e) {
    const double v = cache_.volume(e);
    for (const FaceUse& use : detachAll(e)) {
      const Face& face = mesh_.face(use.face);
      if (!face.front.valid() && !face.back.valid()) {
        deadFaces_.push_back(use.face);
        continue;
      }
      if (!face.front.valid()) {
        mesh_.reverseFace(use.face);
        cache_.reverseFace(use.face);
      }
      mesh_.setOrigin(use.face, FaceOrigin::Cut);
      const ElementId other = mesh_.face(use.face).front;
      touch(other);
    }
    return v;
  }
  /// Merges element s into t: faces between them disappear, s's other faces move to t.
  void merge(ElementId s, ElementId t) {
    touch(t);
    touch(s);
    const FaceList uses = mesh_.element(s).faces;
    for (const FaceUse& use : uses) {
      const Face& face = mesh_.face(use.face);
      const ElementId other = use.reversed ? face.front : face.back;
      mesh_.detachFace(s, use.face);
      if (other == t) {
        mesh_.detachFace(t, use.face);
        deadFaces_.push_back(use.face);
      } else {
        mesh_.attachFace(t, use);
      }
    }
    std::vector<ElementId> joined = sourcesOf(t);
    for (ElementId e : sourcesOf(s)) joined.push_back(e);
    sources_[t.value] = std::move(joined);
    markDead(s);
    if (!created_.contains(t)) changed_.insert(t);
    cache_.invalidateElement(t);
  }
  /// Integrates new faces and recomputes the elements that use them or changed.
  std::size_t updateMoments() {
    cache_.sync();
    for (FaceId f : pendingFaces_)
      if (mesh_.face(f).front.valid() || mesh_.face(f).back.valid()) cache_.invalidateFace(f);
    pendingFaces_.clear();
    for (ElementId e : created_.ids()) cache_.invalidateElement(e);
    for (ElementId e : changed_.ids()) cache_.invalidateElement(e);
    return cache_.update();
  }
  /// Erases dead faces and elements by swap-with-last; everything follows the moves.
  void compact() {
    std::sort(deadFaces_.begin(), deadFaces_.end());
    deadFaces_.erase(std::unique(deadFaces_.begin(), deadFaces_.end()), deadFaces_.end());
    for (auto it = deadFaces_.rbegin(); it != deadFaces_.rend(); ++it) {
      newFaces_.erase(*it);
      const FaceId moved = mesh_.removeFace(*it);
      if (!moved.valid()) continue;
      cache_.moveFace(moved, *it);
      newFaces_.move(moved, *it);
    }
    std::sort(deadElements_.begin(), deadElements_.end());
    deadElements_.erase(std::unique(deadElements_.begin(), deadElements_.end()),
                        deadElements_.end());
    for (auto it = deadElements_.rbegin(); it != deadElements_.rend(); ++it) {
      grid_.erase(*it);
      const ElementId moved = mesh_.removeElement(*it);
      if (!moved.valid()) {
        sources_.erase(it->value);
        continue;
      }
      sources_[it->value] = sourcesOf(moved);
      sources_.erase(moved.value);
      cache_.moveElement(moved, *it);
      grid_.move(moved, *it);
      created_.move(moved, *it);
      changed_.move(moved, *it);
      leftWhole_.move(moved, *it);
    }
    deadFaces_.clear();
    deadElements_.clear();
    cache_.sync();
    cache_.update();
  }
  /// Sum of the recorded pre-change volumes of pre-existing elements.
  double oldVolume() const {
    double v = 0.0;
    for (const auto& [id, volume] : oldVolume_) v += volume;
    return v;
  }

  /// The lineage of the elements (call after compact()).
  ElementLineage lineage() const {
    ElementLineage l;
    for (const auto& [id, sources] : sources_)
      if (sources.size() != 1 || sources[0].value != id) l.changed.emplace(id, sources);
    return l;
  }

  IdSet<ElementId>& created() { return created_; }
  IdSet<ElementId>& changed() { return changed_; }
  IdSet<ElementId>& leftWhole() { return leftWhole_; }
  std::size_t oldElements() const { return oldElements_; }

 private:
  PolyMesh& mesh_;
  MomentCache& cache_;
  ElementGrid& grid_;
  std::size_t oldElements_;
  std::map<std::uint32_t, double> oldVolume_;  ///< ordered: a deterministic sum
  IdSet<ElementId> created_, changed_, leftWhole_;
  IdSet<FaceId> newFaces_;
  std::vector<FaceId> pendingFaces_;  ///< created since the last updateMoments()
  /// Elements of the mesh before the operation that element id covers, where not just itself.
  std::unordered_map<std::uint32_t, std::vector<ElementId>> sources_;
  std::vector<ElementId> sourcesOf(ElementId e) const {
    const auto it = sources_.find(e.value);
    return it == sources_.end() ? std::vector<ElementId>{e} : it->second;
  }
  std::vector<FaceId> deadFaces_;
  std::vector<ElementId> deadElements_;
};

/// Decouples interior face f: its back element gets its own reversed copy; both are boundary
/// faces tagged Cut.
void decouple(Edit& edit, FaceId f);

/// Merges the slivers among `candidates` by the sliver rule and greedy merge slicing uses
/// (isSliver and mergeSliverGroups, polydg/mesh/merge_elements.h): `threshold` is the volume
/// threshold T (sliver fraction times the reference volume); a piece is a sliver if its volume V
/// is below T or its 6 V / A (A: its surface area) is below T^(1/3). Thinnest first, each into
/// the neighbour across its largest shared interior face area, until it is no sliver or has no
/// neighbour.
/// Counts are added to `report`.
void mergeSliverPieces(Edit& edit, std::vector<ElementId> candidates, double threshold,
                       OperationReport& report);

}  // namespace polydg::cut_detail
