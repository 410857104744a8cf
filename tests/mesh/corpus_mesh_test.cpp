// Every model of the assimp-testmodels corpus meshes (closed ones directly, broken ones with
// --repair wrap) into a valid simulation mesh, or is refused with a one-line error naming the
// problem: no crash, no hang (ctest's timeout), no invalid mesh. What each readable model must
// do is derived here, independently of polydg's own surface checks: its edges are counted here,
// its degenerate triangles found with CGAL's exact collinearity predicate, and a closed manifold
// one is tested for self-intersections and measured (enclosed volume) by CGAL's
// Polygon_mesh_processing. Then:
//   - open (a boundary edge) or non-manifold (an edge of three or more triangles): refused, the
//     message naming "open (B boundary edges)" or "non-manifold (N edges" with these counts;
//   - closed, manifold, self-intersecting: refused, the message naming "self-intersecting (";
//   - closed, manifold, free of self-intersections: meshed directly, valid, with the volume CGAL
//     finds enclosed;
// models with a degenerate triangle (which polydg removes first) are held only to the general
// rule above.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "mesh/surface_repair.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/assimp_models.h"
#include "tests/support/packages.h"
#include "tests/support/temp_dir.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;
namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using CgalMesh = CGAL::Surface_mesh<Point>;

/// Coarse grid: the corpus run checks robustness, not resolution.
constexpr int kCells = 8;
/// |mesh volume - CGAL's enclosed volume| / CGAL's for the models that mesh directly: measured
/// at most 2.5e-14 (2026-12-01, 153 models); a tenfold margin.
constexpr double kVolumeRelTol = 2.5e-13;

/// What the test finds about a surface without polydg's surface analysis.
struct Facts {
  std::size_t boundaryEdges = 0;     ///< edges of one triangle
  std::size_t nonManifoldEdges = 0;  ///< edges of three or more triangles
  std::size_t degenerate = 0;        ///< triangles with a repeated or three collinear corners
  /// Closed, manifold, without degenerate triangles: CGAL's findings.
  bool checked = false;
  bool orientable = false;  ///< orient_polygon_soup found a consistent orientation
  bool selfIntersecting = false;
  double volume = 0.0;  ///< enclosed, with every shell oriented to bound it (no self-intersection)
};

Facts examine(const TriangleSurface& s) {
  Facts f;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> uses;
  for (const auto& t : s.triangles) {
    const Point a(s.vertices[t[0]].x(), s.vertices[t[0]].y(), s.vertices[t[0]].z());
    const Point b(s.vertices[t[1]].x(), s.vertices[t[1]].y(), s.vertices[t[1]].z());
    const Point c(s.vertices[t[2]].x(), s.vertices[t[2]].y(), s.vertices[t[2]].z());
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || CGAL::collinear(a, b, c)) ++f.degenerate;
    for (int k = 0; k < 3; ++k)
      ++uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  }
  for (const auto& [edge, count] : uses) {
    f.boundaryEdges += count == 1;
    f.nonManifoldEdges += count > 2;
  }
  if (f.boundaryEdges > 0 || f.nonManifoldEdges > 0 || f.degenerate > 0) return f;
  std::vector<Point> points;
  for (const Vec3& p : s.vertices) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  for (const auto& t : s.triangles) polygons.push_back({t[0], t[1], t[2]});
  f.checked = true;
  f.orientable = PMP::orient_polygon_soup(points, polygons);
  CgalMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  f.selfIntersecting = PMP::does_self_intersect(mesh);
  if (f.orientable && !f.selfIntersecting) {
    PMP::orient_to_bound_a_volume(mesh);
    f.volume = PMP::volume(mesh);
  }
  return f;
}

enum class Outcome { Direct, Wrapped, Unreadable, Refused };

struct Result {
  Outcome outcome;
  std::string detail;        ///< why it was refused or unreadable
  std::size_t elements = 0;  ///< of the mesh made, directly or after wrap
};

bool oneLine(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// The sum of the element volumes of `mesh`.
double meshVolume(const PolyMesh& mesh) {
  double v = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) v += signedVolume(mesh, ElementId(e));
  return v;
}

/// The classes of readable models the expectations sort them into.
struct Classes {
  std::size_t clean = 0, open = 0, nonManifold = 0, selfIntersecting = 0, degenerate = 0,
              nonOrientable = 0;
  double worstVolumeError = 0.0;
};

/// Meshes the model at `path` directly (at `cells` along the longest side) and, if refused, with
/// --repair wrap, checking what the independent facts demand of each.
Result meshModel(const std::string& path, Classes& classes, int cells = kCells) {
  TriangleSurface surface;
  try {
    surface = readSurface(path);
  } catch (const std::runtime_error& e) {
    return {Outcome::Unreadable, e.what()};
  }
  const Facts f = examine(surface);
  const bool clean = f.checked && f.orientable && !f.selfIntersecting;
  if (f.degenerate > 0)
    ++classes.degenerate;
  else if (f.boundaryEdges > 0)
    ++classes.open;
  else if (f.nonManifoldEdges > 0)
    ++classes.nonManifold;
  else if (!f.orientable)
    ++classes.nonOrientable;
  else if (f.selfIntersecting)
    ++classes.selfIntersecting;
  else
    ++classes.clean;

  MeshingOptions options;
  options.cellsAlongLongest = cells;
  try {
    const MeshingResult r = meshSurface(surface, options);
    EXPECT_TRUE(r.report.geometry.passed) << path;
    EXPECT_EQ(f.boundaryEdges, 0u) << path << ": an open surface was meshed";
    EXPECT_EQ(f.nonManifoldEdges, 0u) << path << ": a non-manifold surface was meshed";
    EXPECT_FALSE(f.checked && f.selfIntersecting)
        << path << ": a self-intersecting surface was meshed";
    if (clean) {
      const double error = std::abs(meshVolume(r.mesh) - f.volume) / f.volume;
      classes.worstVolumeError = std::max(classes.worstVolumeError, error);
      EXPECT_LE(error, kVolumeRelTol) << path << ": mesh volume " << meshVolume(r.mesh)
                                      << ", CGAL's enclosed volume " << f.volume;
    }
    return {Outcome::Direct, "", r.report.elements};
  } catch (const InputError& refused) {
    const std::string why = refused.what();
    EXPECT_TRUE(oneLine(why)) << path << ": " << why;
    EXPECT_TRUE(contains(why, "open (") || contains(why, "non-manifold (") ||
                contains(why, "self-intersecting (") || contains(why, "degenerate") ||
                contains(why, "no volume"))
        << path << ": the refusal names no defect: " << why;
    EXPECT_FALSE(clean) << path << ": closed, manifold and free of self-intersections by CGAL, "
                        << "but refused: " << why;
    if (f.degenerate == 0) {
      if (f.boundaryEdges > 0) {
        EXPECT_TRUE(contains(why, "open (" + std::to_string(f.boundaryEdges) + " boundary edges)"))
            << path << ": " << f.boundaryEdges << " boundary edges, refused with: " << why;
      }
      if (f.nonManifoldEdges > 0) {
        EXPECT_TRUE(contains(why, "non-manifold (" + std::to_string(f.nonManifoldEdges) + " edges"))
            << path << ": " << f.nonManifoldEdges << " non-manifold edges, refused with: " << why;
      }
      if (f.checked && f.selfIntersecting) {
        EXPECT_TRUE(contains(why, "self-intersecting ("))
            << path << ": self-intersecting by CGAL, refused with: " << why;
      }
    }
    options.repair = RepairMode::Wrap;
    try {
      const MeshingResult r = meshSurface(surface, options);
      EXPECT_TRUE(r.report.geometry.passed) << path << " (wrapped)";
      return {Outcome::Wrapped, why, r.report.elements};
    } catch (const InputError& e) {
      return {Outcome::Refused, e.what()};
    }
  }
}

TEST(CorpusMeshing, EveryModelMeshesOrIsRefusedAsItsSurfaceDemands) {
  ASSERT_TRUE(packages::assimpTestModels());
  std::vector<fs::path> models;
  for (const auto& entry : fs::recursive_directory_iterator(corpus::kAssimpModels))
    if (entry.is_regular_file() && corpus::isSupportedModel(entry.path()))
      models.push_back(entry.path());
  std::sort(models.begin(), models.end());
  std::map<Outcome, std::size_t> counts;
  Classes classes;
  for (const fs::path& model : models) {
    const std::string name = fs::relative(model, corpus::kAssimpModels).string();
    std::cout << "  " << name << " ..." << std::endl;
    const auto start = std::chrono::steady_clock::now();
    const Result r = meshModel(model.string(), classes);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++counts[r.outcome];
    const char* what[] = {"meshed", "meshed after wrap", "unreadable", "refused"};
    std::cout << "  " << name << ": " << what[static_cast<int>(r.outcome)];
    if (r.elements) std::cout << ", " << r.elements << " elements";
    if (!r.detail.empty()) std::cout << " (" << r.detail << ")";
    std::cout << ", " << seconds << " s" << std::endl;
    if (r.outcome == Outcome::Unreadable || r.outcome == Outcome::Refused) {
      EXPECT_TRUE(oneLine(r.detail)) << model;
    }
  }
  std::cout << models.size() << " models: " << counts[Outcome::Direct] << " meshed directly, "
            << counts[Outcome::Wrapped] << " after --repair wrap, " << counts[Outcome::Refused]
            << " refused, " << counts[Outcome::Unreadable] << " unreadable\n"
            << "readable models by CGAL and the edge counts: " << classes.clean
            << " closed, manifold, free of self-intersections; " << classes.selfIntersecting
            << " closed, manifold, self-intersecting; " << classes.open << " open; "
            << classes.nonManifold << " closed but non-manifold; " << classes.nonOrientable
            << " not orientable; " << classes.degenerate << " with degenerate triangles\n"
            << "worst relative volume error of the clean ones: " << classes.worstVolumeError
            << "\n";
  // Each expectation above must have been put to work.
  EXPECT_GT(classes.clean, 0u);
  EXPECT_GT(classes.selfIntersecting, 0u);
  EXPECT_GT(classes.open, 0u);
  EXPECT_GT(classes.nonManifold, 0u);
}

/// `surface` as OBJ text, coordinates to 17 digits (read back exactly).
std::string objText(const TriangleSurface& surface) {
  std::string text;
  char line[96];
  for (const Vec3& p : surface.vertices) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    text += line;
  }
  for (const auto& t : surface.triangles) {
    std::snprintf(line, sizeof line, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
    text += line;
  }
  return text;
}

TEST(CorpusMeshing, TwistedCadPartsMeshDirectly) {
  // CAD-like parts beside the corpus, made here and read back from OBJ files like it: a 20 x 10
  // rectangle extruded 40 high in 200 slices, turning once and tapering to an apex
  // (twistedTaperedPrism: corners within round-off of grid planes, sliver triangles at the
  // apex), alone and beside three boxes. CGAL finds them closed, manifold and free of
  // self-intersections, so each must mesh directly, valid, with CGAL's volume, at every cell
  // count here. (Far from the origin, CGAL's volume, a sum of tetrahedra on the origin, is no
  // reference to round-off: Slice.TwistedPartsTaperedToAPoint slices the parts there.)
  const testing::TempDir dir("corpus_parts");
  const TriangleSurface twist = twistedTaperedPrism(Vec3::Zero(), 20, 10, 40, 200, 1.0);
  TriangleSurface parts = combine(twist, boxSurface(Box3(Vec3(20, -5, 0), Vec3(30, 5, 10))));
  parts = combine(parts, boxSurface(Box3(Vec3(-30, -5, 0), Vec3(-20, 5, 20))));
  parts = combine(parts, boxSurface(Box3(Vec3(-5, 20, 0), Vec3(5, 30, 5))));
  const std::vector<std::string> files = {dir.write("twist.obj", objText(twist)),
                                          dir.write("twist_parts.obj", objText(parts))};
  const std::vector<int> cellCounts = {8, 16, 24, 32, 48, 64};
  Classes classes;
  for (const std::string& file : files)
    for (const int cells : cellCounts) {
      const Result r = meshModel(file, classes, cells);
      EXPECT_EQ(r.outcome, Outcome::Direct) << file << " at " << cells << " cells: " << r.detail;
      std::cout << "  " << fs::path(file).filename().string() << " at " << cells
                << " cells: " << r.elements << " elements\n";
    }
  EXPECT_EQ(classes.clean, cellCounts.size() * files.size());
  std::cout << "worst relative volume error: " << classes.worstVolumeError << "\n";
}

/// CGAL's count of self-intersecting triangle pairs of `s` (closed and manifold), on the
/// Surface_mesh made of it: the reference diagnose() counts on the soup.
std::size_t cgalSelfIntersections(const TriangleSurface& s) {
  std::vector<Point> points;
  for (const Vec3& p : s.vertices) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  for (const auto& t : s.triangles) polygons.push_back({t[0], t[1], t[2]});
  CgalMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  std::vector<std::pair<CgalMesh::Face_index, CgalMesh::Face_index>> pairs;
  PMP::self_intersections(faces(mesh), mesh, std::back_inserter(pairs));
  return pairs.size();
}

/// A double pyramid over a pentagram: apex v above, w below, the ring of five corners visited
/// twice around the axis. Closed and manifold; fan triangles that share only an apex pass
/// through each other, and the ring's edges cross.
TriangleSurface pentagramBipyramid() {
  TriangleSurface s;
  s.vertices = {Vec3(0.0, 0.0, 1.0), Vec3(0.0, 0.0, -1.0)};
  for (int i = 0; i < 5; ++i) {
    const double angle = 2.0 * 3.14159265358979 * (2 * i % 5) / 5.0;
    const double r = i % 2 == 0 ? 1.0 : 0.3;  // unequal: some triangles pass through others
    s.vertices.emplace_back(r * std::cos(angle), r * std::sin(angle), 0.0);
  }
  for (std::uint32_t i = 0; i < 5; ++i) {
    const std::uint32_t a = 2 + i, b = 2 + (i + 1) % 5;
    s.triangles.push_back({0, a, b});
    s.triangles.push_back({1, b, a});
  }
  return s;
}

/// Two double pyramids over a hexagon, the second turned a quarter about the x axis. In each, the
/// small fan triangle (v, c, d) has its edge c d through the large (v, a, b), whose edge a b
/// stays clear of it: the pair is found from one side only. The turn changes the boxes so that
/// CGAL's box intersection hands the pair over the other way round: each side is needed.
TriangleSurface piercedFans() {
  TriangleSurface s;
  for (const bool turned : {false, true})
    for (const Vec3& p :
         {Vec3(0.0, 0.0, 0.0), Vec3(0.0, 0.0, -3.0), Vec3(4.0, 0.0, 0.0), Vec3(0.0, 4.0, 0.0),
          Vec3(-2.0, -1.0, 0.0), Vec3(-0.2, 0.9, 1.0), Vec3(0.9, -0.2, -1.0), Vec3(2.0, -2.0, 0.0)})
      s.vertices.push_back(turned ? Vec3(p.x() + 20.0, p.z(), -p.y()) : p);
  for (std::uint32_t base : {0u, 8u})
    for (std::uint32_t i = 0; i < 6; ++i) {
      const std::uint32_t a = base + 2 + i, b = base + 2 + (i + 1) % 6;
      s.triangles.push_back({base, a, b});
      s.triangles.push_back({base + 1, b, a});
    }
  return s;
}

TEST(SurfaceDiagnosis, SelfIntersectionsAreCountedAsCgalCountsThemOnTheMesh) {
  TriangleSurface pillow;  // two triangles back to back: folded onto each other at every edge
  pillow.vertices = {Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)};
  pillow.triangles = {{0, 1, 2}, {0, 2, 1}};
  TriangleSurface pierced = icosphere(Vec3::Zero(), 1.0, 2);  // a vertex pushed through
  pierced.vertices[0] *= -1.5;
  const Vec3 far(3.0e6, -2.0e6, 1.0e6);
  const struct {
    const char* name;
    TriangleSurface surface;
    bool intersecting;
  } cases[] = {
      {"sphere", icosphere(Vec3(0.1, 0.2, -0.3), 1.0, 3), false},
      {"overlapping spheres",
       combine(icosphere(Vec3::Zero(), 1.0, 2), icosphere(Vec3(0.8, 0.0, 0.0), 1.0, 2)), true},
      {"overlapping spheres far from the origin",
       combine(icosphere(far, 1.0, 2), icosphere(far + Vec3(0.8, 0.0, 0.0), 1.0, 2)), true},
      // Both have a corner at (1, 0, 0), as two vertices: the six triangles about it on each
      // side touch the other six there, which counts (they share no vertex).
      {"spheres touching at a point",
       combine(icosphere(Vec3::Zero(), 1.0, 1), icosphere(Vec3(2.0, 0.0, 0.0), 1.0, 1)), true},
      {"pillow", pillow, true},
      {"pierced sphere", pierced, true},
      {"pentagram bipyramid", pentagramBipyramid(), true},
      {"pierced fans", piercedFans(), true},
      {"thin torus knot", torusKnot(2, 3, 1.0, 0.4, 0.1, 96, 8), false},
      {"thick torus knot", torusKnot(2, 3, 1.0, 0.4, 0.45, 96, 8), true},
  };
  for (const auto& c : cases) {
    const SurfaceDiagnosis d = diagnose(c.surface);
    ASSERT_TRUE(d.topology.closed()) << c.name;
    ASSERT_TRUE(d.checkedSelfIntersections) << c.name;
    EXPECT_EQ(d.selfIntersections, cgalSelfIntersections(c.surface)) << c.name;
    EXPECT_EQ(d.selfIntersections > 0, c.intersecting) << c.name << ": " << d.selfIntersections;
  }
}

TEST(SurfaceDiagnosis, ASelfIntersectionTestAskedToStopGivesNoCount) {
  // meshSurface starts the test before it knows the test applies, and stops it if not.
  const TriangleSurface overlapping =
      combine(icosphere(Vec3::Zero(), 1.0, 2), icosphere(Vec3(0.8, 0.0, 0.0), 1.0, 2));
  std::atomic<bool> stop{false};
  EXPECT_EQ(selfIntersectionsOfClosedSurface(overlapping, &stop),
            cgalSelfIntersections(overlapping));
  stop = true;
  EXPECT_FALSE(selfIntersectionsOfClosedSurface(overlapping, &stop).has_value());
}

}  // namespace
}  // namespace polydg
