#include "polydg/mesh/geometry_checks.h"

#include <algorithm>
#include <atomic>
#include <unordered_map>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <boost/container/small_vector.hpp>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "mesh/axis_rectangles.h"
#include "mesh/per_element.h"
#include "polydg/mesh/geometry.h"
#include "util/union_find.h"

namespace polydg {

bool isDegenerateFace(const PolyMesh& mesh, FaceId f, const Vec3& area) {
  const Face& face = mesh.face(f);
  for (std::size_t k = 0; k < face.numLoops(); ++k)
    if (face.loop(k).size() < 3) return true;
  boost::container::small_vector<VertexId, 8> sorted(face.vertices.begin(), face.vertices.end());
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return true;
  return area.squaredNorm() == 0.0;
}

bool isDegenerateFace(const PolyMesh& mesh, FaceId f) {
  return isDegenerateFace(mesh, f, areaVector(mesh, f));
}

namespace {

class Problems {
 public:
  Problems(GeometryCheck& report, std::size_t maxMessages)
      : report_(report), maxMessages_(maxMessages) {}

  void add(std::size_t& counter, const std::string& message) {
    ++counter;
    if (report_.messages.size() < maxMessages_) report_.messages.push_back(message);
  }

 private:
  GeometryCheck& report_;
  std::size_t maxMessages_;
};

std::string describe(const char* what, std::size_t index) {
  return std::string(what) + " " + std::to_string(index);
}

/// True if every directed edge of the element's oriented faces is matched by its reverse:
/// each undirected edge's uses in the two directions balance, that is, the edges running from
/// the smaller vertex to the larger are, as a multiset, those running back (an edge from a
/// vertex to itself runs back, unmatched). Each loop's edges are taken from its last corner on,
/// so that no corner's successor needs a division.
bool isClosed(const PolyMesh& mesh, ElementId e) {
  boost::container::small_vector<std::uint64_t, 32> up, down;
  for (const FaceUse& use : mesh.element(e).faces) {
    const Face& face = mesh.face(use.face);
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      const auto loop = face.loop(k);
      if (loop.empty()) continue;
      std::uint32_t previous = loop.back().value;
      for (const VertexId v : loop) {
        std::uint32_t a = previous, b = v.value;
        previous = b;
        if (use.reversed) std::swap(a, b);
        (a < b ? up : down).push_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b));
      }
    }
  }
  if (up.size() != down.size()) return false;
  std::sort(up.begin(), up.end());
  std::sort(down.begin(), down.end());
  return up == down;
}

/// True for the two sides of a cut: boundary faces tagged Cut with the same loops, reversed.
/// They are one polygon, but deliberately not shared (the sides are not coupled).
bool areCutSides(const PolyMesh& mesh, FaceId a, FaceId b) {
  const Face& x = mesh.face(a);
  const Face& y = mesh.face(b);
  return x.origin == FaceOrigin::Cut && y.origin == FaceOrigin::Cut && x.isBoundary() &&
         y.isBoundary() &&
         isReverseOf(x, {y.vertices.data(), y.vertices.size()},
                     {y.loopEnd.data(), y.loopEnd.size()});
}

/// Relative planarity error of a face beyond the tolerance, or 0 when it is planar enough.
double planarityExcess(const PolyMesh& mesh, FaceId f, const GeometryCheckOptions& options) {
  const Box3 box = faceBounds(mesh, f);
  const double deviation = planarityDeviation(mesh, f);
  const double resolution =
      16.0 * std::numeric_limits<double>::epsilon() *
      std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff());
  const double diameter = box.diagonal().norm();
  return deviation > options.planarityTolerance * diameter + resolution ? deviation / diameter
                                                                        : 0.0;
}

}  // namespace

GeometryCheck checkGeometryOf(const PolyMesh& mesh, std::span<const ElementId> elements,
                              const GeometryCheckOptions& options) {
  GeometryCheck report;
  Problems problems(report, options.maxMessages);
  report.elements = elements.size();
  std::vector<FaceId> faces;
  for (ElementId e : elements) {
    const Element& element = mesh.element(e);
    if (element.faces.empty()) {
      problems.add(report.emptyElements, describe("element without faces:", e.index()));
      continue;
    }
    for (const FaceUse& use : element.faces) {
      faces.push_back(use.face);
      const Face& face = mesh.face(use.face);
      if ((use.reversed ? face.back : face.front) != e)
        problems.add(report.inconsistentFaces, "element " + std::to_string(e.index()) +
                                                   " uses face " + std::to_string(use.face.value) +
                                                   " but the face does not list it");
    }
    if (!isClosed(mesh, e))
      problems.add(report.openElements, describe("element", e.index()) +
                                            " is not closed (an edge of its faces is "
                                            "not matched by the reverse edge of another)");
    const double v = signedVolume(mesh, e);
    report.volume += v;
    if (!(v > 0.0)) {
      std::ostringstream msg;
      msg << "element " << e.index() << " has non-positive volume " << v;
      problems.add(report.nonPositiveElements, msg.str());
    }
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  report.faces = faces.size();
  std::vector<std::pair<std::uint64_t, FaceId>> keys;
  for (FaceId f : faces) {
    const Face& face = mesh.face(f);
    if (face.front.valid() && face.back.valid())
      ++report.interiorFaces;
    else
      ++report.boundaryFaces;
    if (!face.front.valid())
      problems.add(report.inconsistentFaces, describe("face used only from its back:", f.index()));
    for (ElementId side : {face.front, face.back}) {
      if (!side.valid()) continue;
      const auto& uses = mesh.element(side).faces;
      if (std::none_of(uses.begin(), uses.end(), [&](const FaceUse& u) { return u.face == f; }))
        problems.add(report.inconsistentFaces,
                     "face " + std::to_string(f.index()) + " lists element " +
                         std::to_string(side.index()) + " which does not use it");
    }
    if (isDegenerateFace(mesh, f)) {
      problems.add(report.degenerateFaces, describe("degenerate face", f.index()));
    } else if (const double excess = planarityExcess(mesh, f, options); excess > 0) {
      std::ostringstream msg;
      msg << "face " << f.index() << " is not planar (relative error " << excess << ")";
      problems.add(report.nonPlanarFaces, msg.str());
    }
    keys.emplace_back(vertexSetKey({face.vertices.data(), face.vertices.size()}), f);
  }
  std::sort(keys.begin(), keys.end());
  auto sortedIds = [&](FaceId f) {
    boost::container::small_vector<VertexId, 8> ids(mesh.face(f).vertices.begin(),
                                                    mesh.face(f).vertices.end());
    std::sort(ids.begin(), ids.end());
    return ids;
  };
  for (std::size_t a = 0; a < keys.size(); ++a)
    for (std::size_t b = a + 1; b < keys.size() && keys[b].first == keys[a].first; ++b)
      if (sortedIds(keys[a].second) == sortedIds(keys[b].second) &&
          !areCutSides(mesh, keys[a].second, keys[b].second))
        problems.add(report.duplicateFaces, "faces " + std::to_string(keys[a].second.index()) +
                                                " and " + std::to_string(keys[b].second.index()) +
                                                " are the same polygon but not shared");
  report.passed = report.openElements == 0 && report.nonPositiveElements == 0 &&
                  report.nonPlanarFaces == 0 && report.degenerateFaces == 0 &&
                  report.duplicateFaces == 0 && report.inconsistentFaces == 0 &&
                  report.emptyElements == 0;
  return report;
}

namespace {

/// The elements joined through their interior faces.
UnionFind elementSets(const PolyMesh& mesh) {
  UnionFind sets(mesh.numElements());
  for (const Face& face : mesh.faces())
    if (face.front.valid() && face.back.valid()) sets.unite(face.front.value, face.back.value);
  return sets;
}

}  // namespace

ElementData<std::uint32_t> connectedComponents(const PolyMesh& mesh, std::size_t& count) {
  UnionFind sets = elementSets(mesh);
  ElementData<std::uint32_t> component;
  count = sets.labels(component.raw());
  return component;
}

namespace {

/// A face whose shape checkGeometry() reports.
struct FaceProblem {
  std::uint32_t face = 0;
  /// Relative deviation, if beyond the tolerance, else 0 (single precision: for the message).
  float planarity = 0.0f;
  bool degenerate = false;
};

/// The faces with a shape problem (degenerate, or not planar enough), found in parallel and
/// listed in face order. There are seldom any, so nothing is kept for the other faces: not their
/// area vectors (the elements' volumes compute them again, which costs less than holding one
/// per face beside the mesh), nor their vertex-set hashes (the duplicate search makes them
/// where it compares faces).
std::vector<FaceProblem> measureFaces(const PolyMesh& mesh, const GeometryCheckOptions& options) {
  tbb::enumerable_thread_specific<std::vector<FaceProblem>> found;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const FaceId f(i);
                        if (isAxisAlignedRectangle(mesh, mesh.face(f))) continue;
                        const Vec3 area = areaVector(mesh, f);
                        FaceProblem problem{static_cast<std::uint32_t>(i)};
                        problem.degenerate = isDegenerateFace(mesh, f, area);
                        if (!problem.degenerate) {
                          const Box3 box = faceBounds(mesh, f);
                          const double deviation = planarityDeviation(mesh, f, area);
                          const double resolution = 16.0 * std::numeric_limits<double>::epsilon() *
                                                    std::max(box.min().cwiseAbs().maxCoeff(),
                                                             box.max().cwiseAbs().maxCoeff());
                          const double diameter = box.diagonal().norm();
                          if (deviation > options.planarityTolerance * diameter + resolution)
                            problem.planarity = static_cast<float>(deviation / diameter);
                        }
                        if (problem.degenerate || problem.planarity > 0)
                          found.local().push_back(problem);
                      }
                    });
  std::vector<FaceProblem> problems;
  for (const std::vector<FaceProblem>& list : found)
    problems.insert(problems.end(), list.begin(), list.end());
  std::sort(problems.begin(), problems.end(),
            [](const FaceProblem& x, const FaceProblem& y) { return x.face < y.face; });
  return problems;
}

/// Counts interior and boundary faces and reports, face by face in order, shape, planarity
/// and links to elements.
void reportFaces(const PolyMesh& mesh, const std::vector<FaceProblem>& shapes, Problems& problems,
                 GeometryCheck& report) {
  auto shape = shapes.begin();
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const Face& face = mesh.face(FaceId(i));
    if (face.front.valid() && face.back.valid())
      ++report.interiorFaces;
    else if (face.front.valid() || face.back.valid())
      ++report.boundaryFaces;
    if (shape != shapes.end() && shape->face == i) {
      if (shape->degenerate) {
        problems.add(report.degenerateFaces, describe("degenerate face", i));
      } else {
        std::ostringstream msg;
        msg << "face " << i << " is not planar (relative error " << shape->planarity << ")";
        problems.add(report.nonPlanarFaces, msg.str());
      }
      ++shape;
    }
    if (!face.front.valid() && !face.back.valid()) {
      problems.add(report.inconsistentFaces, describe("face not used by any element:", i));
    } else if (!face.front.valid()) {
      // A face used only from its back is legal in principle, but polydg always attaches the
      // first element to the front; treat it as a link error.
      problems.add(report.inconsistentFaces, describe("face used only from its back:", i));
    }
  }
}

/// Duplicates: faces with the same vertex set. Such faces share their smallest vertex, so the
/// faces are placed by it (a counting sort, in face order within each vertex) and compared only
/// with those of the same smallest vertex, by their vertex-set hash and then their sorted
/// vertices. The pairs found are returned in order of their faces. Besides the mesh this holds
/// one 32-bit id per face and one count per vertex: the smallest vertex is found again where the
/// faces are placed rather than kept per face.
std::vector<std::pair<std::uint32_t, std::uint32_t>> findDuplicateFaces(const PolyMesh& mesh) {
  const std::size_t nf = mesh.numFaces();
  // Faces without vertices all go to the place after the last vertex.
  const auto none = static_cast<std::uint32_t>(mesh.numVertices());
  auto smallest = [&](std::size_t f) {
    std::uint32_t m = none;
    for (const VertexId v : mesh.face(FaceId(f)).vertices) m = std::min(m, v.value);
    return m;
  };
  if (nf > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("checkGeometry: more than 2^32 - 1 faces");
  // end[m + 1] counts the faces of smallest vertex m, then (summed) is where m's faces end;
  // placing the faces from the last down moves it to where they begin, so that m's faces are
  // byVertex[end[m + 1] .. end[m + 2]), in increasing order.
  std::vector<std::uint32_t> end(std::size_t(none) + 3, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f)
                        std::atomic_ref<std::uint32_t>(end[smallest(f) + 1])
                            .fetch_add(1, std::memory_order_relaxed);
                    });
  std::inclusive_scan(end.begin(), end.end(), end.begin());
  std::vector<std::uint32_t> byVertex(nf);
  for (std::size_t f = nf; f-- > 0;)
    byVertex[--end[smallest(f) + 1]] = static_cast<std::uint32_t>(f);
  auto sortedIds = [&](std::size_t f) {
    boost::container::small_vector<VertexId, 8> ids(mesh.face(FaceId(f)).vertices.begin(),
                                                    mesh.face(FaceId(f)).vertices.end());
    std::sort(ids.begin(), ids.end());
    return ids;
  };
  tbb::enumerable_thread_specific<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, std::size_t(none) + 1, 4096),
      [&](const tbb::blocked_range<std::size_t>& r) {
        boost::container::small_vector<std::uint64_t, 16> keys;
        for (std::size_t v = r.begin(); v != r.end(); ++v) {
          const std::uint32_t first = end[v + 1], last = end[v + 2];
          if (last - first < 2) continue;
          keys.clear();
          for (std::uint32_t x = first; x < last; ++x) {
            const Face& face = mesh.face(FaceId(std::size_t(byVertex[x])));
            keys.push_back(vertexSetKey({face.vertices.data(), face.vertices.size()}));
          }
          for (std::uint32_t x = first; x < last; ++x)
            for (std::uint32_t y = x + 1; y < last; ++y) {
              const std::uint32_t a = byVertex[x], b = byVertex[y];
              if (keys[x - first] == keys[y - first] && sortedIds(a) == sortedIds(b) &&
                  !areCutSides(mesh, FaceId(std::size_t(a)), FaceId(std::size_t(b))))
                found.local().emplace_back(a, b);
            }
        }
      });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (const auto& list : found) pairs.insert(pairs.end(), list.begin(), list.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

/// Reports the duplicate pairs findDuplicateFaces() found, in its order.
void reportDuplicateFaces(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs,
                          Problems& problems, GeometryCheck& report) {
  for (const auto& [a, b] : pairs)
    problems.add(report.duplicateFaces,
                 "faces " + std::to_string(a) + " and " + std::to_string(b) +
                     " are the same polygon but not shared (a face used by more than two "
                     "elements, or twice with the same orientation)");
}

/// Elements: closure (but for `boxes`) and volume in parallel (they are the costly part), then
/// links back to faces and the report in order.
void reportElements(const PolyMesh& mesh, std::span<const double> given,
                    std::span<const char> boxes, Problems& problems, GeometryCheck& report) {
  // Per element, in parallel: closed, linked (each face it uses lists it on that side), and
  // its volume unless given.
  enum : char { kClosed = 1, kLinked = 2 };
  std::vector<char> state(mesh.numElements());
  std::vector<double> computed(given.empty() ? mesh.numElements() : 0);
  const std::span<const double> volumes = given.empty() ? computed : given;
  auto linked = [&](ElementId e) {
    const auto& uses = mesh.element(e).faces;
    return std::all_of(uses.begin(), uses.end(), [&](const FaceUse& use) {
      const Face& face = mesh.face(use.face);
      return (use.reversed ? face.back : face.front) == e;
    });
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numElements(), 512),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const ElementId e(i);
                        const bool closed = (!boxes.empty() && boxes[i]) || isClosed(mesh, e);
                        state[i] =
                            static_cast<char>((closed ? kClosed : 0) | (linked(e) ? kLinked : 0));
                        if (given.empty()) computed[i] = signedVolume(mesh, e);
                      }
                    });
  // The report in element order, reading the mesh again only where a link is wrong.
  bool first = true;
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const ElementId e(i);
    const Element& element = mesh.element(e);
    if (element.faces.empty()) {
      problems.add(report.emptyElements, describe("element without faces:", i));
      continue;
    }
    if (!(state[i] & kLinked))
      for (const FaceUse& use : element.faces) {
        const Face& face = mesh.face(use.face);
        if ((use.reversed ? face.back : face.front) != e)
          problems.add(report.inconsistentFaces, "element " + std::to_string(i) + " uses face " +
                                                     std::to_string(use.face.value) +
                                                     " but the face does not list it");
      }
    if (!(state[i] & kClosed))
      problems.add(report.openElements, describe("element", i) +
                                            " is not closed (an edge of its faces is not "
                                            "matched by the reverse edge of another)");
    const double v = volumes[i];
    report.volume += v;
    report.minElementVolume = first ? v : std::min(report.minElementVolume, v);
    report.maxElementVolume = first ? v : std::max(report.maxElementVolume, v);
    first = false;
    if (!(v > 0.0)) {
      std::ostringstream msg;
      msg << "element " << i << " has non-positive volume " << v
          << (v < 0 ? " (inverted: faces oriented inward)" : "");
      problems.add(report.nonPositiveElements, msg.str());
    }
  }
}

}  // namespace

GeometryCheck checkGeometry(const PolyMesh& mesh, const GeometryCheckOptions& options,
                            std::span<const double> volumes, std::span<const char> boxes) {
  requireNoneOrOnePerElement(volumes.size(), mesh, "checkGeometry", "volumes");
  requireNoneOrOnePerElement(boxes.size(), mesh, "checkGeometry", "box flags");
  GeometryCheck report;
  Problems problems(report, options.maxMessages);
  report.elements = mesh.numElements();
  report.faces = mesh.numFaces();
  // Faces: shape and planarity in parallel, then links, duplicates and the report in order.
  // The duplicates are found first: their search holds two arrays of one entry per face and per
  // vertex, freed before the writer beside reaches its own largest.
  const auto duplicates = findDuplicateFaces(mesh);
  reportFaces(mesh, measureFaces(mesh, options), problems, report);
  reportDuplicateFaces(duplicates, problems, report);
  reportElements(mesh, volumes, boxes, problems, report);
  report.closedByConstruction =
      static_cast<std::size_t>(std::count_if(boxes.begin(), boxes.end(), [](char b) { return b; }));

  // Only their number: no label per element (two arrays of one entry per element less, held
  // while the mesh is written beside).
  report.components = elementSets(mesh).count();
  report.passed = report.openElements == 0 && report.nonPositiveElements == 0 &&
                  report.nonPlanarFaces == 0 && report.degenerateFaces == 0 &&
                  report.duplicateFaces == 0 && report.inconsistentFaces == 0 &&
                  report.emptyElements == 0 && mesh.numElements() > 0;
  if (mesh.numElements() == 0 && report.messages.size() < options.maxMessages)
    report.messages.push_back("the mesh has no elements");
  return report;
}

}  // namespace polydg
