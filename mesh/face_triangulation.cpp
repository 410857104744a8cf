#include "mesh/face_triangulation.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include "polydg/mesh/geometry.h"

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/// Per-triangle nesting level: how many loop edges a path from outside the face must cross to
/// reach the triangle (-1 until visited). Odd levels are inside the face.
struct Nesting {
  int level = -1;
};

using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<VertexId, Kernel>;
using FaceBase = CGAL::Constrained_triangulation_face_base_2<
    Kernel, CGAL::Triangulation_face_base_with_info_2<Nesting, Kernel>>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// The default intersection tag: constraints may touch at input vertices, but any crossing that
// would need a new point throws (we never add Steiner points).
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<
    Kernel, Tds, CGAL::No_constraint_intersection_requiring_constructions_tag>;

std::string faceName(FaceId f) { return "face " + std::to_string(f.value); }

/// Assigns nesting levels: a flood fill from the infinite face that does not cross constrained
/// edges, then repeated from the far side of each constrained edge at one level deeper.
void markNesting(Cdt& cdt) {
  for (auto fh = cdt.all_faces_begin(); fh != cdt.all_faces_end(); ++fh) fh->info().level = -1;

  std::vector<std::pair<Cdt::Face_handle, int>> seeds{{cdt.infinite_face(), 0}};
  std::vector<Cdt::Face_handle> stack;
  // Seeds are processed in order of increasing level: every seed pushed while filling level L
  // has level L + 1, and the seeds of level L are all taken before those of level L + 1.
  for (std::size_t next = 0; next < seeds.size(); ++next) {
    const auto [seed, level] = seeds[next];
    if (seed->info().level != -1) continue;
    seed->info().level = level;
    stack.push_back(seed);
    while (!stack.empty()) {
      const Cdt::Face_handle fh = stack.back();
      stack.pop_back();
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle neighbour = fh->neighbor(i);
        if (neighbour->info().level != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(fh, i))) {
          seeds.emplace_back(neighbour, level + 1);
        } else {
          neighbour->info().level = level;
          stack.push_back(neighbour);
        }
      }
    }
  }
}

}  // namespace

std::vector<std::array<VertexId, 3>> triangulateFace(const PolyMesh& mesh, FaceId f) {
  const Face& face = mesh.face(f);
  const Vec3 area = areaVector(mesh, f);
  int drop = 0;
  for (int axis = 1; axis < 3; ++axis)
    if (std::abs(area[axis]) > std::abs(area[drop])) drop = axis;
  if (area[drop] == 0.0)
    throw std::runtime_error(faceName(f) + " has zero area and cannot be triangulated");
  // (u, v) = the two remaining axes in cyclic order, so the projection keeps the orientation of
  // the face when area[drop] > 0 and reverses it otherwise.
  const int uAxis = (drop + 1) % 3;
  const int vAxis = (drop + 2) % 3;
  const bool flip = area[drop] < 0.0;

  Cdt cdt;
  try {
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      const auto loop = face.loop(k);
      std::vector<Cdt::Vertex_handle> handles;
      handles.reserve(loop.size());
      for (VertexId v : loop) {
        const Vec3& p = mesh.position(v);
        const std::size_t before = cdt.number_of_vertices();
        const Cdt::Vertex_handle h = cdt.insert(Kernel::Point_2(p[uAxis], p[vAxis]));
        if (cdt.number_of_vertices() > before) {
          h->info() = v;
        } else if (h->info() != v) {
          throw std::runtime_error(faceName(f) + " has vertices " + std::to_string(v.value) +
                                   " and " + std::to_string(h->info().value) +
                                   " at the same position");
        }
        handles.push_back(h);
      }
      for (std::size_t i = 0; i < handles.size(); ++i) {
        const auto& a = handles[i];
        const auto& b = handles[(i + 1) % handles.size()];
        if (a != b) cdt.insert_constraint(a, b);
      }
    }
  } catch (const Cdt::Intersection_of_constraints_exception&) {
    throw std::runtime_error(faceName(f) + " has loops that cross; it cannot be triangulated");
  }

  markNesting(cdt);
  std::vector<std::array<VertexId, 3>> triangles;
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
    if (fh->info().level % 2 != 1) continue;
    const VertexId a = fh->vertex(0)->info();
    const VertexId b = fh->vertex(1)->info();
    const VertexId c = fh->vertex(2)->info();
    // CGAL's finite faces are counter-clockwise in (u, v).
    triangles.push_back(flip ? std::array<VertexId, 3>{a, c, b} : std::array<VertexId, 3>{a, b, c});
  }
  return triangles;
}

}  // namespace polydg
