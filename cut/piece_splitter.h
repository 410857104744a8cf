// The splitter adapter of a cut: the mesh's elements as PlaneSplitter pieces (local point ids),
// each crossed face split once for both its elements, the caps, and the pieces built back into
// the mesh through the edit. Private to cut/.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <boost/container/small_vector.hpp>

#include "edit.h"
#include "mesh/plane_split.h"
#include "polydg/cut/cut.h"
#include "util/union_find.h"

namespace polydg::cut_detail {

/// Vertex sides for one plane, computed once per vertex. A vertex constructed by an earlier
/// cut on this same plane is on it.
class VertexSides {
 public:
  VertexSides(const PolyMesh& mesh, const Blade& blade, const std::vector<PlaneTags>& tags,
              std::uint32_t planeId)
      : mesh_(mesh), plane_(blade), tags_(tags), planeId_(planeId) {}
  int operator()(VertexId v) {
    const auto [it, inserted] = sides_.try_emplace(v.value, 0);
    if (inserted) it->second = tagged(v) ? 0 : plane_.side(mesh_.position(v));
    return it->second;
  }
  /// True if an earlier cut by this plane made v (it is on the plane by construction).
  bool tagged(VertexId v) const {
    if (v.index() >= tags_.size()) return false;
    const PlaneTags& t = tags_[v.index()];
    return std::find(t.begin(), t.end(), planeId_) != t.end();
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
    plane_ = SplitPlane(blade, planeId);
  }

  /// The local points of `elements` (mesh vertex ids <-> local indices). A vertex an earlier cut
  /// by this plane made is on the plane for the PlaneSplitter as for VertexSides: one answer.
  void setElements(const std::vector<ElementId>& elements) {
    std::vector<Vec3> points;
    std::vector<std::uint32_t> onPlane;
    for (ElementId e : elements)
      for (const FaceUse& use : mesh_.element(e).faces)
        for (VertexId v : mesh_.face(use.face).vertices)
          if (local_.try_emplace(v.value, static_cast<std::uint32_t>(points.size())).second) {
            const Vec3& p = mesh_.position(v);
            byPosition_.try_emplace({p.x(), p.y(), p.z()},
                                    static_cast<std::uint32_t>(points.size()));
            points.push_back(p);
            meshOf_.push_back(v);
            onPlane.push_back(sides_.tagged(v) ? planeId_ : PlaneSplitter::kNoPlane);
          }
    splitter_ = std::make_unique<PlaneSplitter>(points, onPlane);
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

  /// Caps become interior faces that the pieces on their two sides share (refinement), not a
  /// boundary face of each (a cut). Call before splitElement().
  void coupleCaps() { coupled_ = true; }

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
        std::vector<FaceUse> faces;
        for (std::size_t i : component) {
          const FaceUse use = faceFor(parts[i], side);
          if (use.face.valid()) faces.push_back(use);
        }
        pieces.emplace_back(edit_.addElement({faces.data(), faces.size()}, e), side);
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
      // A constructed point that rounded onto one of the elements' vertices is that vertex, and
      // one that rounded onto another constructed point is that point (distinct exact points,
      // closer than the coordinates resolve).
      const auto same = byPosition_.find({p.x(), p.y(), p.z()});
      if (same != byPosition_.end()) return it->second = meshOf_[same->second];
      const auto [made, first] = newByPosition_.try_emplace({p.x(), p.y(), p.z()}, VertexId());
      if (!first) return it->second = made->second;
      it->second = made->second = mesh_.addVertex(p);
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
      case Part::Kind::Cap:
        return coupled_ ? sharedCap(*part.polygon, side)
                        : FaceUse{makeFace(*part.polygon, FaceOrigin::Cut), false};
    }
    return {};
  }

  /// The interior face of a coupled cap: made on the minus side (outward there), used reversed
  /// by the plus side, whose cap is the same polygon the other way round.
  FaceUse sharedCap(const PiecePolygon& polygon, int side) {
    boost::container::small_vector<VertexId, 8> vertices;
    boost::container::small_vector<std::uint32_t, 2> loopEnd;
    if (!meshLoops(polygon, vertices, loopEnd)) return {};
    std::vector<std::uint32_t> key;
    for (VertexId v : vertices) key.push_back(v.value);
    std::sort(key.begin(), key.end());
    if (side < 0) {
      const FaceId f = edit_.addFace({vertices.data(), vertices.size()},
                                     {loopEnd.data(), loopEnd.size()}, FaceOrigin::Interior);
      capFaces_[std::move(key)] = f;
      return {f, false};
    }
    const auto it = capFaces_.find(key);
    if (it == capFaces_.end())
      throw std::logic_error("refine: an element's section differs on the plane's two sides");
    return {it->second, true};
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
  std::unordered_map<std::array<double, 3>, VertexId, PositionHash> newByPosition_;
  std::map<std::uint32_t, FaceParts> faces_;
  bool coupled_ = false;
  std::map<std::vector<std::uint32_t>, FaceId> capFaces_;  ///< coupled caps by vertex set
};

}  // namespace polydg::cut_detail
