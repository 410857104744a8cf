// 1000 random plane cuts through sliced spheres (sequences of 10): after every cut the mesh
// validates, the volume is conserved, the component count matches independent counts, and the
// operation's own (local) validation passes.
#include <chrono>
#include <cstdio>
#include <numeric>
#include <random>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include <gtest/gtest.h>

#include "cut/mesh_editor.h"
#include "polydg/cut/cut.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_shapes.h"
#include "util/union_find.h"

namespace polydg {
namespace {

constexpr std::uint64_t kSeed = 20261123;
constexpr int kCuts = 1000;
/// Cuts by whole planes never re-join anything, so n successive cuts of a convex body leave up
/// to (n^3 + 5n + 6) / 6 components (40,560 after 100 of these cuts): the 1000 cuts are made
/// as sequences of this many on fresh copies of the sphere.
constexpr int kCutsPerSphere = 10;
constexpr double kRandomCutsVolumeTolerance = 1e-10;

/// Components as unions of elements that list the same face (element face lists only, not the
/// faces' front/back links that checkGeometry() and the editor use).
std::size_t componentsFromFaceLists(const PolyMesh& mesh) {
  UnionFind sets(mesh.numElements());
  std::unordered_map<std::uint32_t, std::size_t> firstUser;
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
      const auto [it, inserted] = firstUser.try_emplace(use.face.value, e);
      if (!inserted)
        sets.unite(static_cast<std::uint32_t>(e), static_cast<std::uint32_t>(it->second));
    }
  std::size_t count = 0;
  for (std::uint32_t e = 0; e < sets.size(); ++e) count += sets.find(e) == e;
  return count;
}

/// Components from geometry alone: the sliced sphere is convex, so each cell of the
/// arrangement of the cut planes is one convex component, and elements are in the same
/// component exactly when their centroids are on the same side of every plane.
std::size_t componentsFromPlaneSides(const MeshEditor& editor,
                                     const std::vector<std::pair<Vec3, double>>& planes) {
  std::unordered_set<std::string> cells;
  for (std::size_t e = 0; e < editor.mesh().numElements(); ++e) {
    const Vec3 c = editor.moments().centroid(ElementId(e));
    std::string signs(planes.size(), '-');
    for (std::size_t i = 0; i < planes.size(); ++i)
      if (planes[i].first.dot(c) > planes[i].second) signs[i] = '+';
    cells.insert(std::move(signs));
  }
  return cells.size();
}

TEST(RandomCuts, ThousandCutsThroughSlicedSpheres) {
  std::printf("seed %llu\n", static_cast<unsigned long long>(kSeed));
  MeshingOptions meshing;
  meshing.cellsAlongLongest = 3;
  const MeshingResult sphere = meshSurface(icosphere(Vec3(0.1, -0.2, 0.3), 1.0, 3), meshing);
  const double cellVolume = sphere.report.grid.cellVolume();
  const Box3 box = meshBounds(sphere.mesh);

  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0), component(-1.0, 1.0);
  std::size_t split = 0, merged = 0, isolated = 0, reintegrated = 0, total = 0, largest = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int sequence = 0; sequence < kCuts / kCutsPerSphere; ++sequence) {
    MeshEditor editor(sphere.mesh, cellVolume);
    const double volume = editor.volume();
    std::vector<std::pair<Vec3, double>> planes;
    for (int i = 0; i < kCutsPerSphere; ++i) {
      const std::string where =
          "sequence " + std::to_string(sequence) + ", cut " + std::to_string(i);
      const Vec3 p = box.min() + Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(box.sizes());
      Vec3 n(component(rng), component(rng), component(rng));
      if (n.squaredNorm() == 0.0) n = Vec3::UnitX();
      const Blade blade = Blade::plane(n, n.dot(p));
      planes.emplace_back(blade.normal, blade.offset);
      const OperationReport r = editor.cut(blade);
      ASSERT_TRUE(r.check.passed) << where << ": " << r.check.failure;
      split += r.elementsSplit;
      merged += r.sliversMerged;
      isolated += r.isolatedSlivers;
      reintegrated += r.facesReintegrated;
      total += r.facesTotal;

      const GeometryCheck check = checkGeometry(editor.mesh());
      ASSERT_TRUE(check.passed) << where << ": " << check.messages.front();
      ASSERT_NEAR(check.volume, volume, kRandomCutsVolumeTolerance * volume) << where;
      ASSERT_NEAR(editor.volume(), volume, kRandomCutsVolumeTolerance * volume) << where;
      ASSERT_EQ(check.components, componentsFromFaceLists(editor.mesh())) << where;
      ASSERT_EQ(check.components, componentsFromPlaneSides(editor, planes)) << where;
    }
    largest = std::max(largest, editor.mesh().numElements());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "%d cuts in %.2f s (largest mesh %zu elements): %zu splits, %zu slivers merged, "
      "%zu isolated; faces re-integrated %zu of %zu (summed over cuts)\n",
      kCuts, seconds, largest, split, merged, isolated, reintegrated, total);
}

}  // namespace
}  // namespace polydg
