#include "mesh/surface_repair.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>
#include <CGAL/box_intersection_d.h>

namespace polydg {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

std::vector<Point> toPoints(const TriangleSurface& s) {
  std::vector<Point> points;
  points.reserve(s.vertices.size());
  for (const Vec3& p : s.vertices) points.emplace_back(p.x(), p.y(), p.z());
  return points;
}

std::vector<std::vector<std::size_t>> toPolygons(const TriangleSurface& s) {
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(s.triangles.size());
  for (const auto& t : s.triangles)
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) polygons.push_back({t[0], t[1], t[2]});
  return polygons;
}

TriangleSurface fromMesh(const Mesh& mesh) {
  TriangleSurface s;
  std::vector<std::uint32_t> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices());
  for (Mesh::Vertex_index v : mesh.vertices()) {
    index[v] = static_cast<std::uint32_t>(s.vertices.size());
    const Point& p = mesh.point(v);
    s.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (Mesh::Face_index f : mesh.faces()) {
    std::array<std::uint32_t, 3> t{};
    int i = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (i == 3) throw std::logic_error("fromMesh: a face is not a triangle");
      t[i++] = index[v];
    }
    s.triangles.push_back(t);
  }
  return s;
}

/// The sign of the volume a surface closed by consistently oriented triangles encloses, from
/// the sum of the signed tetrahedra about its bounding box's centre in interval arithmetic
/// (CGAL's Interval_nt, every rounding directed outward): +1 or -1 when the interval excludes 0,
/// which makes the sign exact; 0 when the volume is within round-off of zero (then undecided).
int enclosedVolumeSign(const TriangleSurface& surface) {
  const CGAL::Protect_FPU_rounding<true> rounding;
  using Interval = CGAL::Interval_nt<false>;
  const Box3 box = bounds(surface);
  const Vec3 centre = 0.5 * (box.min() + box.max());
  std::vector<std::array<Interval, 3>> p(surface.vertices.size());
  for (std::size_t v = 0; v < p.size(); ++v)
    for (int i = 0; i < 3; ++i) p[v][i] = Interval(surface.vertices[v][i]) - Interval(centre[i]);
  Interval sixVolume(0.0);
  for (const auto& t : surface.triangles) {
    const auto &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
    sixVolume += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
                 a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (sixVolume.inf() > 0) return 1;
  if (sixVolume.sup() < 0) return -1;
  return 0;
}

/// Whether triangles h and g of a closed, manifold soup intersect other than in the edge or the
/// vertex they share: CGAL's test for two faces of a mesh (do_faces_intersect of
/// self_intersections()), case by case, on the soup's vertex indices.
bool intersectImproperly(const std::array<std::uint32_t, 3>& h,
                         const std::array<std::uint32_t, 3>& g, const std::vector<Point>& points) {
  auto at = [&](const std::array<std::uint32_t, 3>& t, std::uint32_t v) {
    return t[0] == v ? 0 : t[1] == v ? 1 : t[2] == v ? 2 : -1;
  };
  // A shared edge p q (a manifold edge: its two triangles): they overlap only if folded onto
  // each other, the third corners coplanar with it and on the same side of it.
  for (int i = 0; i < 3; ++i) {
    const int jp = at(g, h[i]), jq = at(g, h[(i + 1) % 3]);
    if (jp < 0 || jq < 0) continue;
    const Point &p = points[h[i]], &q = points[h[(i + 1) % 3]], &r = points[h[(i + 2) % 3]];
    const Point& s = points[g[3 - jp - jq]];
    return CGAL::coplanar(p, q, r, s) && CGAL::coplanar_orientation(p, q, r, s) == CGAL::POSITIVE;
  }
  const Kernel::Triangle_3 th(points[h[0]], points[h[1]], points[h[2]]);
  const Kernel::Triangle_3 tg(points[g[0]], points[g[1]], points[g[2]]);
  // A shared vertex: the edge of each opposite it must meet the other triangle.
  for (int i = 0; i < 3; ++i) {
    const int j = at(g, h[i]);
    if (j < 0) continue;
    const Kernel::Segment_3 sh(points[h[(i + 1) % 3]], points[h[(i + 2) % 3]]);
    const Kernel::Segment_3 sg(points[g[(j + 1) % 3]], points[g[(j + 2) % 3]]);
    return CGAL::do_intersect(th, sg) || CGAL::do_intersect(tg, sh);
  }
  return CGAL::do_intersect(th, tg);
}

}  // namespace

// CGAL's self_intersections() of the mesh a closed, manifold soup without singular vertices
// makes as it is, counted on the soup: a collinear triangle counts once, the others' boxes meet
// in CGAL's box_self_intersection_d (cutoff as CGAL's) and each pair of boxes is tested as CGAL
// tests two faces. Building the Surface_mesh was a fifth of the test on a 75k-triangle scan.
// (CGAL 5.6 has triangle_soup_self_intersections; Debian 12's is 5.5.)
std::optional<std::size_t> selfIntersectionsOfClosedSurface(const TriangleSurface& surface,
                                                            const std::atomic<bool>* stop) {
  using Box =
      CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::uint32_t,
                                                CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;
  const std::vector<Point> points = toPoints(surface);
  std::size_t count = 0;
  std::vector<Box> boxes;
  boxes.reserve(surface.triangles.size());
  for (std::uint32_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    const Point &p = points[tri[0]], &q = points[tri[1]], &r = points[tri[2]];
    if (CGAL::collinear(p, q, r))
      ++count;
    else
      boxes.emplace_back(p.bbox() + q.bbox() + r.bbox(), t);
  }
  std::vector<const Box*> pointers;
  pointers.reserve(boxes.size());
  for (const Box& b : boxes) pointers.push_back(&b);
  struct Stopped {};
  const auto pair = [&](const Box* a, const Box* b) {
    if (stop && stop->load(std::memory_order_relaxed)) throw Stopped{};
    count +=
        intersectImproperly(surface.triangles[a->info()], surface.triangles[b->info()], points);
  };
  try {
    CGAL::box_self_intersection_d<CGAL::Sequential_tag>(pointers.begin(), pointers.end(), pair,
                                                        std::ptrdiff_t(2000));
  } catch (const Stopped&) {
    return std::nullopt;
  }
  return count;
}

bool isClosedManifoldSoup(const SurfaceTopology& topology) {
  return topology.closed() && topology.singularVertices == 0 && topology.degenerateTriangles == 0;
}

SurfaceDiagnosis diagnose(const TriangleSurface& surface, const SurfaceTopology* topology,
                          std::optional<std::size_t> closedSurfaceCount) {
  SurfaceDiagnosis d;
  d.topology = topology ? *topology : analyzeTopology(surface);
  if (surface.triangles.empty()) return d;
  if (d.topology.nonManifoldEdges > 0) return d;
  if (isClosedManifoldSoup(d.topology)) {
    d.selfIntersections =
        closedSurfaceCount ? *closedSurfaceCount : *selfIntersectionsOfClosedSurface(surface);
  } else {
    // A consistently oriented mesh of it (orientation does not change intersections).
    auto points = toPoints(surface);
    auto polygons = toPolygons(surface);
    if (!d.topology.closed() || d.topology.singularVertices > 0)
      PMP::orient_polygon_soup(points, polygons);
    Mesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
    PMP::self_intersections<CGAL::Parallel_if_available_tag>(faces(mesh), mesh,
                                                             std::back_inserter(pairs));
    d.selfIntersections = pairs.size();
  }
  d.checkedSelfIntersections = true;
  d.shells = d.topology.components;
  return d;
}

TriangleSurface orientToBoundVolume(const TriangleSurface& surface, bool& changed,
                                    std::size_t* shells, std::size_t* cavities,
                                    const SurfaceTopology* topology) {
  // One closed shell, consistently oriented already (the usual input): it bounds a volume
  // outward when its volume is positive, and inward when negative (then every triangle flips).
  const SurfaceTopology topo = topology ? *topology : analyzeTopology(surface);
  if (topo.closed() && topo.components == 1 && topo.singularVertices == 0 &&
      topo.degenerateTriangles == 0) {
    if (const int sign = enclosedVolumeSign(surface)) {
      if (shells) *shells = 1;
      if (cavities) *cavities = 0;
      changed = sign < 0;
      TriangleSurface out = surface;
      if (changed)
        for (auto& t : out.triangles) std::swap(t[1], t[2]);
      return out;
    }
  }
  auto points = toPoints(surface);
  auto polygons = toPolygons(surface);
  const auto before = polygons;
  PMP::orient_polygon_soup(points, polygons);
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  if (mesh.number_of_faces() == 0)
    throw std::invalid_argument("orientToBoundVolume: the surface has no triangles");
  if (!CGAL::is_closed(mesh))
    throw std::invalid_argument("orientToBoundVolume: the surface is not closed");
  PMP::orient_to_bound_a_volume(mesh);
  if (shells || cavities) {
    auto volumeIds = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:volume", 0).first;
    std::vector<std::size_t> nesting;
    PMP::volume_connected_components(mesh, volumeIds,
                                     CGAL::parameters::nesting_levels(std::ref(nesting)));
    if (shells) *shells = nesting.size();
    if (cavities) {
      *cavities = 0;
      for (std::size_t level : nesting) *cavities += level % 2 == 1;
    }
  }
  TriangleSurface out = fromMesh(mesh);
  // Compare triangle by triangle: the conversion keeps vertex and face order when no vertex
  // was duplicated, so a flipped triangle is one whose cyclic order changed.
  changed = out.vertices.size() != surface.vertices.size() || out.triangles.size() != before.size();
  for (std::size_t i = 0; !changed && i < before.size(); ++i) {
    const auto& t = out.triangles[i];
    const auto& b = before[i];
    const bool same = (t[0] == b[0] && t[1] == b[1] && t[2] == b[2]) ||
                      (t[0] == b[1] && t[1] == b[2] && t[2] == b[0]) ||
                      (t[0] == b[2] && t[1] == b[0] && t[2] == b[1]);
    changed = !same;
  }
  return out;
}

std::size_t removeDegenerateTriangles(TriangleSurface& surface) {
  const std::size_t before = surface.triangles.size();
  auto points = toPoints(surface);
  auto polygons = toPolygons(surface);
  PMP::orient_polygon_soup(points, polygons);
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  PMP::remove_degenerate_faces(mesh);
  mesh.collect_garbage();
  surface = fromMesh(mesh);
  return before - surface.triangles.size();
}

TriangleSurface fillHoles(const TriangleSurface& surface, std::size_t& filled) {
  if (analyzeTopology(surface).nonManifoldEdges > 0)
    throw std::invalid_argument("hole filling needs a manifold surface; use --repair wrap");
  auto points = toPoints(surface);
  auto polygons = toPolygons(surface);
  PMP::orient_polygon_soup(points, polygons);
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  std::vector<Mesh::Halfedge_index> borders;
  PMP::extract_boundary_cycles(mesh, std::back_inserter(borders));
  filled = 0;
  for (Mesh::Halfedge_index h : borders) {
    std::vector<Mesh::Face_index> patch;
    PMP::triangulate_hole(mesh, h, std::back_inserter(patch));
    filled += !patch.empty();
  }
  mesh.collect_garbage();
  return fromMesh(mesh);
}

TriangleSurface alphaWrap(const TriangleSurface& surface, double alpha, double offset) {
  if (!(alpha > 0) || !(offset > 0))
    throw std::invalid_argument("alpha wrapping needs positive alpha and offset");
  const auto points = toPoints(surface);
  std::vector<std::array<std::size_t, 3>> faces;
  for (const auto& t : surface.triangles)
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) faces.push_back({t[0], t[1], t[2]});
  Mesh wrap;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
  return fromMesh(wrap);
}

}  // namespace polydg
