// Region DG checks (physics/checks/region_checks.h): the patch test and the zero modes per
// component of regions of 1, a few and many elements, connected or not, on a hex grid, a sliced
// sphere, a grid with a sliver and a grid translated by 1e6; the same answer as the global checks
// on the whole mesh; failures on a vertex moved off its faces' planes, a reversed face, an inverted
// element and a stale moment cache, and none for a region away from a defect. With
// RegionCoupling::HoldingFaces: slivers hanging by thin faces and elements touching through
// strips a round-off wide (a Swiss cheese whose walls lie just off the grid planes) are bodies
// of their own, every ring of the cheese passes as the whole mesh does, and defects still fail.
#include "physics/checks/region_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

/// A corrupted region fails the patch test by a wide margin (relative residuals >= 8e-7 below;
/// valid regions stay below 1e-12).
constexpr double kCorruptionMargin = 1e2;

using Region = std::vector<char>;

RegionDgCheck check(const PolyMesh& mesh, const Region& region, int degree = 1) {
  MomentCache moments(mesh, 2 * degree);
  moments.update();
  LocalDgCheckOptions options;
  options.basis.degree = degree;
  return regionDgChecks(mesh, moments, region, options);
}

Region allOf(const PolyMesh& mesh) { return Region(mesh.numElements(), 1); }

Region only(const PolyMesh& mesh, std::initializer_list<std::size_t> elements) {
  Region r(mesh.numElements(), 0);
  for (std::size_t e : elements) r[e] = 1;
  return r;
}

/// Element e and the elements across its faces.
Region withRing(const PolyMesh& mesh, ElementId e) {
  Region r(mesh.numElements(), 0);
  r[e.index()] = 1;
  for (const FaceUse& use : mesh.element(e).faces) {
    const Face& f = mesh.face(use.face);
    for (ElementId n : {f.front, f.back})
      if (n.valid()) r[n.index()] = 1;
  }
  return r;
}

/// Components of the region counted independently: flood fill through shared faces.
std::size_t regionComponents(const PolyMesh& mesh, const Region& region) {
  std::vector<char> seen(mesh.numElements(), 0);
  std::size_t count = 0;
  for (std::size_t s = 0; s < mesh.numElements(); ++s) {
    if (!region[s] || seen[s]) continue;
    ++count;
    std::vector<std::size_t> stack{s};
    seen[s] = 1;
    while (!stack.empty()) {
      const ElementId e(stack.back());
      stack.pop_back();
      for (const FaceUse& use : mesh.element(e).faces) {
        const Face& f = mesh.face(use.face);
        const ElementId n = f.front == e ? f.back : f.front;
        if (n.valid() && region[n.index()] && !seen[n.index()]) {
          seen[n.index()] = 1;
          stack.push_back(n.index());
        }
      }
    }
  }
  return count;
}

void expectPasses(const PolyMesh& mesh, const Region& region, const std::string& name,
                  int degree = 1) {
  const RegionDgCheck c = check(mesh, region, degree);
  const auto selected = static_cast<std::size_t>(std::count(region.begin(), region.end(), 1));
  const std::size_t components = regionComponents(mesh, region);
  EXPECT_EQ(c.degree, degree) << name;
  EXPECT_EQ(c.elements, selected) << name;
  EXPECT_LT(c.patchTestResidual, kRegionPatchResidualTolerance) << name;
  EXPECT_LE(c.momentMismatch, kRegionMomentTolerance) << name;
  EXPECT_EQ(c.components, components) << name;
  ASSERT_EQ(c.zeroModesPerComponent.size(), components) << name;
  for (std::size_t k = 0; k < components; ++k)
    EXPECT_EQ(c.zeroModesPerComponent[k], 6u) << name << " component " << k;
  EXPECT_EQ(c.zeroModes, 6 * components) << name;
  EXPECT_TRUE(c.passed()) << name;
}

PolyMesh grid4() { return hexGridMesh(4, 4, 4, Box3(Vec3::Zero(), Vec3::Ones())); }

/// Grid element (i, j, k) of an n^3 grid (hexGridMesh numbers x fastest).
std::size_t cell(int n, int i, int j, int k) {
  return static_cast<std::size_t>(i + n * (j + n * k));
}

TEST(RegionChecks, HexGridRegionsOfOneFewAndManyElements) {
  const PolyMesh mesh = grid4();
  {
    MomentCache moments(mesh, 1);
    moments.update();
    ASSERT_LT((moments.centroid(ElementId(cell(4, 1, 2, 3))) - Vec3(0.375, 0.625, 0.875)).norm(),
              1e-15);
  }
  for (int degree : {1, 2}) {
    const std::string p = " p" + std::to_string(degree);
    expectPasses(mesh, only(mesh, {cell(4, 1, 1, 1)}), "interior element" + p, degree);
    expectPasses(mesh, only(mesh, {0}), "corner element" + p, degree);
    expectPasses(mesh, withRing(mesh, ElementId(cell(4, 1, 2, 1))), "element and ring" + p, degree);
    expectPasses(mesh, allOf(mesh), "whole grid" + p, degree);
  }
}

TEST(RegionChecks, DisconnectedRegionsCountTheirComponents) {
  const PolyMesh mesh = grid4();
  // Two single elements apart, and the layers z = 0 and z = 2 (layer 1 left out).
  const Region two = only(mesh, {cell(4, 0, 0, 0), cell(4, 3, 3, 3)});
  Region layers(mesh.numElements(), 0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) layers[cell(4, i, j, 0)] = layers[cell(4, i, j, 2)] = 1;
  // Elements touching only along an edge are not connected: a checkerboard of 4 in one layer.
  const Region diagonal =
      only(mesh, {cell(4, 0, 0, 1), cell(4, 1, 1, 1), cell(4, 2, 2, 1), cell(4, 3, 3, 1)});
  ASSERT_EQ(regionComponents(mesh, two), 2u);
  ASSERT_EQ(regionComponents(mesh, layers), 2u);
  ASSERT_EQ(regionComponents(mesh, diagonal), 4u);
  expectPasses(mesh, two, "two elements");
  expectPasses(mesh, layers, "two layers");
  expectPasses(mesh, diagonal, "four diagonal elements");
  EXPECT_EQ(check(mesh, diagonal).zeroModes, 24u);
}

TEST(RegionChecks, WholeMeshAgreesWithTheGlobalChecks) {
  // The two-block mesh of two components and the 4^3 grid.
  const PolyMesh two = testing::twoSeparateBlocks();
  for (const PolyMesh& m : {two, grid4()}) {
    for (int degree : {1, 2}) {
      PhysicsCheckOptions global;
      global.discretization.basis.degree = degree;
      const PatchTestResult patch = patchTest(m, global);
      const ZeroModeReport modes = rigidModes(m, global);
      const RegionDgCheck region = check(m, allOf(m), degree);
      EXPECT_LT(patch.relativeError, kLocalPatchTestTolerance);
      EXPECT_LT(region.patchTestResidual, kRegionPatchResidualTolerance);
      EXPECT_EQ(region.components, modes.components);
      EXPECT_EQ(region.zeroModesPerComponent, modes.zeroModesPerComponent);
      EXPECT_EQ(region.zeroModes, modes.zeroModes);
      EXPECT_TRUE(region.passed());
    }
  }
}

PolyMesh slicedSphere() {
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.05), 1.0, 3);
  return sliceSurface(sphere, Grid::withCellsAlongLongest(bounds(sphere), 6));
}

TEST(RegionChecks, SlicedSphere) {
  const PolyMesh mesh = slicedSphere();
  ASSERT_TRUE(checkGeometry(mesh).passed);
  ASSERT_GT(mesh.numElements(), 100u);
  MomentCache moments(mesh, 2);
  moments.update();
  // The two caps |x - 0.1| > 0.5: many elements, two components.
  Region caps(mesh.numElements(), 0);
  for (std::size_t i = 0; i < mesh.numElements(); ++i)
    caps[i] = std::abs(moments.centroid(ElementId(i)).x() - 0.1) > 0.5;
  ASSERT_EQ(regionComponents(mesh, caps), 2u);
  ASSERT_GT(std::count(caps.begin(), caps.end(), 1), 20);
  for (int degree : {1, 2}) {
    const std::string p = " p" + std::to_string(degree);
    expectPasses(mesh, only(mesh, {0}), "one element" + p, degree);
    expectPasses(mesh, withRing(mesh, ElementId(mesh.numElements() / 2)), "ring" + p, degree);
    expectPasses(mesh, caps, "two caps" + p, degree);
    expectPasses(mesh, allOf(mesh), "whole sphere" + p, degree);
  }
}

TEST(RegionChecks, SliverAndFarFromTheOrigin) {
  // The first layer x < 1e-6 of a 3^3 grid: slivers of relative thickness t = 1e-6.
  PolyMesh sliver = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  for (Vec3& p : sliver.positions().raw())
    if (std::abs(p.x() - 1.0 / 3.0) < 1e-12) p.x() = 1e-6;
  ASSERT_TRUE(checkGeometry(sliver).passed);
  const std::size_t thin = cell(3, 0, 1, 1), thick = cell(3, 1, 1, 1);
  expectPasses(sliver, only(sliver, {thin}), "sliver p1", 1);
  for (int degree : {1, 2}) {
    const std::string p = " p" + std::to_string(degree);
    expectPasses(sliver, only(sliver, {thin, thick}), "sliver and its thick neighbour" + p, degree);
    expectPasses(sliver, only(sliver, {thin, thick, cell(3, 0, 1, 0), cell(3, 1, 1, 0)}),
                 "two slivers held by their thick neighbours" + p, degree);
    expectPasses(sliver, allOf(sliver), "sliver grid" + p, degree);
  }
  PolyMesh far = grid4();
  transform(far, 1.0, Vec3(1e6, -1e6, 1e6));
  expectPasses(far, only(far, {cell(4, 1, 1, 1)}), "translated element");
  expectPasses(far, withRing(far, ElementId(cell(4, 2, 1, 2))), "translated ring");
  expectPasses(far, allOf(far), "translated grid");
}

TEST(RegionChecks, SliversCountTheirRigidMotionsOnly) {
  // Slivers of relative thickness t = 1e-6: a free sliver bends at ~3.7 t^2 from degree 2 on and
  // slivers joined only through their thin faces hinge at ~t^2. Those are elastic modes of the
  // element (counted by elementZeroModes()' scale-free rule) and a face's soft modes (which
  // AllFaces joins without counting): 6 zero modes each, as in localDgChecks().
  PolyMesh sliver = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  for (Vec3& p : sliver.positions().raw())
    if (std::abs(p.x() - 1.0 / 3.0) < 1e-12) p.x() = 1e-6;
  const std::size_t thin = cell(3, 0, 1, 1);
  const RegionDgCheck alone = check(sliver, only(sliver, {thin}), 2);
  EXPECT_LT(alone.patchTestResidual, kRegionPatchResidualTolerance);
  EXPECT_EQ(alone.zeroModes, 6u);
  Region layer(sliver.numElements(), 0);
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) layer[cell(3, 0, j, k)] = 1;
  const RegionDgCheck hinged = check(sliver, layer, 1);
  EXPECT_LT(hinged.patchTestResidual, kRegionPatchResidualTolerance);
  EXPECT_EQ(hinged.components, 1u);
  EXPECT_EQ(hinged.zeroModes, 6u);
}

using testing::withReversedFaces;

RegionDgCheck checkHolding(const PolyMesh& mesh, const Region& region, int degree = 1) {
  MomentCache moments(mesh, 2 * degree);
  moments.update();
  LocalDgCheckOptions options;
  options.basis.degree = degree;
  return regionDgChecks(mesh, moments, region, options, RegionCoupling::HoldingFaces);
}

TEST(RegionChecks, HoldingFacesMakeSliversHangingByThinFacesBodiesOfTheirOwn) {
  // The layer of slivers of SliversHangingByTheirThinFacesHaveSoftModes: their thin faces
  // (t = 1e-6) hinge, so they join nothing, and each sliver is one body with 6 zero modes; the
  // 12 faces between neighbouring slivers of the 3 x 3 layer are loose.
  PolyMesh sliver = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  for (Vec3& p : sliver.positions().raw())
    if (std::abs(p.x() - 1.0 / 3.0) < 1e-12) p.x() = 1e-6;
  Region layer(sliver.numElements(), 0);
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) layer[cell(3, 0, j, k)] = 1;
  const RegionDgCheck hinged = checkHolding(sliver, layer, 1);
  EXPECT_EQ(hinged.components, 9u);
  EXPECT_EQ(hinged.looseFaces, 12u);
  EXPECT_EQ(hinged.zeroModes, 54u);
  EXPECT_TRUE(hinged.passed());
  // Held through their large faces, the slivers join the grid: one body, as with AllFaces.
  for (int degree : {1, 2}) {
    const RegionDgCheck all = checkHolding(sliver, allOf(sliver), degree);
    EXPECT_EQ(all.components, 1u) << degree;
    EXPECT_EQ(all.zeroModes, 6u) << degree;
    EXPECT_TRUE(all.passed()) << degree;
  }
  // A sliver's own bending (~3.7 t^2 from degree 2 on) is an elastic mode of the element.
  EXPECT_EQ(checkHolding(sliver, only(sliver, {cell(3, 0, 1, 1)}), 2).zeroModes, 6u);
}

TEST(RegionChecks, HoldingFacesAgreeWithTheWholeMeshOnSwissCheesesWithThinFaces) {
  // Swiss cheeses whose walls lie 2^-24 and 2^-7 beyond the grid planes (4e-8 and 6e-3 of a
  // cell at 8 cells along 11 units): elements touch some of their neighbours through strips that
  // narrow (or squares that small), which hold their translations but, below a width of about
  // 1e-3 of a cell, not their rotations about the strip, whose stiffness goes as the width^4.
  // Each whole mesh is one body (rigidModes()). Every element with its ring of neighbours
  // passes with HoldingFaces (the strips that do not hold their two elements are loose faces)
  // and with AllFaces (one component per face-connected part of the ring, 6 zero modes each).
  for (const double offset : {testing::kCheeseWallOffset, 0x1p-7}) {
    MeshingOptions meshing;
    meshing.cellsAlongLongest = 8;
    const Box3 box(Vec3::Zero(), Vec3(11, 10, 3));
    const PolyMesh mesh =
        meshSurface(swissCheeseBlock(testing::cheeseWallsOffGrid(box, 8, offset)), meshing).mesh;
    ASSERT_TRUE(checkGeometry(mesh).passed) << offset;
    const ZeroModeReport modes = rigidModes(mesh, PhysicsCheckOptions{});
    ASSERT_EQ(modes.components, 1u) << offset;
    ASSERT_EQ(modes.zeroModes, 6u) << offset;
    const RegionDgCheck whole = checkHolding(mesh, allOf(mesh));
    EXPECT_GT(whole.looseFaces, 0u) << offset;
    EXPECT_EQ(whole.components, 1u) << offset;
    EXPECT_EQ(whole.zeroModes, 6u) << offset;
    EXPECT_TRUE(whole.passed()) << offset;
    for (std::size_t e = 0; e < mesh.numElements(); ++e) {
      const Region ring = withRing(mesh, ElementId(e));
      const RegionDgCheck holding = checkHolding(mesh, ring);
      EXPECT_TRUE(holding.passed()) << offset << ", element " << e << ": " << holding.zeroModes
                                    << " zero modes for " << holding.components << " components";
      const RegionDgCheck all = check(mesh, ring);
      EXPECT_EQ(all.components, regionComponents(mesh, ring)) << offset << ", element " << e;
      EXPECT_TRUE(all.passed()) << offset << ", element " << e;
    }
    std::printf("offset %g: %zu elements, %zu loose faces\n", offset, mesh.numElements(),
                whole.looseFaces);
  }
}

TEST(RegionChecks, HoldingFacesStillFailOnDefects) {
  // A reversed face, an inverted element and a stale cache fail as with AllFaces.
  const PolyMesh grid = grid4();
  const ElementId bad(cell(4, 1, 1, 0));
  int k = -1;
  for (std::size_t j = 0; j < grid.element(bad).faces.size(); ++j)
    if (grid.face(grid.element(bad).faces[j].face).isBoundary()) k = static_cast<int>(j);
  ASSERT_GE(k, 0);
  const PolyMesh reversed = withReversedFaces(grid, bad, k);
  EXPECT_FALSE(checkHolding(reversed, withRing(reversed, bad)).passed());
  const PolyMesh inverted =
      withReversedFaces(boxMesh(Box3(Vec3::Zero(), Vec3(1, 2, 3))), ElementId(0), -1);
  const RegionDgCheck c = checkHolding(inverted, allOf(inverted));
  EXPECT_FALSE(c.passed());
  EXPECT_NE(c.zeroModes, 6u);
  PolyMesh mesh = grid4();
  MomentCache moments(mesh, 2);
  moments.update();
  transform(mesh, 1.5, Vec3::Zero());
  EXPECT_FALSE(regionDgChecks(mesh, moments, withRing(mesh, ElementId(cell(4, 1, 1, 1))), {},
                              RegionCoupling::HoldingFaces)
                   .passed());
}

TEST(RegionChecks, FailsOnAVertexOffItsFacesPlanes) {
  // Grid node (1, 1, 1) of the 4^3 grid moved off the planes of its faces by 1e-3 of a cell.
  PolyMesh mesh = grid4();
  for (Vec3& p : mesh.positions().raw())
    if ((p - Vec3::Constant(0.25)).norm() < 1e-12) p += Vec3(0.3e-3, 0.2e-3, 0.4e-3) * 0.25;
  ASSERT_FALSE(checkGeometry(mesh).passed);
  for (int degree : {1, 2}) {
    const RegionDgCheck touching = check(mesh, only(mesh, {cell(4, 1, 1, 1)}), degree);
    EXPECT_GT(touching.patchTestResidual, kCorruptionMargin * kRegionPatchResidualTolerance)
        << degree;
    EXPECT_FALSE(touching.passed()) << degree;
    EXPECT_FALSE(check(mesh, allOf(mesh), degree).passed()) << degree;
    // Far from the node (not even a neighbour of an element that has it): passes.
    expectPasses(mesh, only(mesh, {cell(4, 3, 3, 3), cell(4, 3, 3, 2)}), "far region");
  }
}

TEST(RegionChecks, FailsOnAReversedFaceAndAnInvertedElement) {
  const PolyMesh grid = grid4();
  const ElementId bad(cell(4, 1, 1, 0));  // on the boundary z = 0
  int k = -1;
  for (std::size_t j = 0; j < grid.element(bad).faces.size(); ++j)
    if (grid.face(grid.element(bad).faces[j].face).isBoundary()) k = static_cast<int>(j);
  ASSERT_GE(k, 0);
  const PolyMesh reversed = withReversedFaces(grid, bad, k);
  ASSERT_FALSE(checkGeometry(reversed).passed);
  for (int degree : {1, 2}) {
    const RegionDgCheck c = check(reversed, withRing(reversed, bad), degree);
    EXPECT_GT(c.patchTestResidual, kCorruptionMargin * kRegionPatchResidualTolerance) << degree;
    EXPECT_FALSE(c.passed()) << degree;
  }
  const PolyMesh inverted =
      withReversedFaces(boxMesh(Box3(Vec3::Zero(), Vec3(1, 2, 3))), ElementId(0), -1);
  const RegionDgCheck c = check(inverted, allOf(inverted));
  EXPECT_FALSE(c.passed());
  EXPECT_NE(c.zeroModes, 6u);
  // Its rows reproduce the linear field (every integral changes sign alike), but its block of
  // the IP matrix is not positive definite: the patch test reports infinity.
  EXPECT_EQ(c.patchTestResidual, std::numeric_limits<double>::infinity());
}

TEST(RegionChecks, FailsOnAStaleMomentCache) {
  PolyMesh mesh = grid4();
  MomentCache moments(mesh, 2);
  moments.update();
  transform(mesh, 1.5, Vec3::Zero());  // valid, but the cache was not updated
  const RegionDgCheck c = regionDgChecks(mesh, moments, only(mesh, {cell(4, 1, 1, 1)}));
  EXPECT_GT(c.momentMismatch, 1e-3);
  EXPECT_FALSE(c.passed());
  moments.invalidateAll();
  moments.update();
  EXPECT_TRUE(regionDgChecks(mesh, moments, only(mesh, {cell(4, 1, 1, 1)})).passed());
}

TEST(RegionChecks, RejectsBadArguments) {
  const PolyMesh mesh = grid4();
  MomentCache moments(mesh, 2);
  moments.update();
  EXPECT_THROW(regionDgChecks(mesh, moments, Region(3, 1)), std::invalid_argument);
  LocalDgCheckOptions quadratic;
  quadratic.basis.degree = 2;
  EXPECT_THROW(regionDgChecks(mesh, moments, allOf(mesh), quadratic), std::invalid_argument);
  const RegionDgCheck empty = regionDgChecks(mesh, moments, Region(mesh.numElements(), 0));
  EXPECT_EQ(empty.elements, 0u);
  EXPECT_TRUE(empty.passed());
}

}  // namespace
}  // namespace polydg
