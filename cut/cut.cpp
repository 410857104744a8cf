#include "polydg/cut/cut.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "polydg/cut/element_grid.h"
#include "polydg/mesh/plane_split.h"
#include "polydg/mesh/validate.h"
#include "polydg/physics/region_checks.h"
#include "polydg/util/stopwatch.h"
#include "polydg/util/union_find.h"

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/// The blade's polygon seen in 2D: the coordinate plane that drops the normal's largest
/// component, with orientations corrected so that the corners run counter-clockwise.
struct PolygonTest {
  int u = 0, w = 1, sign = 1;
  std::vector<Kernel::Point_2> corners;

  explicit PolygonTest(const Blade& blade) {
    const Vec3& n = blade.normal;
    int k = 0;
    if (std::abs(n.y()) > std::abs(n[k])) k = 1;
    if (std::abs(n.z()) > std::abs(n[k])) k = 2;
    u = (k + 1) % 3;
    w = (k + 2) % 3;
    sign = n[k] > 0 ? 1 : -1;
    for (const Vec3& c : blade.polygon) corners.emplace_back(c[u], c[w]);
  }
  /// Exact: true if p projects into the polygon or onto its boundary.
  bool inside(const Vec3& p) const {
    const Kernel::Point_2 q(p[u], p[w]);
    const std::size_t n = corners.size();
    for (std::size_t i = 0; i < n; ++i) {
      const int o = static_cast<int>(CGAL::orientation(corners[i], corners[(i + 1) % n], q));
      if (sign * o < 0) return false;
    }
    return true;
  }
};

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
                   std::vector<std::uint32_t>& loopEnd) {
  vertices.assign(face.vertices.begin(), face.vertices.end());
  loopEnd.assign(face.loopEnd.begin(), face.loopEnd.end());
  for (std::size_t k = 0; k < loopEnd.size(); ++k) {
    const std::size_t begin = k == 0 ? 0 : loopEnd[k - 1];
    std::reverse(vertices.begin() + begin + 1, vertices.begin() + loopEnd[k]);
  }
}

PiecePolygon reversedPolygon(const PiecePolygon& p) {
  PiecePolygon r = p;
  for (std::size_t k = 0; k < p.numLoops(); ++k)
    std::reverse(r.vertices.begin() + p.loopBegin(k), r.vertices.begin() + p.loopEnd[k]);
  return r;
}

}  // namespace

// --- Blade -------------------------------------------------------------------------------

Blade Blade::plane(const Vec3& normal, double offset) {
  Blade b;
  static_cast<Plane&>(b) = Plane::make(normal, offset);
  return b;
}

Blade Blade::fromPolygon(std::vector<Vec3> corners) {
  if (corners.size() < 3) throw std::invalid_argument("a polygon blade needs at least 3 corners");
  for (const Vec3& c : corners)
    if (!c.allFinite()) throw std::invalid_argument("a polygon blade's corners must be finite");
  // Newell normal about the first corner: counter-clockwise corners give an outward normal.
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    n += (corners[i] - corners[0]).cross(corners[i + 1] - corners[0]);
  double diameter = 0.0;
  for (const Vec3& c : corners) diameter = std::max(diameter, (c - corners[0]).norm());
  if (!(n.norm() > 1e-12 * diameter * diameter))
    throw std::invalid_argument("the polygon blade is degenerate (its corners are collinear)");
  double offset = 0.0;
  for (const Vec3& c : corners) offset += n.dot(c);
  offset /= static_cast<double>(corners.size());
  // Within 1e-9 of the polygon's size of one plane (a tolerance on input, not a decision).
  for (const Vec3& c : corners)
    if (std::abs(n.dot(c) - offset) > 1e-9 * n.norm() * diameter)
      throw std::invalid_argument("the polygon blade's corners are not coplanar");
  Blade b;
  static_cast<Plane&>(b) = Plane::make(n, offset);
  b.polygon = std::move(corners);
  const PolygonTest test(b);
  const std::size_t m = test.corners.size();
  for (std::size_t i = 0; i < m; ++i) {
    const auto o =
        CGAL::orientation(test.corners[i], test.corners[(i + 1) % m], test.corners[(i + 2) % m]);
    if (test.sign * static_cast<int>(o) <= 0)
      throw std::invalid_argument(
          "the polygon blade is not strictly convex (corners must turn the same way, none "
          "repeated or collinear)");
  }
  return b;
}

// --- MeshEditor state --------------------------------------------------------------------

/// Plane ids of one vertex (usually none, one or two).
using PlaneTags = boost::container::small_vector<std::uint32_t, 2>;

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
  /// later cut by the same plane sees it on the plane (its rounded position may not be).
  std::vector<PlaneTags> vertexPlane;
  std::vector<Plane> planes;  ///< the plane of every cut so far
  /// Faces integrated by caches this editor has replaced with ones of higher degree.
  std::size_t retiredIntegrations = 0;
};

std::size_t MeshEditor::raiseMomentDegree(int degree) {
  State& s = *state_;
  if (degree <= s.moments->degree()) return 0;
  s.retiredIntegrations += s.moments->facesIntegrated();
  s.moments = std::make_unique<MomentCache>(s.mesh, degree);
  s.moments->reserve(s.mesh.numFaces() + s.mesh.numFaces() / 4,
                     s.mesh.numElements() + s.mesh.numElements() / 4);
  return s.moments->update();
}

namespace {

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
  ElementId addElement(std::span<const FaceUse> uses) {
    const ElementId e = mesh_.addElementFromFaces(uses);
    created_.insert(e);
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
      if (!moved.valid()) continue;
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
  std::vector<FaceId> deadFaces_;
  std::vector<ElementId> deadElements_;
};

/// Vertex sides for one plane, computed once per vertex. A vertex constructed by an earlier
/// cut on this same plane is on it.
class VertexSides {
 public:
  VertexSides(const PolyMesh& mesh, const Blade& blade, const std::vector<PlaneTags>& tags,
              std::uint32_t planeId)
      : mesh_(mesh), plane_(blade), tags_(tags), planeId_(planeId) {}
  int operator()(VertexId v) {
    const auto [it, inserted] = sides_.try_emplace(v.value, 0);
    if (inserted) {
      const bool onThisPlane =
          v.index() < tags_.size() && std::find(tags_[v.index()].begin(), tags_[v.index()].end(),
                                                planeId_) != tags_[v.index()].end();
      it->second = onThisPlane ? 0 : plane_.side(mesh_.position(v));
    }
    return it->second;
  }
  /// Lowest and highest side over the face's vertices.
  std::pair<int, int> range(FaceId f) {
    int lo = 1, hi = -1;
    for (VertexId v : mesh_.face(f).vertices) {
      const int s = (*this)(v);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    return {lo, hi};
  }
  std::pair<int, int> range(ElementId e) {
    int lo = 1, hi = -1;
    for (const FaceUse& use : mesh_.element(e).faces) {
      const auto [a, b] = range(use.face);
      lo = std::min(lo, a);
      hi = std::max(hi, b);
    }
    return {lo, hi};
  }

 private:
  const PolyMesh& mesh_;
  const Plane& plane_;
  const std::vector<PlaneTags>& tags_;
  std::uint32_t planeId_;
  std::unordered_map<std::uint32_t, int> sides_;
};

/// The parts of a piece's boundary, by source: a whole existing face, a part of a split face,
/// or a cap in the plane.
struct Part {
  enum class Kind { Whole, Sub, Cap } kind = Kind::Whole;
  FaceUse use;            ///< Whole: the face and orientation; Sub: the split face and the
                          ///< piece's orientation of it
  std::size_t index = 0;  ///< Sub: index among the split face's parts on this side; Cap: cap
  const PiecePolygon* polygon = nullptr;  ///< Sub, Cap: loops in local point ids
};

/// Splits the crossed elements of one cut: local points, one PlaneSplitter, each crossed face
/// split once, each element's caps, and the pieces built into the mesh.
class Splitter {
 public:
  Splitter(Edit& edit, VertexSides& sides, const Blade& blade, std::vector<PlaneTags>& tags,
           std::uint32_t planeId)
      : edit_(edit),
        mesh_(edit.mesh()),
        sides_(sides),
        blade_(blade),
        tags_(tags),
        planeId_(planeId) {
    plane_ = SplitPlane(blade, 0);
  }

  /// The local points of `elements` (mesh vertex ids <-> local indices).
  void setElements(const std::vector<ElementId>& elements) {
    std::vector<Vec3> points;
    for (ElementId e : elements)
      for (const FaceUse& use : mesh_.element(e).faces)
        for (VertexId v : mesh_.face(use.face).vertices)
          if (local_.try_emplace(v.value, static_cast<std::uint32_t>(points.size())).second) {
            const Vec3& p = mesh_.position(v);
            byPosition_.try_emplace({p.x(), p.y(), p.z()},
                                    static_cast<std::uint32_t>(points.size()));
            points.push_back(p);
            meshOf_.push_back(v);
          }
    splitter_ = std::make_unique<PlaneSplitter>(points);
  }

  /// The polygon in mesh vertex ids, with repeated consecutive vertices (a constructed point
  /// that rounded onto a vertex) merged and collapsed holes dropped; false if its outer loop
  /// collapsed (the polygon has no area left).
  bool meshLoops(const PiecePolygon& polygon, boost::container::small_vector<VertexId, 8>& out,
                 boost::container::small_vector<std::uint32_t, 2>& loopEnd) {
    out.clear();
    loopEnd.clear();
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = out.size();
      for (std::size_t i = polygon.loopBegin(k); i < polygon.loopEnd[k]; ++i) {
        const VertexId v = meshVertex(polygon.vertices[i]);
        if (out.size() == begin || out.back() != v) out.push_back(v);
      }
      while (out.size() > begin + 1 && out[begin] == out.back()) out.pop_back();
      if (out.size() >= begin + 3) {
        loopEnd.push_back(static_cast<std::uint32_t>(out.size()));
      } else {
        out.resize(begin);
        if (k == 0) return false;
      }
    }
    return true;
  }
  bool collapses(const PiecePolygon& polygon) {
    boost::container::small_vector<VertexId, 8> vertices;
    boost::container::small_vector<std::uint32_t, 2> loopEnd;
    return !meshLoops(polygon, vertices, loopEnd);
  }

  /// Element e's outward polygons in local ids.
  Piece piece(ElementId e) const {
    Piece piece;
    for (const FaceUse& use : mesh_.element(e).faces) {
      PiecePolygon p = polygonOf(use.face);
      piece.push_back(use.reversed ? reversedPolygon(p) : std::move(p));
    }
    return piece;
  }

  /// Splits e's piece; returns its caps on each side (minus, plus).
  std::pair<Piece, Piece> caps(ElementId e) {
    PieceSplit s = splitter_->split(piece(e), plane_, FaceOrigin::Cut);
    Piece minus, plus;
    for (PiecePolygon& p : s.minus)
      if (p.origin == FaceOrigin::Cut) minus.push_back(std::move(p));
    for (PiecePolygon& p : s.plus)
      if (p.origin == FaceOrigin::Cut) plus.push_back(std::move(p));
    return {std::move(minus), std::move(plus)};
  }

  const Vec3& point(std::uint32_t local) const { return splitter_->point(local); }

  /// Replaces e by its pieces; returns them with their sides. `caps` from caps(e).
  std::vector<std::pair<ElementId, int>> splitElement(ElementId e,
                                                      const std::pair<Piece, Piece>& caps) {
    const FaceList uses = mesh_.element(e).faces;
    struct SidePart {
      Part part;
    };
    std::vector<Part> minus, plus;
    for (const FaceUse& use : uses) {
      const auto [lo, hi] = sides_.range(use.face);
      if (lo < 0 && hi > 0) {
        const FaceParts& parts = split(use.face);
        for (std::size_t i = 0; i < parts.minus.size(); ++i)
          minus.push_back({Part::Kind::Sub, use, i, &parts.minus[i]});
        for (std::size_t i = 0; i < parts.plus.size(); ++i)
          plus.push_back({Part::Kind::Sub, use, i, &parts.plus[i]});
      } else if (hi > 0 || (lo == 0 && hi == 0 && outwardAlongNormal(use) < 0)) {
        plus.push_back({Part::Kind::Whole, use, 0, nullptr});
      } else {
        minus.push_back({Part::Kind::Whole, use, 0, nullptr});
      }
    }
    for (std::size_t i = 0; i < caps.first.size(); ++i)
      minus.push_back({Part::Kind::Cap, {}, i, &caps.first[i]});
    for (std::size_t i = 0; i < caps.second.size(); ++i)
      plus.push_back({Part::Kind::Cap, {}, i, &caps.second[i]});
    for (std::vector<Part>* parts : {&minus, &plus})  // parts that rounding collapsed
      parts->erase(std::remove_if(parts->begin(), parts->end(),
                                  [&](const Part& part) {
                                    return part.kind != Part::Kind::Whole &&
                                           collapses(*part.polygon);
                                  }),
                   parts->end());

    edit_.detachAll(e);
    std::vector<std::pair<ElementId, int>> pieces;
    for (int side : {-1, 1}) {
      const std::vector<Part>& parts = side < 0 ? minus : plus;
      for (const std::vector<std::size_t>& component : components(parts)) {
        if (component.size() < 2) continue;  // a lone polygon bounds no volume
        FaceList faces;
        for (std::size_t i : component) {
          const FaceUse use = faceFor(parts[i], side);
          if (use.face.valid()) faces.push_back(use);
        }
        pieces.emplace_back(edit_.addElement({faces.data(), faces.size()}), side);
      }
    }
    return pieces;
  }

  /// The points this cut made on edges of the split faces: (a, b) -> p, mesh vertex ids.
  /// In a part (the face's orientation), an edge from an original vertex x off the plane to a
  /// new point lies on x's outgoing edge of the face, one from a new point to such a y on y's
  /// incoming edge.
  std::map<std::pair<std::uint32_t, std::uint32_t>, VertexId> edgePoints() {
    std::map<std::pair<std::uint32_t, std::uint32_t>, VertexId> out;
    auto key = [](VertexId a, VertexId b) {
      return std::make_pair(std::min(a.value, b.value), std::max(a.value, b.value));
    };
    for (const auto& [id, parts] : faces_) {
      const Face& face = mesh_.face(FaceId(id));
      auto neighbour = [&](VertexId x, int step) {
        for (std::size_t k = 0; k < face.numLoops(); ++k) {
          const auto loop = face.loop(k);
          for (std::size_t i = 0; i < loop.size(); ++i)
            if (loop[i] == x) return loop[(i + loop.size() + step) % loop.size()];
        }
        return VertexId();
      };
      for (const Piece* side : {&parts.minus, &parts.plus})
        for (const PiecePolygon& p : *side)
          for (std::size_t k = 0; k < p.numLoops(); ++k) {
            const std::size_t begin = p.loopBegin(k), end = p.loopEnd[k];
            for (std::size_t i = begin; i < end; ++i) {
              const std::uint32_t u = p.vertices[i], w = p.vertices[i + 1 == end ? begin : i + 1];
              // An original vertex on the plane starts or ends segments along the cut line,
              // not pieces of its face's edges.
              const bool uOld = u < meshOf_.size(), wOld = w < meshOf_.size();
              if ((uOld && sides_(meshOf_[u]) == 0) || (wOld && sides_(meshOf_[w]) == 0)) continue;
              if (uOld && !wOld) {
                const VertexId x = meshOf_[u], y = neighbour(x, 1), q = meshVertex(w);
                if (y.valid() && q != x && q != y) out[key(x, y)] = q;
              } else if (!uOld && wOld) {
                const VertexId y = meshOf_[w], x = neighbour(y, -1), q = meshVertex(u);
                if (x.valid() && q != x && q != y) out[key(x, y)] = q;
              }
            }
          }
    }
    return out;
  }

  /// Faces split by this cut, for the neighbours that keep them whole.
  struct FaceParts {
    Piece minus, plus;                          ///< in the face's own orientation, local ids
    std::vector<FaceId> minusFaces, plusFaces;  ///< mesh faces made from them (lazily)
  };
  std::map<std::uint32_t, FaceParts>& splitFaces() { return faces_; }

  /// Makes the mesh face of part i of split face f on `side` (once).
  FaceId subFace(FaceId f, int side, std::size_t i) {
    FaceParts& parts = faces_.at(f.value);
    auto& ids = side < 0 ? parts.minusFaces : parts.plusFaces;
    const Piece& polygons = side < 0 ? parts.minus : parts.plus;
    if (ids.empty()) ids.resize(polygons.size());
    if (!ids[i].valid()) {
      const Face& face = mesh_.face(f);
      const FaceOrigin origin = face.isBoundary() ? face.origin : FaceOrigin::Interior;
      ids[i] = makeFace(polygons[i], origin);
    }
    return ids[i];
  }

 private:
  PiecePolygon polygonOf(FaceId f) const {
    const Face& face = mesh_.face(f);
    PiecePolygon p;
    for (VertexId v : face.vertices) p.vertices.push_back(local_.at(v.value));
    p.loopEnd.assign(face.loopEnd.begin(), face.loopEnd.end());
    p.origin = FaceOrigin::Surface;
    return p;
  }

  /// The dot product of the face's outward (for this use) area vector with the plane normal;
  /// used only for faces lying in the plane, whose normal is parallel to it.
  double outwardAlongNormal(const FaceUse& use) const {
    const Face& face = mesh_.face(use.face);
    const Vec3& c = mesh_.position(face.vertices[0]);
    Vec3 a = Vec3::Zero();
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      const auto loop = face.loop(k);
      for (std::size_t i = 0; i < loop.size(); ++i)
        a += (mesh_.position(loop[i]) - c).cross(mesh_.position(loop[(i + 1) % loop.size()]) - c);
    }
    const double d = a.dot(blade_.normal);
    return use.reversed ? -d : d;
  }

  /// Splits face f once, in its own orientation (with its reverse, so the two close a
  /// zero-volume piece that needs no cap).
  const FaceParts& split(FaceId f) {
    auto [it, inserted] = faces_.try_emplace(f.value);
    if (!inserted) return it->second;
    PiecePolygon p = polygonOf(f);
    PiecePolygon r = reversedPolygon(p);
    r.origin = FaceOrigin::Box;
    PieceSplit s = splitter_->split({p, r}, plane_, FaceOrigin::Cut);
    for (PiecePolygon& q : s.minus) {
      if (q.origin == FaceOrigin::Cut)
        throw std::logic_error("cut: a face's two orientations split differently");
      if (q.origin == FaceOrigin::Surface) it->second.minus.push_back(std::move(q));
    }
    for (PiecePolygon& q : s.plus) {
      if (q.origin == FaceOrigin::Cut)
        throw std::logic_error("cut: a face's two orientations split differently");
      if (q.origin == FaceOrigin::Surface) it->second.plus.push_back(std::move(q));
    }
    return it->second;
  }

  VertexId meshVertex(std::uint32_t local) {
    if (local < meshOf_.size()) return meshOf_[local];
    const auto [it, inserted] = newVertices_.try_emplace(local, VertexId());
    if (inserted) {
      const Vec3& p = splitter_->point(local);
      // A constructed point that rounded onto one of the elements' vertices is that vertex.
      const auto same = byPosition_.find({p.x(), p.y(), p.z()});
      if (same != byPosition_.end()) return it->second = meshOf_[same->second];
      it->second = mesh_.addVertex(p);
      tags_.resize(mesh_.numVertices());
      tags_[it->second.index()] = {planeId_};
    }
    return it->second;
  }

  /// The face of a polygon; invalid if rounding collapsed it.
  FaceId makeFace(const PiecePolygon& polygon, FaceOrigin origin) {
    boost::container::small_vector<VertexId, 8> vertices;
    boost::container::small_vector<std::uint32_t, 2> loopEnd;
    if (!meshLoops(polygon, vertices, loopEnd)) return FaceId();
    return edit_.addFace({vertices.data(), vertices.size()}, {loopEnd.data(), loopEnd.size()},
                         origin);
  }

  FaceUse faceFor(const Part& part, int side) {
    switch (part.kind) {
      case Part::Kind::Whole: return part.use;
      case Part::Kind::Sub: return {subFace(part.use.face, side, part.index), part.use.reversed};
      case Part::Kind::Cap: return {makeFace(*part.polygon, FaceOrigin::Cut), false};
    }
    return {};
  }

  /// Connected components of a side's parts, joined across shared edges (mesh vertex ids).
  std::vector<std::vector<std::size_t>> components(const std::vector<Part>& parts) {
    UnionFind sets(parts.size());
    std::unordered_map<std::uint64_t, std::size_t> firstUse;
    auto addEdge = [&](std::size_t p, VertexId a, VertexId b) {
      const std::uint64_t key =
          std::uint64_t(std::min(a.value, b.value)) << 32 | std::max(a.value, b.value);
      const auto [it, inserted] = firstUse.try_emplace(key, p);
      if (!inserted)
        sets.unite(static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(it->second));
    };
    for (std::size_t p = 0; p < parts.size(); ++p) {
      if (parts[p].kind == Part::Kind::Whole) {
        const Face& face = mesh_.face(parts[p].use.face);
        for (std::size_t k = 0; k < face.numLoops(); ++k) {
          const auto loop = face.loop(k);
          for (std::size_t i = 0; i < loop.size(); ++i)
            addEdge(p, loop[i], loop[(i + 1) % loop.size()]);
        }
      } else {
        boost::container::small_vector<VertexId, 8> vertices;
        boost::container::small_vector<std::uint32_t, 2> loopEnd;
        meshLoops(*parts[p].polygon, vertices, loopEnd);
        for (std::size_t k = 0; k < loopEnd.size(); ++k) {
          const std::size_t begin = k == 0 ? 0 : loopEnd[k - 1], end = loopEnd[k];
          for (std::size_t i = begin; i < end; ++i)
            addEdge(p, vertices[i], vertices[i + 1 == end ? begin : i + 1]);
        }
      }
    }
    std::vector<std::vector<std::size_t>> out;
    std::unordered_map<std::size_t, std::size_t> index;
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const auto [it, inserted] =
          index.try_emplace(sets.find(static_cast<std::uint32_t>(p)), out.size());
      if (inserted) out.emplace_back();
      out[it->second].push_back(p);
    }
    return out;
  }

  Edit& edit_;
  PolyMesh& mesh_;
  VertexSides& sides_;
  const Blade& blade_;
  std::vector<PlaneTags>& tags_;
  std::uint32_t planeId_;
  SplitPlane plane_;
  std::unordered_map<std::uint32_t, std::uint32_t> local_;
  std::vector<VertexId> meshOf_;
  std::unique_ptr<PlaneSplitter> splitter_;
  std::unordered_map<std::uint32_t, VertexId> newVertices_;
  struct PositionHash {
    std::size_t operator()(const std::array<double, 3>& p) const {
      std::size_t h = 0;
      for (double x : p) h = h * 0x9E3779B97F4A7C15ull + std::hash<double>{}(x);
      return h;
    }
  };
  std::unordered_map<std::array<double, 3>, std::uint32_t, PositionHash> byPosition_;
  std::map<std::uint32_t, FaceParts> faces_;
};

/// Decouples interior face f: its back element gets its own reversed copy; both are boundary
/// faces tagged Cut.
void decouple(Edit& edit, FaceId f) {
  PolyMesh& mesh = edit.mesh();
  const Face& face = mesh.face(f);
  const ElementId front = face.front, back = face.back;
  edit.touch(front);
  edit.touch(back);
  std::vector<VertexId> vertices;
  std::vector<std::uint32_t> loopEnd;
  reversedLoops(face, vertices, loopEnd);
  const FaceId copy = edit.addFace(vertices, loopEnd, FaceOrigin::Cut);
  mesh.detachFace(back, f);
  mesh.attachFace(back, {copy, false});
  mesh.setOrigin(f, FaceOrigin::Cut);
}

/// Merges the slivers among `candidates` (smallest first) into the neighbour across their
/// largest shared face area (interior faces), until each is above the threshold or has no
/// neighbour. Counts go to `report`.
void mergeSliverPieces(Edit& edit, std::vector<ElementId> candidates, double threshold,
                       OperationReport& report) {
  report.sliverThreshold = threshold;
  PolyMesh& mesh = edit.mesh();
  MomentCache& cache = edit.cache();
  std::unordered_set<std::uint32_t> dead;
  std::sort(candidates.begin(), candidates.end(), [&](ElementId a, ElementId b) {
    const double va = cache.volume(a), vb = cache.volume(b);
    return va != vb ? va < vb : a < b;
  });
  for (ElementId e : candidates) report.slivers += cache.volume(e) < threshold;
  for (ElementId g : candidates) {
    if (dead.count(g.value)) continue;
    bool merged = false;
    while (cache.volume(g) < threshold) {
      std::map<std::uint32_t, double> shared;
      for (const FaceUse& use : mesh.element(g).faces) {
        const Face& face = mesh.face(use.face);
        if (!face.front.valid() || !face.back.valid()) continue;
        const ElementId other = use.reversed ? face.front : face.back;
        shared[other.value] += cache.area(use.face);
      }
      if (shared.empty()) {
        if (!merged) ++report.isolatedSlivers;
        break;
      }
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const ElementId target(best->first);
      edit.merge(g, target);
      dead.insert(g.value);
      cache.update();  // the target's moments from its faces (no face is integrated)
      ++report.sliversMerged;
      merged = true;
      g = target;
    }
  }
}

}  // namespace

// --- MeshEditor --------------------------------------------------------------------------

MeshEditor::MeshEditor(PolyMesh mesh, double referenceVolume)
    : MeshEditor(std::move(mesh), referenceVolume, nullptr) {}

MeshEditor::MeshEditor(PolyMesh mesh, double referenceVolume, std::unique_ptr<MomentCache> moments)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.mesh = std::move(mesh);
  if (s.mesh.numElements() == 0) throw std::invalid_argument("MeshEditor: the mesh is empty");
  // Room to grow by a quarter in place before any array is copied (growth is amortized
  // after that, like any vector's).
  const auto headroom = [](std::size_t n) { return n + n / 4 + 64; };
  s.mesh.reserve(headroom(s.mesh.numVertices()), headroom(s.mesh.numFaces()),
                 headroom(s.mesh.numElements()));
  if (moments && moments->degree() >= 2) {
    s.moments = std::move(moments);
    s.moments->rebind(s.mesh);
  } else {
    s.moments = std::make_unique<MomentCache>(s.mesh, 2);
  }
  s.moments->reserve(headroom(s.mesh.numFaces()), headroom(s.mesh.numElements()));
  s.moments->update();
  std::vector<double> volumes(s.mesh.numElements());
  for (std::size_t e = 0; e < volumes.size(); ++e) {
    volumes[e] = s.moments->volume(ElementId(e));
    s.volume += volumes[e];
  }
  if (referenceVolume <= 0.0) {
    std::nth_element(volumes.begin(), volumes.begin() + volumes.size() / 2, volumes.end());
    referenceVolume = volumes[volumes.size() / 2];
  }
  if (!(referenceVolume > 0.0) || !std::isfinite(referenceVolume))
    throw std::invalid_argument("MeshEditor: the reference volume must be positive");
  s.referenceVolume = referenceVolume;
  s.grid = ElementGrid(s.mesh, std::cbrt(referenceVolume));
  s.region.assign(s.mesh.numElements(), 0);
  s.vertexPlane.assign(s.mesh.numVertices(), {});
}

MeshEditor::~MeshEditor() = default;
MeshEditor::MeshEditor(MeshEditor&&) noexcept = default;
MeshEditor& MeshEditor::operator=(MeshEditor&&) noexcept = default;

const PolyMesh& MeshEditor::mesh() const { return state_->mesh; }
const MomentCache& MeshEditor::moments() const { return *state_->moments; }

const MomentCache& MeshEditor::requireMoments(int degree) {
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  raiseMomentDegree(degree);
  return *state_->moments;
}

std::size_t MeshEditor::facesIntegrated() const {
  return state_->retiredIntegrations + state_->moments->facesIntegrated();
}
double MeshEditor::referenceVolume() const { return state_->referenceVolume; }
double MeshEditor::volume() const { return state_->volume; }

PolyMesh MeshEditor::release() {
  PolyMesh mesh = std::move(state_->mesh);
  state_.reset();
  return mesh;
}

namespace {

/// The checks after an operation on the elements it touched (see ValidationLevel).
void validateOperation(const PolyMesh& mesh, const MomentCache& moments,
                       const std::vector<ElementId>& touched, std::vector<char>& region,
                       ValidationLevel level, int degree, double sliverThreshold,
                       OperationValidation& v) {
  v.level = level;
  auto fail = [&](const std::string& message) {
    if (v.passed) v.failure = message;
    v.passed = false;
  };
  if (level == ValidationLevel::None) return;
  if (level == ValidationLevel::Local) {
    const ValidationReport geometry = validateElements(mesh, touched);
    v.elementsChecked = touched.size();
    if (!geometry.passed)
      fail("geometry: " + (geometry.messages.empty() ? std::string("invalid element")
                                                     : geometry.messages.front()));
    if (touched.empty() || !geometry.passed) return;
    region.resize(mesh.numElements(), 0);
    std::vector<ElementId> members;
    auto add = [&](ElementId e) {
      if (!region[e.index()]) {
        region[e.index()] = 1;
        members.push_back(e);
      }
    };
    // Isolated slivers (below the sliver threshold, no interior face) are left out of the DG
    // region: they are reported as isolated and are too thin for a meaningful solve.
    auto isolatedSliver = [&](ElementId e) {
      if (!(moments.volume(e) < sliverThreshold)) return false;
      const auto& uses = mesh.element(e).faces;
      return std::none_of(uses.begin(), uses.end(),
                          [&](const FaceUse& u) { return !mesh.face(u.face).isBoundary(); });
    };
    for (ElementId e : touched) {
      if (isolatedSliver(e)) continue;
      add(e);
      for (const FaceUse& use : mesh.element(e).faces) {
        const Face& face = mesh.face(use.face);
        if (face.front.valid()) add(face.front);
        if (face.back.valid()) add(face.back);
      }
    }
    if (members.empty()) return;
    LocalDgCheckOptions options;
    options.basis.degree = degree;
    // Elements the region holds only through faces too narrow to hold their rotations count as
    // bodies of their own: what holds them is the rest of the mesh, outside the region.
    const RegionDgCheck dg =
        regionDgChecks(mesh, moments, region, options, RegionCoupling::HoldingFaces);
    for (ElementId e : members) region[e.index()] = 0;
    v.regionElements = dg.elements;
    v.regionComponents = dg.components;
    v.zeroModes = dg.zeroModes;
    v.patchTestError = dg.patchTestError;
    if (!dg.passed()) {
      std::ostringstream msg;
      msg << "DG region check: patch test error " << dg.patchTestError << ", " << dg.zeroModes
          << " zero modes for " << dg.components << " components (expected " << 6 * dg.components
          << ")";
      fail(msg.str());
    }
    return;
  }
  const ValidationReport geometry = validate(mesh);
  v.elementsChecked = mesh.numElements();
  if (!geometry.passed)
    fail("geometry: " +
         (geometry.messages.empty() ? std::string("invalid mesh") : geometry.messages.front()));
  if (!geometry.passed) return;
  PhysicsCheckOptions options;
  options.basis.degree = degree;
  const PatchTestResult patch = patchTest(mesh, options);
  const ZeroModeReport modes = rigidModes(mesh, options);
  v.regionElements = mesh.numElements();
  v.patchTestError = patch.relativeError;
  v.regionComponents = modes.components;
  v.zeroModes = modes.zeroModes;
  if (!(patch.relativeError < kLocalPatchTestTolerance)) {
    std::ostringstream msg;
    msg << "DG patch test: relative error " << patch.relativeError;
    fail(msg.str());
  }
  if (modes.zeroModes != 6 * modes.components)
    fail("DG rigid modes: " + std::to_string(modes.zeroModes) + " zero modes for " +
         std::to_string(modes.components) + " components");
}

/// Relative volume balance above which an operation fails.
constexpr double kVolumeBalanceTolerance = 1e-10;

void checkOptions(const CutOptions& options) {
  if (options.removeSide < -1 || options.removeSide > 1)
    throw std::invalid_argument("removeSide must be -1, 0 or +1");
  if (!(options.sliverFraction >= 0.0) || !std::isfinite(options.sliverFraction))
    throw std::invalid_argument("the sliver fraction must be finite and not negative");
  if (options.validationDegree < 1 || options.validationDegree > 3)
    throw std::invalid_argument("the validation degree must be 1, 2 or 3");
}

}  // namespace

OperationReport MeshEditor::cut(const Blade& blade, const CutOptions& options) {
  checkOptions(options);
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  const Stopwatch start;
  try {
    return cutInPlace(blade, options);
  } catch (const std::exception& e) {
    // The splitter could not close a piece (constructions at round-off scale): the operation
    // fails like a failed check, and the part-edited mesh must not be used further.
    OperationReport report;
    report.op = blade.finite() ? "cut_polygon" : "cut";
    report.validation.level = options.validation;
    report.validation.passed = false;
    report.validation.failure = std::string("split: ") + e.what();
    report.seconds = start.seconds();
    return report;
  }
}

OperationReport MeshEditor::cutInPlace(const Blade& blade, const CutOptions& options) {
  const Stopwatch start;
  State& s = *state_;
  OperationReport report;
  report.op = blade.finite() ? "cut_polygon" : "cut";
  report.facesReintegrated += raiseMomentDegree(2 * options.validationDegree);
  const double volumeBefore = s.volume;
  Edit edit(s.mesh, *s.moments, s.grid);
  std::uint32_t planeId = 0;
  while (planeId < s.planes.size() && !s.planes[planeId].sameAs(blade)) ++planeId;
  if (planeId == s.planes.size()) s.planes.push_back(blade);
  s.vertexPlane.resize(s.mesh.numVertices());
  const std::size_t oldVertices = s.mesh.numVertices();
  VertexSides sides(s.mesh, blade, s.vertexPlane, planeId);
  const int removeSide = blade.finite() ? 0 : options.removeSide;
  std::optional<PolygonTest> polygon;
  if (blade.finite()) polygon.emplace(blade);

  // 1. Candidates from the grid, classified by their vertices' exact sides.
  std::vector<ElementId> candidates;
  {
    std::unordered_set<std::uint32_t> seen;
    s.grid.forEachNear(blade.normal, blade.offset, removeSide, [&](ElementId e) {
      if (seen.insert(e.value).second) candidates.push_back(e);
    });
    std::sort(candidates.begin(), candidates.end());
  }
  std::vector<ElementId> crossed, touching, wholeRemoved;
  for (ElementId e : candidates) {
    const auto [lo, hi] = sides.range(e);
    if (lo < 0 && hi > 0) crossed.push_back(e);
    if (lo <= 0 && hi >= 0) touching.push_back(e);
    if ((removeSide < 0 && hi <= 0) || (removeSide > 0 && lo >= 0)) wholeRemoved.push_back(e);
  }

  // 2. Faces lying in the plane (inside the polygon) decouple the elements on their sides.
  for (ElementId e : touching) {
    const FaceList uses = s.mesh.element(e).faces;
    for (const FaceUse& use : uses) {
      const Face& face = s.mesh.face(use.face);
      if (face.isBoundary()) continue;
      const auto [lo, hi] = sides.range(use.face);
      if (lo != 0 || hi != 0) continue;
      if (polygon && !std::all_of(face.vertices.begin(), face.vertices.end(),
                                  [&](VertexId v) { return polygon->inside(s.mesh.position(v)); }))
        continue;
      decouple(edit, use.face);
    }
  }

  // 3. Crossed elements: caps first (a finite blade splits only elements whose section lies
  //    in the polygon), then the pieces.
  Splitter splitter(edit, sides, blade, s.vertexPlane, planeId);
  splitter.setElements(crossed);
  std::vector<std::pair<ElementId, std::pair<Piece, Piece>>> toSplit;
  std::vector<ElementId> unsplit;  ///< crossed but kept whole
  for (ElementId e : crossed) {
    auto caps = splitter.caps(e);
    if (caps.first.empty() || caps.second.empty()) {
      // The section collapsed in rounding (the element is within round-off of the plane):
      // kept whole, like an element at a finite blade's edge.
      unsplit.push_back(e);
      continue;
    }
    if (polygon) {
      std::size_t in = 0, total = 0;
      for (const PiecePolygon& cap : caps.first)
        for (std::uint32_t v : cap.vertices) {
          ++total;
          in += polygon->inside(splitter.point(v));
        }
      if (in != total) {
        if (in > 0) edit.leftWhole().insert(e);
        unsplit.push_back(e);
        continue;
      }
    }
    toSplit.emplace_back(e, std::move(caps));
  }
  std::vector<std::pair<ElementId, int>> pieces;
  for (auto& [e, caps] : toSplit) {
    auto made = splitter.splitElement(e, caps);
    pieces.insert(pieces.end(), made.begin(), made.end());
  }
  report.elementsSplit = toSplit.size();
  report.piecesCreated = pieces.size();
  // Split faces still used by an element left whole: that element takes all the parts.
  for (auto& [id, parts] : splitter.splitFaces()) {
    const FaceId f(id);
    const ElementId front = s.mesh.face(f).front, back = s.mesh.face(f).back;
    for (const ElementId n : {front, back}) {
      if (!n.valid()) continue;
      const bool reversed = n == back;
      edit.touch(n);
      s.mesh.detachFace(n, f);
      for (int side : {-1, 1})
        for (std::size_t i = 0; i < (side < 0 ? parts.minus : parts.plus).size(); ++i)
          if (const FaceId part = splitter.subFace(f, side, i); part.valid())
            s.mesh.attachFace(n, {part, reversed});
    }
    edit.markDeadIfUnused(f);
  }
  // A new point on an edge whose ends both lie on an earlier plane lies on it too.
  std::map<std::pair<std::uint32_t, std::uint32_t>, VertexId> points;
  if (!toSplit.empty()) points = splitter.edgePoints();
  // (An end lies on a plane if it was made on it or lies on it exactly.)
  auto onPlane = [&](std::uint32_t v, std::uint32_t t) {
    const PlaneTags& tags = s.vertexPlane[v];
    if (std::find(tags.begin(), tags.end(), t) != tags.end()) return true;
    return s.planes[t].side(s.mesh.position(VertexId(v))) == 0;
  };
  for (const auto& [edge, p] : points) {
    if (p.index() < oldVertices) continue;
    PlaneTags candidates = s.vertexPlane[edge.first];
    candidates.insert(candidates.end(), s.vertexPlane[edge.second].begin(),
                      s.vertexPlane[edge.second].end());
    PlaneTags& tags = s.vertexPlane[p.index()];
    for (std::uint32_t t : candidates)
      if (std::find(tags.begin(), tags.end(), t) == tags.end() && onPlane(edge.first, t) &&
          onPlane(edge.second, t))
        tags.push_back(t);
  }
  // Edges the cut divided also bound faces of crossed elements kept whole: insert the new
  // points there too, so every element stays closed (no T-junctions).
  if (!unsplit.empty() && !toSplit.empty()) {
    for (ElementId e : unsplit) {
      const FaceList uses = s.mesh.element(e).faces;
      for (const FaceUse& use : uses) {
        bool changed = false;
        const Face face = s.mesh.face(use.face);
        for (std::size_t k = 0; k < face.numLoops(); ++k) {
          const auto loop = face.loop(k);
          for (std::size_t i = 0; i < loop.size(); ++i) {
            const VertexId a = loop[i], b = loop[(i + 1) % loop.size()];
            const auto it = points.find({std::min(a.value, b.value), std::max(a.value, b.value)});
            if (it != points.end()) changed |= s.mesh.splitEdge(use.face, a, b, it->second);
          }
        }
        if (!changed) continue;
        edit.refresh(use.face);
      }
    }
  }
  report.facesReintegrated += edit.updateMoments();

  // 4. Removal of one side: whole elements (infinite blade) and pieces.
  if (options.removeSide != 0) {
    for (ElementId e : wholeRemoved) {
      report.volumeRemoved += edit.removeAndExpose(e);
      ++report.elementsRemoved;
    }
    for (const auto& [e, side] : pieces)
      if (side == options.removeSide) {
        report.volumeRemoved += edit.removeAndExpose(e);
        ++report.elementsRemoved;
      }
  }

  // 5. Slivers among the new pieces.
  if (options.sliverFraction > 0.0) {
    std::vector<ElementId> alive = edit.created().sorted();
    mergeSliverPieces(edit, std::move(alive), options.sliverFraction * s.referenceVolume, report);
  }

  // 6. Compaction, the grid, the volume.
  report.facesReintegrated += edit.updateMoments();
  const double oldVolume = edit.oldVolume();
  edit.compact();
  double newVolume = 0.0;
  std::vector<ElementId> touched = edit.created().sorted();
  for (ElementId e : edit.changed().sorted()) touched.push_back(e);
  std::sort(touched.begin(), touched.end());
  for (ElementId e : touched) {
    newVolume += s.moments->volume(e);
    s.grid.insert(e, elementBounds(s.mesh, e));
  }
  s.volume = volumeBefore - oldVolume + newVolume;
  report.leftWhole = edit.leftWhole().sorted();
  report.facesTotal = s.mesh.numFaces();

  // 7. Checks.
  OperationValidation& v = report.validation;
  validateOperation(s.mesh, *s.moments, touched, s.region, options.validation,
                    options.validationDegree, options.sliverFraction * s.referenceVolume, v);
  v.volumeRelError =
      std::abs(volumeBefore - report.volumeRemoved - s.volume) / std::abs(volumeBefore);
  if (!(v.volumeRelError <= kVolumeBalanceTolerance)) {
    std::ostringstream msg;
    msg << "volume balance: relative error " << v.volumeRelError;
    if (v.passed) v.failure = msg.str();
    v.passed = false;
  }
  report.seconds = start.seconds();
  return report;
}

OperationReport MeshEditor::mergeSlivers(double fraction, ValidationLevel validation,
                                         int validationDegree) {
  CutOptions options;
  options.sliverFraction = fraction;
  options.validationDegree = validationDegree;
  checkOptions(options);
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  const Stopwatch start;
  State& s = *state_;
  OperationReport report;
  report.op = "merge";
  report.facesReintegrated += raiseMomentDegree(2 * validationDegree);
  const double volumeBefore = s.volume;
  Edit edit(s.mesh, *s.moments, s.grid);
  std::vector<ElementId> all(s.mesh.numElements());
  for (std::size_t e = 0; e < all.size(); ++e) all[e] = ElementId(e);
  if (fraction > 0.0) mergeSliverPieces(edit, std::move(all), fraction * s.referenceVolume, report);
  report.facesReintegrated += edit.updateMoments();
  const double oldVolume = edit.oldVolume();
  edit.compact();
  double newVolume = 0.0;
  const std::vector<ElementId> touched = edit.changed().sorted();
  for (ElementId e : touched) {
    newVolume += s.moments->volume(e);
    s.grid.insert(e, elementBounds(s.mesh, e));
  }
  s.volume = volumeBefore - oldVolume + newVolume;
  report.facesTotal = s.mesh.numFaces();
  validateOperation(s.mesh, *s.moments, touched, s.region, validation, validationDegree,
                    fraction * s.referenceVolume, report.validation);
  report.validation.volumeRelError = std::abs(volumeBefore - s.volume) / std::abs(volumeBefore);
  if (!(report.validation.volumeRelError <= kVolumeBalanceTolerance)) {
    if (report.validation.passed)
      report.validation.failure =
          "volume balance: relative error " + std::to_string(report.validation.volumeRelError);
    report.validation.passed = false;
  }
  report.seconds = start.seconds();
  return report;
}

}  // namespace polydg
