// tetrahedralize (polydg/mesh/tetrahedralize.h): each element the cone from an interior point
// over its faces' triangles, or, where no such point is found, TetGen's tets of those triangles.
// TetGen's header stays in this file.
#include "polydg/mesh/tetrahedralize.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <mutex>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <tbb/parallel_for.h>
#include <tetgen.h>

#include "mesh/face_triangulation.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = std::array<VertexId, 3>;
using Tet = std::array<std::uint32_t, 4>;

/// One element's tets. A corner below the mesh's vertex count is a mesh vertex; corner
/// numVertices + k is the element's new point k.
struct ElementTets {
  std::vector<Vec3> points;
  std::vector<Tet> tets;
  bool cone = false;
  std::string error;  ///< why the element could not be split ("" if it was)
};

Kernel::Point_3 point(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

/// checkTetMesh's test of one tet: positive by CGAL's exact predicate and in double precision.
bool positive(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return CGAL::orientation(point(a), point(b), point(c), point(d)) == CGAL::POSITIVE &&
         sixVolume(a, b, c, d) > 0.0;
}

/// "cut face of element 3": where a boundary face comes from and the element it bounds.
std::string faceName(const PolyMesh& mesh, FaceId f) {
  const Face& face = mesh.face(f);
  return std::string(toString(face.origin)) + " face of element " +
         std::to_string((face.front.valid() ? face.front : face.back).value);
}

/// The triangles of every face an element uses, each face once; throws InputError for the
/// first face (in id order) that triangulateFace() refuses, naming an element that uses it.
FaceData<std::vector<Triangle>> triangulateFaces(const PolyMesh& mesh) {
  const std::size_t nf = mesh.numFaces();
  FaceData<std::vector<Triangle>> triangles(nf);
  FaceData<std::string> errors(nf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const FaceId f(i);
                        if (!mesh.face(f).front.valid() && !mesh.face(f).back.valid()) continue;
                        try {
                          triangles[f] = triangulateFace(mesh, f);
                        } catch (const std::runtime_error& e) {
                          errors[f] = e.what();
                        }
                      }
                    });
  for (std::size_t i = 0; i < nf; ++i) {
    const FaceId f(i);
    if (errors[f].empty()) continue;
    const Face& face = mesh.face(f);
    const ElementId e = face.front.valid() ? face.front : face.back;
    throw InputError("element " + std::to_string(e.value) + ": " + errors[f] +
                     "; repair the mesh (polydg check reports such faces) before splitting it "
                     "into tets");
  }
  return triangles;
}

/// Throws InputError if two boundary faces are one polygon seen from both sides (the two sides
/// of a cut that kept both, touching surfaces of two bodies): tets on the same vertices would
/// join what the polyhedral mesh keeps apart.
void refuseTouchingBoundaryFaces(const PolyMesh& mesh) {
  std::unordered_multimap<std::uint64_t, FaceId> seen;
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const FaceId f(i);
    const Face& face = mesh.face(f);
    if (face.front.valid() == face.back.valid()) continue;  // interior, or used by no element
    const std::span<const VertexId> vertices(face.vertices.data(), face.vertices.size());
    const std::span<const std::uint32_t> loopEnd(face.loopEnd.data(), face.loopEnd.size());
    const std::uint64_t key = vertexSetKey(vertices);
    const auto [begin, end] = seen.equal_range(key);
    for (auto it = begin; it != end; ++it)
      if (isReverseOf(mesh.face(it->second), vertices, loopEnd))
        throw InputError(
            "faces " + std::to_string(it->second.value) + " and " + std::to_string(f.value) +
            " are one polygon, a boundary of elements on both of its sides (" +
            faceName(mesh, it->second) + ", " + faceName(mesh, f) +
            "), as where a cut kept both sides: tets would join them; remove one side of the "
            "cut, or solve with a DG method");
    seen.emplace(key, f);
  }
}

/// Element e's boundary: its faces' triangles, reversed where it uses the face reversed, so
/// that every triangle's normal (right-hand rule) points out of the element.
std::vector<Triangle> elementBoundary(const PolyMesh& mesh, ElementId e,
                                      const FaceData<std::vector<Triangle>>& faces) {
  std::vector<Triangle> boundary;
  for (const FaceUse& use : mesh.element(e).faces)
    for (const Triangle& t : faces[use.face])
      boundary.push_back(use.reversed ? Triangle{t[0], t[2], t[1]} : t);
  return boundary;
}

/// The boundary's distinct vertices, in increasing id order.
std::vector<VertexId> boundaryVertices(const std::vector<Triangle>& boundary) {
  std::vector<VertexId> vertices;
  for (const Triangle& t : boundary) vertices.insert(vertices.end(), t.begin(), t.end());
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  return vertices;
}

/// The points a cone may start from: the mean of the element's vertices, then the centroid of
/// the solid its boundary encloses (the volume-weighted mean of the cone tets' centroids from
/// the first point; the first point again if that volume is not positive).
std::array<Vec3, 2> apexCandidates(const PolyMesh& mesh, const std::vector<Triangle>& boundary) {
  Vec3 mean = Vec3::Zero();
  const std::vector<VertexId> vertices = boundaryVertices(boundary);
  for (VertexId v : vertices) mean += mesh.position(v);
  mean /= static_cast<double>(vertices.size());
  Vec3 moment = Vec3::Zero();
  double volume = 0.0;
  for (const Triangle& t : boundary) {
    const Vec3 &a = mesh.position(t[0]), &b = mesh.position(t[1]), &c = mesh.position(t[2]);
    const double v = sixVolume(mean, a, b, c);
    // The tet's centroid about `mean`: (a + b + c - 3 mean) / 4.
    moment += v * ((a - mean) + (b - mean) + (c - mean)) / 4.0;
    volume += v;
  }
  return {mean, volume > 0.0 ? Vec3(mean + moment / volume) : mean};
}

/// The cone from `apex` over the boundary, if every one of its tets is positive; false (and
/// `out` untouched) otherwise.
bool coneFrom(const PolyMesh& mesh, const std::vector<Triangle>& boundary, const Vec3& apex,
              ElementTets& out) {
  for (const Triangle& t : boundary)
    if (!positive(apex, mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2])))
      return false;
  const auto a = static_cast<std::uint32_t>(mesh.numVertices());
  out.points = {apex};
  out.tets.clear();
  for (const Triangle& t : boundary) out.tets.push_back({a, t[0].value, t[1].value, t[2].value});
  out.cone = true;
  return true;
}

// ============================================================================================
// TetGen
// ============================================================================================

/// TetGen keeps the state of its predicates in globals set per call (exactinit() scales its
/// filters to the input's bounding box): one call at a time.
std::mutex tetgenMutex;

/// What TetGen's exit codes (terminatetetgen) mean.
std::string tetgenFailure(int code) {
  switch (code) {
    case 1: return "it ran out of memory";
    case 3: return "it found the element's boundary self-intersecting";
    case 4: return "it found a feature of the boundary too small for it";
    case 5: return "it found two boundary faces too close to each other";
    case 10: return "it refused the element's boundary as input";
    default: return "it failed with code " + std::to_string(code);
  }
}

/// The element's boundary as TetGen's input: its vertices (`vertices`, in order) and one facet
/// per triangle.
void fillTetgenInput(const PolyMesh& mesh, const std::vector<Triangle>& boundary,
                     const std::vector<VertexId>& vertices, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(vertices.size());
  in.pointlist = new REAL[3 * vertices.size()];
  for (std::size_t i = 0; i < vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = mesh.position(vertices[i])[k];
  in.numberoffacets = static_cast<int>(boundary.size());
  in.facetlist = new tetgenio::facet[boundary.size()];
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    tetgenio::facet& facet = in.facetlist[i];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(facet.polygonlist);
    facet.polygonlist->numberofvertices = 3;
    facet.polygonlist->vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) {
      const auto at = std::lower_bound(vertices.begin(), vertices.end(), boundary[i][k]);
      facet.polygonlist->vertexlist[k] = static_cast<int>(at - vertices.begin());
    }
  }
}

/// A triangle turned so that its smallest corner comes first (orientation kept).
std::array<std::uint32_t, 3> canonical(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

/// The faces of `tets` that no other of them shares, each outward and canonical, sorted.
std::vector<std::array<std::uint32_t, 3>> outerFaces(const std::vector<Tet>& tets) {
  std::map<std::array<std::uint32_t, 3>, std::array<std::uint32_t, 3>> once;
  for (const Tet& t : tets)
    for (const auto& f : kTetFaces) {
      const std::array<std::uint32_t, 3> face =
          canonical(t[static_cast<std::size_t>(f[0])], t[static_cast<std::size_t>(f[1])],
                    t[static_cast<std::size_t>(f[2])]);
      std::array<std::uint32_t, 3> key = face;
      std::sort(key.begin(), key.end());
      if (!once.erase(key)) once.emplace(key, face);
    }
  std::vector<std::array<std::uint32_t, 3>> faces;
  for (const auto& [key, face] : once) faces.push_back(face);
  std::sort(faces.begin(), faces.end());
  return faces;
}

/// TetGen's tets of the element bounded by `boundary`, in `out`; or out.error saying why not.
void tetgenElement(const PolyMesh& mesh, const std::vector<Triangle>& boundary, ElementTets& out) {
  const std::vector<VertexId> vertices = boundaryVertices(boundary);
  tetgenio in, result;
  fillTetgenInput(mesh, boundary, vertices, in);
  // p: the input is a boundary (a PLC); z: indices from 0; Y: no Steiner point on the
  // boundary; Q: quiet; T1e-16: TetGen's tolerance (default 1e-8 of the element's size, below
  // which it merges two vertices) as small as it goes, since welding leaves the vertices of a
  // sliced mesh as little as a few ulps apart (0 makes TetGen 1.5 fail).
  char switches[] = "pzYQT1e-16";
  try {
    const std::lock_guard<std::mutex> lock(tetgenMutex);
    ::tetrahedralize(switches, &in, &result);
  } catch (int code) {
    out.error = "TetGen cannot split it into tets: " + tetgenFailure(code);
    return;
  }
  const std::size_t n = vertices.size();
  // TetGen's output starts with its input points, unless it merged some.
  if (result.numberofpoints < static_cast<int>(n) ||
      !std::equal(in.pointlist, in.pointlist + 3 * n, result.pointlist)) {
    out.error = "TetGen merged or moved some of its vertices";
    return;
  }
  // TetGen's point i: the element's vertex i, then new point i - n.
  const auto nv = static_cast<std::uint32_t>(mesh.numVertices());
  auto corner = [&](int i) {
    const auto k = static_cast<std::size_t>(i - result.firstnumber);
    return k < n ? vertices[k].value : nv + static_cast<std::uint32_t>(k - n);
  };
  for (std::size_t k = n; k < static_cast<std::size_t>(result.numberofpoints); ++k)
    out.points.emplace_back(result.pointlist[3 * k], result.pointlist[3 * k + 1],
                            result.pointlist[3 * k + 2]);
  auto position = [&](std::uint32_t v) -> const Vec3& {
    return v < nv ? mesh.position(VertexId(v)) : out.points[v - nv];
  };
  for (int t = 0; t < result.numberoftetrahedra; ++t) {
    const int* c = result.tetrahedronlist + 4 * t;
    // TetGen 1.5 writes its tets positively oriented, as TetMesh wants them.
    const Tet tet{corner(c[0]), corner(c[1]), corner(c[2]), corner(c[3])};
    if (!positive(position(tet[0]), position(tet[1]), position(tet[2]), position(tet[3]))) {
      out.error = "TetGen made a flat or inverted tet";
      return;
    }
    out.tets.push_back(tet);
  }
  std::vector<std::array<std::uint32_t, 3>> given;
  for (const Triangle& t : boundary) given.push_back(canonical(t[0].value, t[1].value, t[2].value));
  std::sort(given.begin(), given.end());
  if (outerFaces(out.tets) != given)
    out.error = "TetGen's tets do not keep its boundary triangles as they are";
}

/// Element e's tets: a cone if it is star-shaped from a candidate point, else TetGen's.
ElementTets splitElement(const PolyMesh& mesh, ElementId e,
                         const FaceData<std::vector<Triangle>>& faces) {
  const std::vector<Triangle> boundary = elementBoundary(mesh, e, faces);
  ElementTets out;
  for (const Vec3& apex : apexCandidates(mesh, boundary))
    if (coneFrom(mesh, boundary, apex, out)) return out;
  tetgenElement(mesh, boundary, out);
  return out;
}

}  // namespace

TetMesh tetrahedralize(const PolyMesh& mesh, TetrahedralizeReport* report) {
  const Stopwatch watch;
  refuseTouchingBoundaryFaces(mesh);
  const FaceData<std::vector<Triangle>> faces = triangulateFaces(mesh);
  const std::size_t ne = mesh.numElements();
  std::vector<ElementTets> parts(ne);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne, 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e)
                        parts[e] = splitElement(mesh, ElementId(e), faces);
                    });

  TetMesh out;
  out.vertices = mesh.positions().raw();
  TetrahedralizeReport counts;
  const auto nv = static_cast<std::uint32_t>(mesh.numVertices());
  for (std::size_t e = 0; e < ne; ++e) {
    ElementTets& part = parts[e];
    if (!part.error.empty())
      throw InputError("element " + std::to_string(e) + " is not star-shaped and " + part.error +
                       "; mesh the surface with another cell size, or solve it with a DG method");
    if (out.vertices.size() + part.points.size() >= std::numeric_limits<std::uint32_t>::max())
      throw InputError(
          "the tet mesh has more vertices than polydg's 32-bit indices hold; mesh "
          "with a larger cell size");
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    out.vertices.insert(out.vertices.end(), part.points.begin(), part.points.end());
    for (Tet& t : part.tets) {
      for (std::uint32_t& c : t)
        if (c >= nv) c = base + (c - nv);
      out.tets.push_back(t);
    }
    counts.steinerPoints += part.points.size();
    (part.cone ? counts.coneElements : counts.tetgenElements) += 1;
  }
  checkTetMesh(out);
  counts.tets = out.numTets();
  counts.seconds = watch.seconds();
  if (report) *report = counts;
  return out;
}

}  // namespace polydg
