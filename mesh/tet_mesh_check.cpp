// checkTetMesh (polydg/mesh/tet_mesh.h, mesh/tet_mesh_check.h): per-tet checks, shared faces,
// and T-junctions on the boundary, all decided with CGAL's exact predicates.
#include "mesh/tet_mesh_check.h"

#include <algorithm>
#include <optional>
#include <tuple>
#include <utility>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>

#include "polydg/util/error.h"

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = std::array<std::uint32_t, 3>;

Point point(const TetMesh& mesh, std::uint32_t v) {
  const Vec3& p = mesh.vertices[v];
  return {p.x(), p.y(), p.z()};
}

/// Tet t's face k, outward.
Triangle tetFace(const TetMesh& mesh, std::size_t t, int k) {
  const auto& c = mesh.tets[t];
  const auto& f = kTetFaces[static_cast<std::size_t>(k)];
  return {c[f[0]], c[f[1]], c[f[2]]};
}

[[noreturn]] void fail(const TetNaming& naming, const std::string& what) {
  throw InputError((naming.file.empty() ? "" : naming.file + ": ") + what);
}

std::string faceText(const TetNaming& naming, const Triangle& f) {
  return "(" + naming.vertex(f[0]) + ", " + naming.vertex(f[1]) + ", " + naming.vertex(f[2]) + ")";
}

// ============================================================================================
// Each tet on its own
// ============================================================================================

void checkEachTet(const TetMesh& mesh, const TetNaming& naming) {
  const std::size_t n = mesh.numVertices();
  for (std::size_t t = 0; t < mesh.numTets(); ++t) {
    const auto& c = mesh.tets[t];
    for (std::uint32_t v : c)
      if (v >= n)
        fail(naming, naming.tet(t) + " has corner index " + std::to_string(v) +
                         ", but the mesh has " + std::to_string(n) +
                         " vertices (indices from 0); fix its corners");
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = i + 1; j < 4; ++j)
        if (c[i] == c[j])
          fail(naming, naming.tet(t) + " has " + naming.vertex(c[i]) +
                           " as two of its corners; a tet needs four distinct corners: fix or "
                           "remove it");
    const CGAL::Orientation o = CGAL::orientation(point(mesh, c[0]), point(mesh, c[1]),
                                                  point(mesh, c[2]), point(mesh, c[3]));
    if (o == CGAL::COPLANAR)
      fail(naming, naming.tet(t) + " is flat: its corners " + naming.vertex(c[0]) + ", " +
                       naming.vertex(c[1]) + ", " + naming.vertex(c[2]) + ", " +
                       naming.vertex(c[3]) +
                       " lie in one plane (zero volume); remove it or remesh");
    if (o == CGAL::NEGATIVE)
      fail(naming,
           naming.tet(t) + " is inverted (negative volume); swap two of its corners to orient it");
    if (!(sixVolume(mesh, t) > 0.0))
      fail(naming, naming.tet(t) +
                       " is too thin for double precision: its volume computes as zero or "
                       "negative; remove it or remesh");
  }
}

// ============================================================================================
// Shared faces
// ============================================================================================

/// One tet's use of a triangle: the corners sorted, and whether the tet's outward order is an
/// odd permutation of them (two tets on opposite sides of a face have opposite parities).
struct FaceRecord {
  Triangle sorted;
  std::uint32_t tet;
  std::uint8_t face;
  bool odd;
};

FaceRecord faceRecord(const TetMesh& mesh, std::size_t t, int k) {
  FaceRecord r{tetFace(mesh, t, k), static_cast<std::uint32_t>(t), static_cast<std::uint8_t>(k),
               false};
  auto order = [&](std::size_t i, std::size_t j) {
    if (r.sorted[i] > r.sorted[j]) {
      std::swap(r.sorted[i], r.sorted[j]);
      r.odd = !r.odd;
    }
  };
  order(0, 1);
  order(1, 2);
  order(0, 1);
  return r;
}

/// A tet's face that no other tet shares.
struct BoundaryFace {
  std::uint32_t tet;
  std::uint8_t face;
};

/// Checks that each triangle is used by at most two tets, from opposite sides; returns the
/// faces used once.
std::vector<BoundaryFace> checkSharedFaces(const TetMesh& mesh, const TetNaming& naming) {
  std::vector<FaceRecord> records;
  records.reserve(4 * mesh.numTets());
  for (std::size_t t = 0; t < mesh.numTets(); ++t)
    for (int k = 0; k < 4; ++k) records.push_back(faceRecord(mesh, t, k));
  std::sort(records.begin(), records.end(), [](const FaceRecord& a, const FaceRecord& b) {
    return std::tie(a.sorted, a.tet, a.face) < std::tie(b.sorted, b.tet, b.face);
  });
  std::vector<BoundaryFace> boundary;
  // The bad group whose first tet comes first, so that the message names the first bad tet.
  std::optional<std::pair<std::size_t, std::size_t>> worst;
  for (std::size_t begin = 0, end = 0; begin < records.size(); begin = end) {
    while (end < records.size() && records[end].sorted == records[begin].sorted) ++end;
    const bool bad =
        end - begin > 2 || (end - begin == 2 && records[begin].odd == records[begin + 1].odd);
    if (end - begin == 1) boundary.push_back({records[begin].tet, records[begin].face});
    if (bad && (!worst || records[begin].tet < records[worst->first].tet)) worst = {begin, end};
  }
  if (worst) {
    const auto [begin, end] = *worst;
    const FaceRecord& first = records[begin];
    const std::string face = "face " + faceText(naming, tetFace(mesh, first.tet, first.face));
    if (end - begin == 2)
      fail(naming, naming.tet(first.tet) + " and " + naming.tet(records[begin + 1].tet) +
                       " lie on the same side of their common " + face +
                       ", so they overlap; remove one or remesh");
    std::string tets;
    for (std::size_t i = begin; i < end; ++i)
      tets += (i == begin ? "" : i + 1 == end ? " and " : ", ") + naming.tet(records[i].tet);
    fail(naming, "the " + face + " belongs to " + std::to_string(end - begin) + " tets (" + tets +
                     "), but a face can be shared by two tets only; remove the extra tets or "
                     "remesh");
  }
  return boundary;
}

// ============================================================================================
// T-junctions on the boundary
// ============================================================================================

/// Where a point in a triangle's plane lies: a hanging vertex is Inside or OnEdge.
enum class Where { Outside, Inside, OnEdge, AtCorner };

/// Where point p, in the plane of triangle (a, b, c), lies in it.
Where whereInTriangle(const Point& a, const Point& b, const Point& c, const Point& p) {
  const CGAL::Orientation sides[3] = {CGAL::coplanar_orientation(a, b, c, p),
                                      CGAL::coplanar_orientation(b, c, a, p),
                                      CGAL::coplanar_orientation(c, a, b, p)};
  // coplanar_orientation(a, b, c, p) is POSITIVE when p is on c's side of line ab, COLLINEAR
  // when on the line: inside has all three positive, an edge's inside one collinear.
  int onLines = 0;
  for (CGAL::Orientation s : sides) {
    if (s == CGAL::NEGATIVE) return Where::Outside;
    if (s == CGAL::COLLINEAR) ++onLines;
  }
  return onLines == 0 ? Where::Inside : onLines == 1 ? Where::OnEdge : Where::AtCorner;
}

/// True if some edge line of triangle `a` has all of `b` on its closed outer side.
bool edgeSeparates(const std::array<Point, 3>& a, const std::array<Point, 3>& b) {
  for (int i = 0; i < 3; ++i) {
    const Point& p = a[static_cast<std::size_t>(i)];
    const Point& q = a[static_cast<std::size_t>((i + 1) % 3)];
    const Point& r = a[static_cast<std::size_t>((i + 2) % 3)];
    if (std::all_of(b.begin(), b.end(), [&](const Point& s) {
          return CGAL::coplanar_orientation(p, q, r, s) != CGAL::POSITIVE;
        }))
      return true;
  }
  return false;
}

/// A T-junction: boundary face `face` of the mesh contains a vertex or overlaps another face.
struct Junction {
  BoundaryFace face;
  std::uint32_t vertex = 0;  ///< the vertex inside `face`, if `other` is not set
  bool onEdge = false;       ///< the vertex is inside an edge of `face`
  std::optional<BoundaryFace> other;

  auto key() const { return std::make_tuple(face.tet, face.face, other ? other->tet : 0u, vertex); }
};

/// The T-junction between boundary faces f and g that names the earliest tet, if any. Both
/// boxes are known to meet.
std::optional<Junction> junction(const TetMesh& mesh, const BoundaryFace& f,
                                 const BoundaryFace& g) {
  const Triangle fv = tetFace(mesh, f.tet, f.face), gv = tetFace(mesh, g.tet, g.face);
  const std::array<Point, 3> fp = {point(mesh, fv[0]), point(mesh, fv[1]), point(mesh, fv[2])};
  const std::array<Point, 3> gp = {point(mesh, gv[0]), point(mesh, gv[1]), point(mesh, gv[2])};
  std::optional<Junction> found;
  auto consider = [&](const Junction& j) {
    if (!found || j.key() < found->key()) found = j;
  };
  // A corner of one face inside the other face or one of its edges.
  auto cornersIn = [&](const BoundaryFace& outer, const std::array<Point, 3>& op,
                       const Triangle& ov, const Triangle& inner, const std::array<Point, 3>& ip) {
    for (int i = 0; i < 3; ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      if (std::find(ov.begin(), ov.end(), inner[k]) != ov.end() ||
          CGAL::orientation(op[0], op[1], op[2], ip[k]) != CGAL::COPLANAR)
        continue;
      const Where where = whereInTriangle(op[0], op[1], op[2], ip[k]);
      if (where == Where::Inside || where == Where::OnEdge)
        consider({outer, inner[k], where == Where::OnEdge, std::nullopt});
    }
  };
  cornersIn(f, fp, fv, gv, gp);
  cornersIn(g, gp, gv, fv, fp);
  if (found) return found;
  const bool coplanar = std::all_of(gp.begin(), gp.end(), [&](const Point& s) {
    return CGAL::orientation(fp[0], fp[1], fp[2], s) == CGAL::COPLANAR;
  });
  // Coplanar triangles whose interiors are apart have an edge line of one with the other on
  // its far side (the separating axis theorem); else they overlap.
  if (coplanar && !edgeSeparates(fp, gp) && !edgeSeparates(gp, fp)) {
    const bool fFirst = std::tie(f.tet, f.face) < std::tie(g.tet, g.face);
    return Junction{fFirst ? f : g, 0, false, fFirst ? g : f};
  }
  return std::nullopt;
}

void checkBoundaryJunctions(const TetMesh& mesh, const std::vector<BoundaryFace>& boundary,
                            const TetNaming& naming) {
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::uint32_t>;
  std::vector<Box> boxes;
  boxes.reserve(boundary.size());
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const Triangle v = tetFace(mesh, boundary[i].tet, boundary[i].face);
    const CGAL::Bbox_3 box =
        point(mesh, v[0]).bbox() + point(mesh, v[1]).bbox() + point(mesh, v[2]).bbox();
    boxes.emplace_back(box, static_cast<std::uint32_t>(i));
  }
  std::optional<Junction> first;
  // Closed boxes: faces that only touch are tested too (exact double bounds, no padding needed).
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& a, const Box& b) {
    if (const auto j = junction(mesh, boundary[a.info()], boundary[b.info()]))
      if (!first || j->key() < first->key()) first = j;
  });
  if (!first) return;
  const Triangle face = tetFace(mesh, first->face.tet, first->face.face);
  const std::string where =
      "the boundary face " + faceText(naming, face) + " of " + naming.tet(first->face.tet);
  if (first->other)
    fail(naming, where + " overlaps the boundary face " +
                     faceText(naming, tetFace(mesh, first->other->tet, first->other->face)) +
                     " of " + naming.tet(first->other->tet) +
                     " in one plane: neighbouring tets do not share whole faces (a T-junction, "
                     "e.g. a quadrilateral split by different diagonals); remesh conformingly");
  fail(naming, naming.vertex(first->vertex) + " lies inside " +
                   (first->onEdge ? "an edge of " : "") + where +
                   " without being one of its corners: a hanging vertex (T-junction); remesh so "
                   "that neighbouring tets share whole faces");
}

}  // namespace

std::string TetNaming::tet(std::size_t t) const {
  return tetWord + " " +
         std::to_string(t < tetNumbers.size() ? tetNumbers[t] : static_cast<std::int64_t>(t));
}

std::string TetNaming::vertex(std::size_t v) const {
  return vertexWord + " " +
         std::to_string(v < vertexNumbers.size() ? vertexNumbers[v] : static_cast<std::int64_t>(v));
}

void checkTetMesh(const TetMesh& mesh, const TetNaming& naming) {
  checkEachTet(mesh, naming);
  checkBoundaryJunctions(mesh, checkSharedFaces(mesh, naming), naming);
}

void checkTetMesh(const TetMesh& mesh) { checkTetMesh(mesh, TetNaming{}); }

void orientTets(TetMesh& mesh) {
  for (auto& c : mesh.tets)
    if (CGAL::orientation(point(mesh, c[0]), point(mesh, c[1]), point(mesh, c[2]),
                          point(mesh, c[3])) == CGAL::NEGATIVE)
      std::swap(c[2], c[3]);
}

}  // namespace polydg
