#include "mesh/flat_faces.h"

#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <tbb/parallel_for.h>
#include <boost/container/small_vector.hpp>

#include "mesh/axis_rectangles.h"
#include "polydg/mesh/geometry.h"
#include "util/union_find.h"

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

Kernel::Point_3 point(const PolyMesh& mesh, VertexId v) {
  const Vec3& p = mesh.position(v);
  return {p.x(), p.y(), p.z()};
}

/// Face f's distinct corners if they lie exactly on one line (two distinct positions at least)
/// and its area vector is zero; otherwise none.
std::vector<VertexId> flatCorners(const PolyMesh& mesh, FaceId f) {
  if (areaVector(mesh, f).squaredNorm() != 0.0) return {};
  const Face& face = mesh.face(f);
  std::vector<VertexId> corners(face.vertices.begin(), face.vertices.end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const auto other = std::find_if(corners.begin(), corners.end(), [&](VertexId v) {
    return mesh.position(v) != mesh.position(corners.front());
  });
  if (other == corners.end()) return {};
  const Kernel::Point_3 a = point(mesh, corners.front()), b = point(mesh, *other);
  for (VertexId v : corners)
    if (!CGAL::collinear(a, b, point(mesh, v))) return {};
  return corners;
}

/// True if face f's directed edges cancel in pairs (each edge as often one way as the other).
bool boundsNothing(const Face& face) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> net;
  for (std::size_t k = 0; k < face.numLoops(); ++k) {
    const auto loop = face.loop(k);
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const std::uint32_t a = loop[i].value, b = loop[(i + 1) % loop.size()].value;
      net[{std::min(a, b), std::max(a, b)}] += a < b ? 1 : -1;
    }
  }
  return std::all_of(net.begin(), net.end(), [](const auto& e) { return e.second == 0; });
}

/// The flat faces' lines: faces sharing two corners lie on one line. Each line's corners sorted
/// along it, and for each corner the lines through it with its rank there.
struct Lines {
  std::vector<std::vector<VertexId>> corners;
  std::map<std::uint32_t,
           boost::container::small_vector<std::pair<std::uint32_t, std::uint32_t>, 2>>
      at;  ///< vertex -> (line, rank)
};

Lines linesOf(const PolyMesh& mesh, const std::vector<std::vector<VertexId>>& flat) {
  UnionFind sets(flat.size());
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> byPair;
  for (std::uint32_t i = 0; i < flat.size(); ++i)
    for (std::size_t a = 0; a < flat[i].size(); ++a)
      for (std::size_t b = a + 1; b < flat[i].size(); ++b) {
        const auto [it, first] = byPair.try_emplace({flat[i][a].value, flat[i][b].value}, i);
        if (!first) sets.unite(i, it->second);
      }
  std::vector<std::uint32_t> label;
  Lines lines;
  lines.corners.resize(sets.labels(label));
  for (std::uint32_t i = 0; i < flat.size(); ++i)
    lines.corners[label[i]].insert(lines.corners[label[i]].end(), flat[i].begin(), flat[i].end());
  for (std::uint32_t l = 0; l < lines.corners.size(); ++l) {
    std::vector<VertexId>& c = lines.corners[l];
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    // Along the coordinate in which the corners spread most (distinct points on the line differ
    // in it).
    Box3 box;
    for (VertexId v : c) box.extend(mesh.position(v));
    Eigen::Index axis = 0;
    box.diagonal().maxCoeff(&axis);
    std::sort(c.begin(), c.end(), [&](VertexId x, VertexId y) {
      return mesh.position(x)[axis] < mesh.position(y)[axis];
    });
    for (std::uint32_t r = 0; r < c.size(); ++r) lines.at[c[r].value].push_back({l, r});
  }
  return lines;
}

/// The corners of a line strictly between u and w on it, in order from u to w; none if u and w
/// are not both on one line.
std::vector<VertexId> between(const Lines& lines, VertexId u, VertexId w) {
  const auto iu = lines.at.find(u.value), iw = lines.at.find(w.value);
  if (iu == lines.at.end() || iw == lines.at.end()) return {};
  for (const auto& [lu, ru] : iu->second)
    for (const auto& [lw, rw] : iw->second) {
      if (lu != lw) continue;
      std::vector<VertexId> out;
      const std::vector<VertexId>& c = lines.corners[lu];
      if (ru < rw)
        for (std::uint32_t r = ru + 1; r < rw; ++r) out.push_back(c[r]);
      else
        for (std::uint32_t r = ru; r-- > rw + 1;) out.push_back(c[r]);
      return out;
    }
  return {};
}

}  // namespace

std::size_t dissolveFlatFaces(PolyMesh& mesh) {
  // A byte per face, not a list: flat faces are rare, and a mesh has millions of faces.
  std::vector<char> zeroArea(mesh.numFaces());
  tbb::parallel_for(std::size_t(0), mesh.numFaces(), [&](std::size_t f) {
    const Face& face = mesh.face(FaceId(f));
    zeroArea[f] =
        !isAxisAlignedRectangle(mesh, face) && areaVector(mesh, FaceId(f)).squaredNorm() == 0.0;
  });
  std::vector<FaceId> flat;
  std::vector<std::vector<VertexId>> flatCornerSets;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    if (!zeroArea[f]) continue;
    std::vector<VertexId> corners = flatCorners(mesh, FaceId(f));
    if (corners.empty()) continue;
    flat.push_back(FaceId(f));
    flatCornerSets.push_back(std::move(corners));
  }
  if (flat.empty()) return 0;
  const Lines lines = linesOf(mesh, flatCornerSets);
  // Every edge between two corners of a line gets the corners between them, in every face.
  struct Split {
    FaceId face;
    VertexId u, w;
    std::vector<VertexId> points;  ///< from u to w
  };
  std::vector<Split> splits;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Face& face = mesh.face(FaceId(f));
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      const auto loop = face.loop(k);
      for (std::size_t i = 0; i < loop.size(); ++i) {
        const VertexId u = loop[i], w = loop[(i + 1) % loop.size()];
        if (!lines.at.contains(u.value) || !lines.at.contains(w.value)) continue;
        std::vector<VertexId> points = between(lines, u, w);
        if (!points.empty()) splits.push_back({FaceId(f), u, w, std::move(points)});
      }
    }
  }
  for (const Split& s : splits) {
    VertexId from = s.u;
    for (VertexId p : s.points) {
      mesh.splitEdge(s.face, from, s.w, p);
      from = p;
    }
  }
  // Flat faces now run along each piece of their line both ways: out of their elements.
  std::vector<FaceId> removed;
  for (FaceId f : flat) {
    if (!boundsNothing(mesh.face(f))) continue;
    for (ElementId e : {mesh.face(f).front, mesh.face(f).back})
      if (e.valid()) mesh.detachFace(e, f);
    removed.push_back(f);
  }
  std::sort(removed.begin(), removed.end(), [](FaceId a, FaceId b) { return a.value > b.value; });
  for (FaceId f : removed) mesh.removeFace(f);
  return removed.size();
}

}  // namespace polydg
