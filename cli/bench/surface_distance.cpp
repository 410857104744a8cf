#include "cli/bench/surface_distance.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>

namespace polydg::bench {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
using Side = CGAL::Side_of_triangle_mesh<Mesh, Kernel, CGAL::Default, AabbTree>;

Point point(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

Mesh surfaceMesh(const TriangleSurface& surface) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<Point> points;
  points.reserve(surface.vertices.size());
  for (const Vec3& v : surface.vertices) points.push_back(point(v));
  std::vector<std::array<std::size_t, 3>> triangles;
  triangles.reserve(surface.triangles.size());
  for (const auto& t : surface.triangles) triangles.push_back({t[0], t[1], t[2]});
  // The inside test counts crossings of a ray, which only a closed surface makes meaningful.
  if (!analyzeTopology(surface).closed() || !pmp::is_polygon_soup_a_polygon_mesh(triangles))
    throw std::invalid_argument("the surface is not a closed, oriented manifold triangle mesh");
  Mesh mesh;
  pmp::polygon_soup_to_polygon_mesh(points, triangles, mesh);
  return mesh;
}

}  // namespace

/// The mesh, its tree, and the inside test on that tree (declared in this order: each refers to
/// the one before).
struct SurfaceDistance::Tree {
  explicit Tree(const TriangleSurface& surface)
      : mesh(surfaceMesh(surface)), tree(faces(mesh).first, faces(mesh).second, mesh), side(tree) {
    tree.accelerate_distance_queries();
  }
  Mesh mesh;
  AabbTree tree;
  Side side;
};

SurfaceDistance::SurfaceDistance(const TriangleSurface& surface)
    : tree_(std::make_unique<Tree>(surface)) {}

SurfaceDistance::~SurfaceDistance() = default;

double SurfaceDistance::distance(const Vec3& p) const {
  return std::sqrt(tree_->tree.squared_distance(point(p)));
}

double SurfaceDistance::largestDistance(const std::vector<Vec3>& points) const {
  double largest = 0.0;
  for (const Vec3& p : points) largest = std::max(largest, distance(p));
  return largest;
}

bool SurfaceDistance::inside(const Vec3& p) const {
  return tree_->side(point(p)) == CGAL::ON_BOUNDED_SIDE;
}

}  // namespace polydg::bench
