// The meshing pipeline (meshSurface): a closed surface is sliced while its self-intersection
// test runs, and the result is kept only if the test finds nothing; a self-intersecting closed
// surface is refused (or wrapped with RepairMode::Wrap), an inward one re-oriented, and the
// report holds the diagnosis and every phase either way. Surfaces whose lengths would overflow
// or underflow double precision downstream are refused as such, on both sides of the limits.
#include "polydg/mesh/meshing.h"

#include "polydg/mesh/geometry.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "mesh/surface_repair.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/identical_meshes.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

/// Volume kept by slicing: the exact polyhedral volume up to round-off (issue 3).
constexpr double kMeshingVolumeTolerance = 1e-10;

bool hasPhase(const MeshingReport& r, const std::string& phase) {
  return std::any_of(r.timings.begin(), r.timings.end(),
                     [&](const auto& t) { return t.first == phase; });
}

MeshingOptions cells(int n) {
  MeshingOptions o;
  o.cellsAlongLongest = n;
  return o;
}

TEST(Meshing, ClosedSurfaceReportsItsDiagnosisAndEveryPhase) {
  const TriangleSurface sphere = icosphere(Vec3(0.1, 0.2, -0.3), 1.0, 3);
  const MeshingResult m = meshSurface(sphere, cells(8));
  const MeshingReport& r = m.report;
  EXPECT_TRUE(r.geometry.passed);
  EXPECT_EQ(r.inputTriangles, sphere.triangles.size());
  EXPECT_EQ(r.inputVertices, sphere.vertices.size());
  EXPECT_TRUE(r.inputClosed);
  EXPECT_TRUE(r.inputManifold);
  EXPECT_TRUE(r.selfIntersectionsChecked);
  EXPECT_EQ(r.selfIntersections, 0u);
  EXPECT_EQ(r.shells, 1u);
  EXPECT_TRUE(r.repairs.empty());
  EXPECT_LT(r.volumeRelError, kMeshingVolumeTolerance);
  for (const char* phase : {"check", "orient", "slice", "merge_slivers", "validate"})
    EXPECT_TRUE(hasPhase(r, phase)) << phase;
  // The whole is at least as long as any phase inside it (phases may overlap).
  for (const auto& [phase, seconds] : r.timings) EXPECT_GE(r.seconds, seconds) << phase;
}

TEST(Meshing, SelfIntersectingClosedSurfaceIsRefusedOrWrapped) {
  // Two overlapping spheres: closed and manifold edge by edge, so they are sliced while the
  // self-intersection test runs; the test's verdict wins.
  const TriangleSurface overlapping =
      combine(icosphere(Vec3::Zero(), 1.0, 2), icosphere(Vec3(0.8, 0.0, 0.0), 1.0, 2));
  try {
    meshSurface(overlapping, cells(8));
    ADD_FAILURE() << "a self-intersecting surface was meshed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("self-intersecting ("), std::string::npos) << e.what();
  }
  MeshingOptions wrap = cells(8);
  wrap.repair = RepairMode::Wrap;
  const MeshingResult m = meshSurface(overlapping, wrap);
  EXPECT_TRUE(m.report.geometry.passed);
  EXPECT_GT(m.report.selfIntersections, 0u);
  ASSERT_FALSE(m.report.repairs.empty());
  EXPECT_NE(m.report.repairs[0].find("alpha-wrapped"), std::string::npos);
  EXPECT_LT(m.report.volumeRelError, kMeshingVolumeTolerance);
}

TEST(Meshing, InwardSurfaceIsReorientedAndKeepsItsVolume) {
  const TriangleSurface sphere = icosphere(Vec3(0.1, 0.2, -0.3), 1.0, 3);
  const MeshingResult outward = meshSurface(sphere, cells(8));
  const MeshingResult inward = meshSurface(reversedSurface(sphere), cells(8));
  EXPECT_TRUE(inward.report.geometry.passed);
  ASSERT_EQ(inward.report.repairs.size(), 1u);
  EXPECT_NE(inward.report.repairs[0].find("re-oriented"), std::string::npos);
  EXPECT_EQ(inward.report.elements, outward.report.elements);
  EXPECT_LT(std::abs(inward.report.outputVolume - outward.report.outputVolume) /
                outward.report.outputVolume,
            kMeshingVolumeTolerance);
}

// One consistently oriented shell takes the shortcut of orientToBoundVolume(): the sign of its
// volume. It must agree with CGAL's path, which two shells still take (and which reports the
// inner one as a cavity), also far from the origin, where the volume is a sum of large terms.
TEST(Meshing, OrientationByTheVolumeSignAgreesWithCgalsOrientation) {
  for (const Vec3& centre : {Vec3(0.1, 0.2, -0.3), Vec3(1e6, -2e6, 3e6)}) {
    const TriangleSurface sphere = icosphere(centre, 1.0, 3);
    for (bool flip : {false, true}) {
      const TriangleSurface input = flip ? reversedSurface(sphere) : sphere;
      bool changed = !flip;
      std::size_t shells = 0, cavities = 1;
      const TriangleSurface out = orientToBoundVolume(input, changed, &shells, &cavities);
      EXPECT_EQ(changed, flip);
      EXPECT_EQ(shells, 1u);
      EXPECT_EQ(cavities, 0u);
      EXPECT_GT(enclosedVolume(out), 0.0);
      EXPECT_EQ(out.triangles, sphere.triangles);
    }
    // Two shells, the inner one outward too: CGAL's path turns it inward, a cavity.
    TriangleSurface shell = sphere;
    const TriangleSurface inner = icosphere(centre, 0.5, 2);
    const auto offset = static_cast<std::uint32_t>(shell.vertices.size());
    shell.vertices.insert(shell.vertices.end(), inner.vertices.begin(), inner.vertices.end());
    for (auto t : inner.triangles)
      shell.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    bool changed = false;
    std::size_t shells = 0, cavities = 0;
    const TriangleSurface out = orientToBoundVolume(shell, changed, &shells, &cavities);
    EXPECT_TRUE(changed);
    EXPECT_EQ(shells, 2u);
    EXPECT_EQ(cavities, 1u);
    const double expected = 4.0 / 3.0 * M_PI * (1.0 - 0.125);
    EXPECT_NEAR(enclosedVolume(out), expected, 0.05 * expected);  // polyhedral spheres
  }
}

TEST(Meshing, GeometryChecksCanBeLeftToTheCaller) {
  const TriangleSurface sphere = icosphere(Vec3::Zero(), 1.0, 2);
  MeshingOptions later = cells(6);
  later.checkGeometry = false;
  MeshingResult m = meshSurface(sphere, later);
  EXPECT_FALSE(hasPhase(m.report, "validate"));
  EXPECT_EQ(m.report.elements, 0u);
  checkMeshing(m);
  EXPECT_TRUE(hasPhase(m.report, "validate"));
  EXPECT_TRUE(m.report.geometry.passed);
  EXPECT_EQ(m.report.elements, m.mesh.numElements());
  EXPECT_EQ(m.report.hexahedra + m.report.polyhedra, m.report.elements);
  EXPECT_LT(m.report.volumeRelError, kMeshingVolumeTolerance);
}

TEST(Meshing, WholeCellsAreHexahedraAndCountAsWhatTheShapesSay) {
  // The whole cells slicing and sliver merging left alone are flagged, so that validation
  // need not measure their shapes: each is a grid hexahedron, an element that took in a sliver
  // is not flagged, and the counts are those of measuring every element. The grid is the unit
  // cells of [0, 4]^3 (two small cubes in its corners make the bounds); the block's side at
  // x = 3.05 leaves slabs 0.05 thick beyond x = 3, slivers that merge into whole cells.
  TriangleSurface blocks = boxSurface(Box3(Vec3(0.5, 0.5, 0.5), Vec3(3.05, 3.5, 3.5)));
  blocks = combine(blocks, boxSurface(Box3(Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1))));
  blocks = combine(blocks, boxSurface(Box3(Vec3(3.9, 3.9, 3.9), Vec3(4, 4, 4))));
  MeshingOptions options;
  options.cellSize = 1.0;
  options.sliverTau = 0.1;
  const MeshingResult m = meshSurface(blocks, options);
  ASSERT_EQ(m.report.grid.cells, (std::array<int, 3>{4, 4, 4}));
  ASSERT_EQ(m.wholeCells.size(), m.mesh.numElements());
  std::size_t flagged = 0, notHexahedra = 0;
  for (std::size_t e = 0; e < m.mesh.numElements(); ++e)
    if (m.wholeCells[e]) {
      ++flagged;
      notHexahedra += !isGridHexahedron(m.mesh, ElementId(e));
    }
  EXPECT_GT(flagged, 0u);
  EXPECT_EQ(notHexahedra, 0u);
  EXPECT_GE(m.report.slivers.merged, 4u);
  MeshingReport measured;
  measured.inputVolume = m.report.inputVolume;
  checkMeshing(m.mesh, measured);
  EXPECT_EQ(m.report.hexahedra, measured.hexahedra);
  EXPECT_EQ(m.report.nonconvex, measured.nonconvex);
  EXPECT_GE(m.report.hexahedra, flagged);
  // The flagged cells' closure is taken from the flags, the rest is tested: the same verdict
  // and volume as testing every element.
  EXPECT_EQ(m.report.geometry.closedByConstruction, flagged);
  EXPECT_EQ(measured.geometry.closedByConstruction, 0u);
  EXPECT_TRUE(m.report.geometry.passed);
  EXPECT_EQ(m.report.geometry.passed, measured.geometry.passed);
  EXPECT_EQ(m.report.outputVolume, measured.outputVolume);
}

// --- scale: overflow and underflow ------------------------------------------------------------

/// The cube [0, side]^3; with `side` a power of two every coordinate and volume is exact.
TriangleSurface cube(double side) { return boxSurface(Box3(Vec3::Zero(), Vec3::Constant(side))); }

/// The one-line message of the InputError meshSurface throws, or "" if it meshes.
std::string refusal(const TriangleSurface& surface, const MeshingOptions& options) {
  try {
    meshSurface(surface, options);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  return "";
}

/// Meshes `surface` and checks the result: valid, with the volume `volume`, and element moments
/// up to degree 6 (what a degree-3 DG basis needs) finite, the largest of them normal.
void expectMeshesExactly(const TriangleSurface& surface, const MeshingOptions& options,
                         double volume, std::size_t elements) {
  const MeshingResult m = meshSurface(surface, options);
  EXPECT_TRUE(m.report.geometry.passed);
  EXPECT_EQ(m.report.elements, elements);
  EXPECT_LT(std::abs(m.report.outputVolume - volume) / volume, kMeshingVolumeTolerance)
      << m.report.outputVolume << " vs " << volume;
  MomentCache moments(m.mesh, 6);
  moments.update();
  for (std::size_t e = 0; e < m.mesh.numElements(); ++e) {
    double largest = 0.0;
    for (double value : moments.element(ElementId(e))) {
      ASSERT_TRUE(std::isfinite(value)) << "element " << e;
      largest = std::max(largest, std::abs(value));
    }
    EXPECT_GE(largest, std::numeric_limits<double>::min()) << "element " << e;
  }
}

TEST(MeshingScale, CubesJustInsideTheLimitsMeshWithTheirExactVolume) {
  // The largest extent, sliced into 8^3 cells of 2^97.
  expectMeshesExactly(cube(kLargestLength), cells(8), std::pow(kLargestLength, 3), 512);
  // The smallest cell, 2^-100, in a cube of 2^-97.
  const double small = 8 * kSmallestLength;
  expectMeshesExactly(cube(small), cells(8), std::pow(small, 3), 512);
  // The smallest extent: one cell.
  MeshingOptions one;
  one.cellSize = kSmallestLength;
  expectMeshesExactly(cube(kSmallestLength), one, std::pow(kSmallestLength, 3), 1);
  // And the scales the README promises work as at 1: 1e-6 and 1e6.
  for (double scale : {1e-6, 1e6}) {
    SCOPED_TRACE(scale);
    const TriangleSurface sphere =
        transformed(icosphere(Vec3::Zero(), 1.0, 3), scale, Vec3::Zero());
    expectMeshesExactly(sphere, cells(6), enclosedVolume(sphere),
                        meshSurface(icosphere(Vec3::Zero(), 1.0, 3), cells(6)).report.elements);
  }
}

TEST(MeshingScale, LargerSurfacesAreRefusedAsOverflowNamingTheLargestCoordinate) {
  // Just beyond 2^100, and near the largest double, which was refused as "encloses no volume"
  // (its volume, 1e924, is infinite in double).
  for (double side : {std::nextafter(kLargestLength, 2 * kLargestLength), 1e308}) {
    SCOPED_TRACE(side);
    const std::string why = refusal(cube(side), cells(8));
    EXPECT_EQ(
        why.rfind("the surface is too large for double precision: its bounding box spans ", 0), 0u)
        << why;
    EXPECT_NE(why.find("would overflow"), std::string::npos) << why;
    EXPECT_NE(why.find(side == 1e308 ? "(largest |coordinate| 1e+308)"
                                     : "(largest |coordinate| 1.27e+30)"),
              std::string::npos)
        << why;
    EXPECT_NE(why.find("; scale the model down"), std::string::npos) << why;
  }
}

TEST(MeshingScale, SmallerSurfacesAreRefusedAsUnderflow) {
  MeshingOptions one;
  one.cellSize = kSmallestLength;
  for (double side : {std::nextafter(kSmallestLength, 0.0), 1e-300}) {
    SCOPED_TRACE(side);
    const std::string why = refusal(cube(side), cells(8));
    EXPECT_EQ(
        why.rfind("the surface is too small for double precision: its bounding box spans ", 0), 0u)
        << why;
    EXPECT_NE(why.find("would underflow to zero"), std::string::npos) << why;
    EXPECT_NE(why.find(side == 1e-300 ? "(largest |coordinate| 1e-300)"
                                      : "(largest |coordinate| 7.89e-31)"),
              std::string::npos)
        << why;
    EXPECT_NE(why.find("; scale the model up"), std::string::npos) << why;
    EXPECT_EQ(refusal(cube(side), one), why);  // whatever the cell size
  }
}

TEST(MeshingScale, CellSizesOutsideTheLimitsAreRefused) {
  // 16 cells along 2^-97: cells of 2^-101.
  const std::string small = refusal(cube(8 * kSmallestLength), cells(16));
  EXPECT_EQ(small.rfind("the cell size 3.94e-31 is less than 7.89e-31 (2^-100)", 0), 0u) << small;
  EXPECT_NE(small.find("; use fewer cells, or scale the model up"), std::string::npos) << small;
  MeshingOptions huge;
  huge.cellSize = 2 * kLargestLength;
  const std::string large = refusal(cube(1.0), huge);
  EXPECT_EQ(large.rfind("the cell size 2.54e+30 is more than 1.27e+30 (2^100)", 0), 0u) << large;
}

TEST(MeshingScale, NonFiniteCoordinatesAreRefused) {
  TriangleSurface s = cube(1.0);
  s.vertices[3].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(refusal(s, cells(4)),
            "a vertex has a non-finite coordinate (NaN or infinity); fix the surface");
}

TEST(Meshing, SwissCheeseBlockMeshesToItsKnownVolume) {
  // 11 x 10 x 9 unit cells with 3 x 3 holes along each axis, crossing: integer vertices, so the
  // volume is the count of kept cells. 16 cells along x puts no grid plane on a cell side.
  const Box3 box(Vec3::Zero(), Vec3(11, 10, 9));
  const std::array<int, 3> n{11, 10, 9};
  const TriangleSurface cheese = swissCheeseBlock(box, n);
  const SurfaceTopology topology = analyzeTopology(cheese);
  EXPECT_TRUE(topology.closed());
  EXPECT_EQ(topology.components, 1u);
  EXPECT_EQ(topology.degenerateTriangles, 0u);
  // Inclusion-exclusion: the 9 + 9 + 9 hole rows remove 99 + 90 + 81 unit cells, each pair of
  // hole directions shares the 27 crossings, all three share them too.
  const double volume = 11 * 10 * 9 - (99 + 90 + 81) + 3 * 27 - 27;
  EXPECT_EQ(swissCheeseVolume(uniformCheeseWalls(box, n)), volume);
  EXPECT_LT(std::abs(enclosedVolume(cheese) - volume) / volume, kMeshingVolumeTolerance);

  const MeshingResult m = meshSurface(cheese, cells(16));
  const MeshingReport& r = m.report;
  EXPECT_TRUE(r.geometry.passed);
  EXPECT_TRUE(r.inputClosed);
  EXPECT_TRUE(r.inputManifold);
  EXPECT_TRUE(r.selfIntersectionsChecked);
  EXPECT_EQ(r.selfIntersections, 0u);
  EXPECT_EQ(r.shells, 1u);
  EXPECT_EQ(r.cavities, 0u);
  EXPECT_TRUE(r.repairs.empty());
  EXPECT_EQ(r.geometry.components, 1u);
  EXPECT_LT(std::abs(r.outputVolume - volume) / volume, kMeshingVolumeTolerance);
}

TEST(Meshing, SwissCheeseWithWallsJustOffTheGridPlanes) {
  // The walls a little beyond the grid planes (testing::cheeseWallsOffGrid): slivers of that
  // thickness between each wall and its plane, merged, and faces that thin between elements.
  const CheeseWalls walls = testing::cheeseWallsOffGrid(Box3(Vec3::Zero(), Vec3(11, 10, 9)), 16);
  const MeshingResult m = meshSurface(swissCheeseBlock(walls), cells(16));
  EXPECT_TRUE(m.report.geometry.passed);
  EXPECT_EQ(m.report.selfIntersections, 0u);
  EXPECT_GT(m.report.slivers.merged, 0u);
  const double volume = swissCheeseVolume(walls);
  EXPECT_LT(std::abs(m.report.inputVolume - volume) / volume, kMeshingVolumeTolerance);
  EXPECT_LT(std::abs(m.report.outputVolume - volume) / volume, kMeshingVolumeTolerance);
}

TEST(Meshing, TorusObjAtCellCountsPuttingAVertexOnOneGridPlaneAndNearAnother) {
  // At 14 cells (and multiples) a vertex of testdata/torus.obj lies on the grid plane
  // y = -0.6 and 1.1e-16 from x = 0: the points x = 0 makes on its edges round onto y = -0.6
  // (PlaneSplit.VertexOnOnePlaneAndWithinRoundOffOfAnother). Slicing once stopped there with
  // "traceLoops: open chain of edges".
  const TriangleSurface torus = readSurface(std::string(POLYDG_TESTDATA_DIR) + "/torus.obj");
  for (const int n : {14, 28}) {
    SCOPED_TRACE("cells " + std::to_string(n));
    const MeshingResult m = meshSurface(torus, cells(n));
    EXPECT_TRUE(m.report.geometry.passed);
    EXPECT_EQ(m.report.geometry.components, 1u);
    EXPECT_LT(std::abs(m.report.outputVolume - m.report.inputVolume) / m.report.inputVolume,
              kMeshingVolumeTolerance);
  }
}

TEST(Meshing, SameInputGivesTheSameMeshWhateverTheSchedule) {
  // Slicing runs in parallel, and the ids of the points it makes follow the schedule; the mesh
  // must not. One run on one thread, then runs on all threads: the same mesh in every detail.
  const TriangleSurface torus = readSurface(std::string(POLYDG_TESTDATA_DIR) + "/torus.obj");
  MeshingResult serial;
  {
    const tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
    serial = meshSurface(torus, cells(20));
  }
  for (int run = 0; run < 3; ++run) {
    SCOPED_TRACE("parallel run " + std::to_string(run));
    const MeshingResult parallel = meshSurface(torus, cells(20));
    testing::expectIdenticalMeshes(serial.mesh, parallel.mesh);
  }
}

}  // namespace
}  // namespace polydg
