#include "polydg/mesh/poly_mesh.h"

#include <algorithm>
#include <functional>
#include <stdexcept>

#include <tbb/parallel_invoke.h>
#include <tbb/parallel_scan.h>

#include <boost/container/small_vector.hpp>

namespace polydg {

std::string_view toString(FaceOrigin origin) {
  switch (origin) {
    case FaceOrigin::Interior: return "interior";
    case FaceOrigin::Surface: return "surface";
    case FaceOrigin::Cut: return "cut";
    case FaceOrigin::Box: return "box";
    case FaceOrigin::Imported: return "imported";
  }
  return "unknown";
}

namespace {

/// Loops as concatenated vertices and loop ends, for the span-based functions.
struct FlatLoops {
  std::vector<VertexId> vertices;
  std::vector<std::uint32_t> loopEnd;
  explicit FlatLoops(const std::vector<Loop>& loops) {
    for (const Loop& loop : loops) {
      vertices.insert(vertices.end(), loop.begin(), loop.end());
      loopEnd.push_back(static_cast<std::uint32_t>(vertices.size()));
    }
  }
};

/// True if cycle `b` is cycle `a` traversed backwards (any rotation).
bool isReversedCycle(std::span<const VertexId> a, std::span<const VertexId> b) {
  const std::size_t n = a.size();
  if (b.size() != n || n == 0) return false;
  const auto start = std::find(b.begin(), b.end(), a[0]);
  if (start == b.end()) return false;
  const std::size_t s = static_cast<std::size_t>(start - b.begin());
  for (std::size_t i = 0; i < n; ++i)
    if (a[i] != b[(s + n - i) % n]) return false;
  return true;
}

}  // namespace

std::uint64_t vertexSetKey(std::span<const VertexId> vertices) {
  boost::container::small_vector<std::uint32_t, 8> ids;
  for (VertexId v : vertices) ids.push_back(v.value);
  std::sort(ids.begin(), ids.end());
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint32_t id : ids) {
    h ^= id;
    h *= 1099511628211ull;
  }
  return h;
}

bool isReverseOf(const Face& a, const std::vector<Loop>& loops) {
  const FlatLoops flat(loops);
  return isReverseOf(a, flat.vertices, flat.loopEnd);
}

bool isReverseOf(const Face& a, std::span<const VertexId> vertices,
                 std::span<const std::uint32_t> loopEnd) {
  if (a.numLoops() != loopEnd.size()) return false;
  std::vector<bool> used(loopEnd.size(), false);
  for (std::size_t k = 0; k < a.numLoops(); ++k) {
    bool found = false;
    for (std::size_t j = 0; j < loopEnd.size() && !found; ++j) {
      const std::size_t begin = j == 0 ? 0 : loopEnd[j - 1];
      if (!used[j] && isReversedCycle(a.loop(k), vertices.subspan(begin, loopEnd[j] - begin)))
        used[j] = found = true;
    }
    if (!found) return false;
  }
  return true;
}

VertexId PolyMesh::addVertex(const Vec3& p) {
  positions_.push_back(p);
  return VertexId(positions_.size() - 1);
}

void PolyMesh::setOrigin(FaceId f, FaceOrigin origin) {
  Face& face = faces_[f];
  if (!face.isBoundary()) throw std::logic_error("setOrigin: face is interior");
  face.origin = origin;
}

FaceId PolyMesh::addFace(std::vector<Loop> loops, FaceOrigin origin) {
  const FlatLoops flat(loops);
  return addFace(flat.vertices, flat.loopEnd, origin);
}

FaceId PolyMesh::addFace(std::span<const VertexId> vertices, std::span<const std::uint32_t> loopEnd,
                         FaceOrigin origin) {
  if (loopEnd.empty()) throw std::invalid_argument("addFace: a face needs at least one loop");
  std::uint32_t begin = 0;
  for (std::uint32_t end : loopEnd) {
    if (end < begin + 3 || end > vertices.size())
      throw std::invalid_argument("addFace: every loop of a face needs at least 3 vertices");
    begin = end;
  }
  if (begin != vertices.size()) throw std::invalid_argument("addFace: loop ends do not match");
  for (VertexId v : vertices)
    if (!v.valid() || v.index() >= positions_.size())
      throw std::out_of_range("addFace: vertex id out of range");
  Face face;
  face.vertices.assign(vertices.begin(), vertices.end());
  face.loopEnd.assign(loopEnd.begin(), loopEnd.end());
  face.origin = origin;
  faces_.push_back(std::move(face));
  return FaceId(faces_.size() - 1);
}

FaceUse PolyMesh::findOrCreateFace(std::span<const VertexId> vertices,
                                   std::span<const std::uint32_t> loopEnd, FaceOrigin origin) {
  if (openFacesStale_) {
    openFaces_.clear();
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      const Face& face = faces_[FaceId(i)];
      if (face.back.valid() || !face.front.valid()) continue;
      openFaces_.emplace(vertexSetKey({face.vertices.data(), face.vertices.size()}), FaceId(i));
    }
    openFacesStale_ = false;
  }
  const std::uint64_t key = vertexSetKey(vertices);
  auto [begin, end] = openFaces_.equal_range(key);
  for (auto it = begin; it != end; ++it) {
    const Face& candidate = faces_[it->second];
    if (!candidate.back.valid() && isReverseOf(candidate, vertices, loopEnd)) {
      const FaceId f = it->second;
      openFaces_.erase(it);
      return {f, true};
    }
  }
  const FaceId f = addFace(vertices, loopEnd, origin);
  openFaces_.emplace(key, f);
  return {f, false};
}

ElementId PolyMesh::addElement(const std::vector<std::vector<Loop>>& boundary,
                               FaceOrigin boundaryOrigin) {
  std::vector<FaceUse> uses;
  uses.reserve(boundary.size());
  for (const auto& loops : boundary) {
    const FlatLoops flat(loops);
    uses.push_back(findOrCreateFace(flat.vertices, flat.loopEnd, boundaryOrigin));
  }
  return addElementFromFaces(uses);
}

ElementId PolyMesh::addElement(const std::vector<std::vector<Loop>>& boundary,
                               const std::vector<FaceOrigin>& origins) {
  if (origins.size() != boundary.size())
    throw std::invalid_argument("addElement: one origin per face is needed");
  std::vector<FaceUse> uses;
  uses.reserve(boundary.size());
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    if (origins[i] == FaceOrigin::Interior) {
      const FlatLoops flat(boundary[i]);
      uses.push_back(findOrCreateFace(flat.vertices, flat.loopEnd, origins[i]));
    } else {
      uses.push_back({addFace(boundary[i], origins[i]), false});
    }
  }
  return addElementFromFaces(uses);
}

void PolyMesh::mergeElementGroups(const std::vector<std::uint32_t>& group, std::size_t groups) {
  if (group.size() != elements_.size())
    throw std::invalid_argument("mergeElementGroups: one group per element is needed");
  auto dropped = [&](ElementId e) { return e.valid() && group[e.index()] == kDroppedElement; };
  auto regrouped = [&](ElementId e) { return e.valid() ? ElementId(group[e.index()]) : e; };
  // The kept faces' new ids, by a scan on all cores; then the faces are compacted in place (a
  // kept face only moves towards the front, so in order, on one core) while the elements take
  // their members' face lists on the other: neither reads what the other writes.
  std::vector<FaceId> newId(faces_.size());
  auto inside = [&](const Face& face) {
    return (face.front.valid() && face.back.valid() &&
            group[face.front.index()] == group[face.back.index()]) ||
           dropped(face.front) || dropped(face.back);
  };
  const std::size_t kept = tbb::parallel_scan(
      tbb::blocked_range<std::size_t>(0, faces_.size(), 4096), std::size_t(0),
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t next, bool final) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          if (inside(faces_[FaceId(i)])) continue;
          if (final) newId[i] = FaceId(next);
          ++next;
        }
        return next;
      },
      std::plus<>());
  auto compactFaces = [&] {
    for (std::size_t i = 0; i < newId.size(); ++i) {
      if (!newId[i].valid()) continue;
      Face& face = faces_[FaceId(i)];
      face.front = regrouped(face.front);
      face.back = regrouped(face.back);
      if (newId[i].index() != i) faces_[newId[i]] = std::move(face);
    }
    faces_.raw().resize(kept);
  };
  // Groups numbered in order of their first element (as the merges here number them) take
  // their members' faces in place: group g's slot is never read again once g's members start
  // arriving. Any other numbering fills a new list.
  bool inPlace = true;
  for (std::size_t e = 0; e < group.size() && inPlace; ++e)
    inPlace = group[e] == kDroppedElement || group[e] <= e;
  ElementData<Element> fresh(inPlace ? 0 : groups);
  ElementData<Element>& merged = inPlace ? elements_ : fresh;
  auto regroupElements = [&] {
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const FaceList uses = std::move(elements_[ElementId(e)].faces);
      elements_[ElementId(e)].faces.clear();
      if (group[e] == kDroppedElement) continue;
      FaceList& into = merged[ElementId(group[e])].faces;
      for (const FaceUse& use : uses)
        if (newId[use.face.index()].valid())
          into.push_back({newId[use.face.index()], use.reversed});
    }
  };
  tbb::parallel_invoke(compactFaces, regroupElements);
  if (inPlace)
    elements_.raw().resize(groups);
  else
    elements_ = std::move(fresh);
  openFacesStale_ = true;
}

void PolyMesh::detachFace(ElementId e, FaceId f) {
  FaceList& uses = elements_[e].faces;
  const auto it =
      std::find_if(uses.begin(), uses.end(), [&](const FaceUse& use) { return use.face == f; });
  if (it == uses.end())
    throw std::invalid_argument("detachFace: the element does not use the face");
  Face& face = faces_[f];
  ((*it).reversed ? face.back : face.front) = ElementId();
  uses.erase(static_cast<std::size_t>(it - uses.begin()));
  openFacesStale_ = true;
}

void PolyMesh::attachFace(ElementId e, FaceUse use) {
  Face& face = faces_[use.face];
  ElementId& side = use.reversed ? face.back : face.front;
  if (side.valid()) throw std::invalid_argument("attachFace: face side already used by an element");
  side = e;
  if (face.front.valid() && face.back.valid()) face.origin = FaceOrigin::Interior;
  elements_[e].faces.push_back(use);
  openFacesStale_ = true;
}

void PolyMesh::reverseFace(FaceId f) {
  Face& face = faces_[f];
  for (std::size_t k = 0; k < face.numLoops(); ++k) {
    const std::size_t begin = k == 0 ? 0 : face.loopEnd[k - 1];
    std::reverse(face.vertices.begin() + begin + 1, face.vertices.begin() + face.loopEnd[k]);
  }
  std::swap(face.front, face.back);
  for (ElementId e : {face.front, face.back}) {
    if (!e.valid()) continue;
    FaceList& uses = elements_[e].faces;
    for (std::size_t i = 0; i < uses.size(); ++i)
      if (uses[i].face == f) uses.set(i, {f, !uses[i].reversed});
  }
  openFacesStale_ = true;
}

FaceId PolyMesh::removeFace(FaceId f) {
  if (faces_[f].front.valid() || faces_[f].back.valid())
    throw std::invalid_argument("removeFace: the face is still used by an element");
  const FaceId last(faces_.size() - 1);
  openFacesStale_ = true;
  if (f == last) {
    faces_.raw().pop_back();
    return FaceId();
  }
  faces_[f] = std::move(faces_[last]);
  faces_.raw().pop_back();
  for (ElementId e : {faces_[f].front, faces_[f].back}) {
    if (!e.valid()) continue;
    FaceList& uses = elements_[e].faces;
    for (std::size_t i = 0; i < uses.size(); ++i)
      if (uses[i].face == last) uses.set(i, {f, uses[i].reversed});
  }
  return last;
}

ElementId PolyMesh::removeElement(ElementId e) {
  if (!elements_[e].faces.empty())
    throw std::invalid_argument("removeElement: the element still has faces");
  const ElementId last(elements_.size() - 1);
  if (e == last) {
    elements_.raw().pop_back();
    return ElementId();
  }
  elements_[e] = std::move(elements_[last]);
  elements_.raw().pop_back();
  for (const FaceUse& use : elements_[e].faces) {
    Face& face = faces_[use.face];
    (use.reversed ? face.back : face.front) = e;
  }
  return last;
}

bool PolyMesh::splitEdge(FaceId f, VertexId a, VertexId b, VertexId p) {
  Face& face = faces_[f];
  for (std::size_t k = 0; k < face.numLoops(); ++k) {
    const std::size_t begin = k == 0 ? 0 : face.loopEnd[k - 1], end = face.loopEnd[k];
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t j = i + 1 == end ? begin : i + 1;
      const VertexId u = face.vertices[i], w = face.vertices[j];
      if (!((u == a && w == b) || (u == b && w == a))) continue;
      // Insert after position i (at the loop's end when the edge closes the loop).
      face.vertices.insert(face.vertices.begin() + static_cast<std::ptrdiff_t>(i + 1), p);
      for (std::size_t m = k; m < face.loopEnd.size(); ++m) ++face.loopEnd[m];
      openFacesStale_ = true;
      return true;
    }
  }
  return false;
}

ElementId PolyMesh::addElementFromFaces(std::span<const FaceUse> faces) {
  const ElementId e(elements_.size());
  // Check every face first, so a failure leaves the mesh unchanged.
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const FaceUse& use = faces[i];
    if (!use.face.valid() || use.face.index() >= faces_.size())
      throw std::out_of_range("addElementFromFaces: face id out of range");
    const Face& face = faces_[use.face];
    if ((use.reversed ? face.back : face.front).valid())
      throw std::invalid_argument("addElementFromFaces: face side already used by an element");
    for (std::size_t j = 0; j < i; ++j)
      if (faces[j].face == use.face && faces[j].reversed == use.reversed)
        throw std::invalid_argument("addElementFromFaces: the same face side listed twice");
  }
  for (const FaceUse& use : faces) {
    Face& face = faces_[use.face];
    (use.reversed ? face.back : face.front) = e;
    if (face.front.valid() && face.back.valid()) face.origin = FaceOrigin::Interior;
  }
  Element element;
  element.faces.assign(faces.begin(), faces.end());
  elements_.push_back(std::move(element));
  return e;
}

}  // namespace polydg
