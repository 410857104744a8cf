// Hexahedral slicing of generated shapes whose exact polyhedral volume is known: the elements
// fill the input's volume, every element is valid, and components come out right, also for
// faces on grid planes, thin plates, nearby shells, cavities, and far from the origin.
#include "polydg/mesh/slice.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <iomanip>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "mesh/slice_reference.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/merge_elements.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/identical_meshes.h"

namespace polydg {
namespace {

/// Slicing keeps the polyhedral volume to this relative accuracy.
constexpr double kVolumeTolerance = 1e-10;
/// The twisted parts' volume, to round-off: the sum of the element volumes against the
/// surface's enclosed volume, each a sum of some 10^4 to 10^5 rounded products, relative.
/// Measured at most 4e-14 at the origin and 2.6e-13 1e6 away (2026-12-04), a fourfold margin.
constexpr double kPartVolumeTolerance = 1e-12;

struct Sliced {
  PolyMesh mesh;
  SliceStats stats;
  std::vector<std::array<int, 3>> elementCell;
  GeometryCheck geometry;
  double volume = 0.0;
  std::size_t hexahedra = 0;
  std::vector<double> elementVolumes;
};

Sliced slice(const TriangleSurface& surface, const Grid& grid) {
  Sliced s;
  s.mesh = sliceSurface(surface, grid, &s.stats, &s.elementCell);
  s.geometry = checkGeometry(s.mesh);
  MomentCache moments(s.mesh, 0);
  moments.update();
  for (std::size_t e = 0; e < s.mesh.numElements(); ++e) {
    s.volume += moments.volume(ElementId(e));
    s.elementVolumes.push_back(moments.volume(ElementId(e)));
    const Element& element = s.mesh.element(ElementId(e));
    bool hex = element.faces.size() == 6;
    for (const FaceUse& use : element.faces)
      hex = hex && s.mesh.face(use.face).vertices.size() == 4 &&
            s.mesh.face(use.face).origin == FaceOrigin::Interior;
    s.hexahedra += hex;
  }
  return s;
}

void expectGood(const Sliced& s, double exactVolume, std::size_t components) {
  EXPECT_TRUE(s.geometry.passed);
  for (const std::string& m : s.geometry.messages) ADD_FAILURE() << m;
  EXPECT_NEAR(s.volume, exactVolume, kVolumeTolerance * std::abs(exactVolume));
  EXPECT_NEAR(s.geometry.volume, exactVolume, kVolumeTolerance * std::abs(exactVolume));
  EXPECT_EQ(s.geometry.components, components);
}

TEST(Slice, SphereFillsItsVolume) {
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.05), 1.0, 3);
  const Sliced s = slice(sphere, Grid::withCellsAlongLongest(bounds(sphere), 8));
  expectGood(s, enclosedVolume(sphere), 1);
  EXPECT_GT(s.hexahedra, 50u);  // the inside is hexahedra
  EXPECT_GT(s.mesh.numElements(), s.hexahedra + 100);
}

// Enough whole cells that their grid nodes are copied into the points in several parallel
// blocks (of 2^14): every block must land at its place for the boxes to keep their volume.
TEST(Slice, ManyWholeCellsFillTheirVolume) {
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.05), 1.0, 3);
  const Sliced s = slice(sphere, Grid::withCellsAlongLongest(bounds(sphere), 40));
  EXPECT_GT(s.stats.wholeCells, 20000u);
  expectGood(s, enclosedVolume(sphere), 1);
}

TEST(Slice, TorusIsOneComponentWithAHole) {
  const TriangleSurface t = torus(Vec3::Zero(), 1.0, 0.35, 48, 24);
  const Sliced s = slice(t, Grid::withCellsAlongLongest(bounds(t), 10));
  expectGood(s, enclosedVolume(t), 1);
}

TEST(Slice, ACellSideWithAHoleKeepsBothLoops) {
  // A torus whose hole (radius about 0.1) lies inside one cell's side on the grid plane z = 0:
  // that side is a square with a round hole, one face of two loops, whose corners are those of
  // both (welding keeps a polygon's corner count only as its last loop's end).
  const TriangleSurface t = torus(Vec3(0.5, 0.5, 0.05), 1.0, 0.9, 64, 32);
  const Sliced s = slice(t, Grid::covering(Box3(Vec3(-2, -2, -1), Vec3(3, 3, 1)), 1.0));
  expectGood(s, enclosedVolume(t), 1);
  std::size_t holed = 0;
  for (const Face& face : s.mesh.faces()) {
    if (face.numLoops() < 2) continue;
    ++holed;
    EXPECT_EQ(face.numLoops(), 2u);
    EXPECT_EQ(face.loopEnd[1], face.vertices.size());
    EXPECT_GE(face.loop(1).size(), 8u);  // the hole, a polygon of the torus's 64 segments
  }
  EXPECT_EQ(holed, 1u);
}

TEST(Slice, GridAlignedCubeGivesExactHexahedra) {
  // Faces on grid planes, corners on grid nodes, edges on grid lines.
  const TriangleSurface cube = boxSurface(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const Grid grid = Grid::covering(bounds(cube), 0.25);
  ASSERT_EQ(grid.origin(), Vec3::Zero());
  const Sliced s = slice(cube, grid);
  expectGood(s, 1.0, 1);
  EXPECT_EQ(s.mesh.numElements(), 64u);
  EXPECT_EQ(s.hexahedra, 8u);  // the 2 x 2 x 2 cells that touch no side
  for (double v : s.elementVolumes) EXPECT_NEAR(v, 1.0 / 64, 1e-16);
}

TEST(Slice, PlateThinnerThanOneCell) {
  const TriangleSurface plate = boxSurface(Box3(Vec3(0, 0, 0.4), Vec3(1, 1, 0.41)));
  const Grid grid = Grid::covering(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)), 0.25);
  const Sliced s = slice(plate, grid);
  expectGood(s, 0.01, 1);
  EXPECT_EQ(s.mesh.numElements(), 16u);
}

TEST(Slice, TwoSpheresInOneCellAreTwoElements) {
  const TriangleSurface two =
      combine(icosphere(Vec3(0.3, 0.5, 0.5), 0.15, 2), icosphere(Vec3(0.7, 0.5, 0.5), 0.15, 2));
  const Grid grid = Grid::covering(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)), 1.0);
  ASSERT_EQ(grid.cells, (std::array<int, 3>{1, 1, 1}));
  const Sliced s = slice(two, grid);
  expectGood(s, enclosedVolume(two), 2);
  EXPECT_EQ(s.mesh.numElements(), 2u);
  EXPECT_EQ(s.geometry.interiorFaces, 0u);
  // Finer: still two components, never coupled.
  const Sliced fine = slice(two, Grid::covering(bounds(two), 0.1));
  expectGood(fine, enclosedVolume(two), 2);
}

TEST(Slice, HollowSphereKeepsItsCavity) {
  const TriangleSurface hollow =
      combine(icosphere(Vec3::Zero(), 1.0, 3), reversedSurface(icosphere(Vec3::Zero(), 0.6, 2)));
  const Sliced s = slice(hollow, Grid::withCellsAlongLongest(bounds(hollow), 7));
  expectGood(s, enclosedVolume(hollow), 1);
  EXPECT_LT(enclosedVolume(hollow), enclosedVolume(icosphere(Vec3::Zero(), 1.0, 3)));
}

TEST(Slice, FarFromTheOriginAndAtSmallScale) {
  struct Case {
    double scale;
    Vec3 offset;
  };
  const TriangleSurface base =
      combine(icosphere(Vec3::Zero(), 1.0, 3), reversedSurface(icosphere(Vec3::Zero(), 0.5, 2)));
  for (const Case& c :
       {Case{1.0, Vec3(1e6, -1e6, 1e6)}, Case{1e-6, Vec3::Zero()}, Case{1e6, Vec3::Zero()}}) {
    const TriangleSurface moved = transformed(base, c.scale, c.offset);
    const Sliced s = slice(moved, Grid::withCellsAlongLongest(bounds(moved), 6));
    SCOPED_TRACE("scale " + std::to_string(c.scale) + " offset " + std::to_string(c.offset.x()));
    expectGood(s, enclosedVolume(moved), 1);
  }
}

TEST(Slice, TipOfRoundOffSizeBeyondAGridPlane) {
  // A tetrahedron whose corner lies on the grid plane y = -0.5 and pokes 1e-16 beyond x = 0:
  // the tip cut off by x = 0 rounds wholly into y = -0.5 (a closed piece lying in the plane),
  // and on the other side a face has an edge of round-off length along y = -0.5. The tip goes
  // whole to one side, and welding removes it.
  Grid grid;
  grid.cellSize = 0.25;
  grid.cells = {8, 8, 8};
  ASSERT_EQ(grid.plane(0, 4), 0.0);
  ASSERT_EQ(grid.plane(1, 2), -0.5);
  for (const double zSign : {1.0, -1.0})
    for (const double apexY : {-0.49, -0.51}) {
      SCOPED_TRACE("zSign " + std::to_string(zSign) + ", apexY " + std::to_string(apexY));
      TriangleSurface tet;
      tet.vertices = {Vec3(-1e-16, -0.5, 0.0), Vec3(0.06, -0.497, 0.0),
                      Vec3(0.06, -0.505, -0.08 * zSign), Vec3(0.05, apexY, 0.08 * zSign)};
      tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
      if (enclosedVolume(tet) < 0) tet = reversedSurface(tet);
      expectGood(slice(tet, grid), enclosedVolume(tet), 1);
    }
}

/// Every element is a piece of its cell: its corners lie in the cell's box, widened by the
/// resolution of the coordinates (welding moves points by at most 8 ulps of the largest).
void expectElementsInTheirCells(const Sliced& s, const Grid& grid) {
  ASSERT_EQ(s.elementCell.size(), s.mesh.numElements());
  double largest = 0.0;
  for (const Vec3& p : s.mesh.positions().raw())
    largest = std::max(largest, p.cwiseAbs().maxCoeff());
  const double resolution = 8.0 * std::numeric_limits<double>::epsilon() * largest;
  std::size_t outside = 0;
  for (std::size_t e = 0; e < s.mesh.numElements(); ++e) {
    const Box3 box = elementBounds(s.mesh, ElementId(e));
    for (int a = 0; a < 3; ++a)
      outside += box.min()[a] < grid.plane(a, s.elementCell[e][a]) - resolution ||
                 box.max()[a] > grid.plane(a, s.elementCell[e][a] + 1) + resolution;
  }
  EXPECT_EQ(outside, 0u);
}

TEST(Slice, TwistedPartsTaperedToAPoint) {
  // A CAD-like part (twistedTaperedPrism): a 20 x 10 rectangle extruded 40 high in 200 thin
  // slices, turning once and tapering to an apex. Many corners lie within round-off of grid
  // planes (the rectangle's sides at a quarter turn), grid planes pass through the apex and
  // along the slices, and the triangles at the apex are slivers. Alone, and beside three boxes
  // (four components); at the origin and 1e6 away.
  for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(1e6, 0, 0)})
    for (const bool boxes : {false, true}) {
      TriangleSurface part = twistedTaperedPrism(offset, 20, 10, 40, 200, 1.0);
      if (boxes) {
        part = combine(part, boxSurface(Box3(offset + Vec3(20, -5, 0), offset + Vec3(30, 5, 10))));
        part =
            combine(part, boxSurface(Box3(offset + Vec3(-30, -5, 0), offset + Vec3(-20, 5, 20))));
        part = combine(part, boxSurface(Box3(offset + Vec3(-5, 20, 0), offset + Vec3(5, 30, 5))));
      }
      const double exact = enclosedVolume(part);
      for (const int cells : {16, 32, 48, 58, 64}) {
        const std::string name = std::string(boxes ? "twist and boxes" : "twist") +
                                 (offset.x() == 0 ? " at the origin, " : " 1e6 away, ") +
                                 std::to_string(cells) + " cells";
        SCOPED_TRACE(name);
        const Grid grid = Grid::withCellsAlongLongest(bounds(part), cells);
        const Sliced s = slice(part, grid);
        expectGood(s, exact, boxes ? 4 : 1);
        expectElementsInTheirCells(s, grid);
        // Each piece of a cell stays its own element: the two sides of a sliver that rounding
        // puts on one polygon cancel in their cell (at 58 cells), no element is merged.
        EXPECT_EQ(s.stats.mergedElements, 0u);
        EXPECT_NEAR(s.volume, exact, kPartVolumeTolerance * exact);
        EXPECT_NEAR(s.geometry.volume, exact, kPartVolumeTolerance * exact);
        std::cout << name << ": " << s.mesh.numElements() << " elements, volume "
                  << std::setprecision(17) << s.volume << " (enclosed " << exact
                  << ", relative difference " << std::setprecision(2)
                  << std::abs(s.volume - exact) / exact << ")\n";
      }
    }
}

TEST(Slice, ManyThinTwistedSlices) {
  // The part in 1000 slices 0.04 thick, turning three times: ring edges lie within round-off
  // of grid lines, and the slivers beside them round flat. Faces rounding leaves flat are
  // dissolved and flat elements merged (the stats count them), and the mesh stays valid with
  // its volume.
  const TriangleSurface part = twistedTaperedPrism(Vec3::Zero(), 20, 10, 40, 1000, 3.0);
  const double exact = enclosedVolume(part);
  std::size_t repairs = 0;
  for (const int cells : {8, 16, 24}) {
    SCOPED_TRACE(std::to_string(cells) + " cells");
    const Sliced s = slice(part, Grid::withCellsAlongLongest(bounds(part), cells));
    expectGood(s, exact, 1);
    EXPECT_NEAR(s.volume, exact, kPartVolumeTolerance * exact);
    repairs += s.stats.flatFaces + s.stats.mergedElements;
    std::cout << cells << " cells: " << s.mesh.numElements() << " elements, " << s.stats.flatFaces
              << " flat faces dissolved, " << s.stats.mergedElements << " merges, volume "
              << std::setprecision(17) << s.volume << " (enclosed " << exact << ")\n";
  }
  EXPECT_GT(repairs, 0u);  // what rounding flattens was there to repair
}

/// A mesh's elements in order, each as its faces as it uses them (outward): each loop the
/// cycle of its corners' positions from the smallest, the holes sorted, the faces sorted. Two
/// meshes with the same elements, faces and orientations give the same list, whatever the
/// order of an element's faces and the first corner of each loop.
using CanonicalLoop = std::vector<std::array<double, 3>>;
using CanonicalFace = std::vector<CanonicalLoop>;
std::vector<std::vector<CanonicalFace>> canonicalElements(const PolyMesh& mesh) {
  std::vector<std::vector<CanonicalFace>> elements;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    std::vector<CanonicalFace> faces;
    for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
      const Face& f = mesh.face(use.face);
      CanonicalFace face;
      for (std::size_t k = 0; k < f.numLoops(); ++k) {
        CanonicalLoop loop;
        for (VertexId v : f.loop(k)) {
          const Vec3& p = mesh.position(v);
          loop.push_back({p.x(), p.y(), p.z()});
        }
        if (use.reversed) std::reverse(loop.begin(), loop.end());
        std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
        face.push_back(std::move(loop));
      }
      std::sort(face.begin() + 1, face.end());
      faces.push_back(std::move(face));
    }
    std::sort(faces.begin(), faces.end());
    elements.push_back(std::move(faces));
  }
  return elements;
}

/// The octahedron with corners centre +- d[k], outward.
TriangleSurface octahedron(const Vec3& centre, const std::array<Vec3, 3>& d) {
  TriangleSurface s;
  for (const Vec3& v : d) {
    s.vertices.push_back(centre + v);
    s.vertices.push_back(centre - v);
  }
  for (std::uint32_t a = 0; a < 2; ++a)
    for (std::uint32_t b = 2; b < 4; ++b)
      for (std::uint32_t c = 4; c < 6; ++c) {
        const Vec3 n = (s.vertices[b] - s.vertices[a]).cross(s.vertices[c] - s.vertices[a]);
        if (n.dot(s.vertices[a] + s.vertices[b] + s.vertices[c] - 3 * centre) > 0)
          s.triangles.push_back({a, b, c});
        else
          s.triangles.push_back({a, c, b});
      }
  return s;
}

/// testdata/torus.obj.
TriangleSurface bundledTorus() {
  return readSurface(std::string(POLYDG_TESTDATA_DIR) + "/torus.obj");
}

/// Twisted parts tapered to a point beside a box, 1e6 from the origin.
TriangleSurface twistBesideABoxFarAway() {
  return transformed(combine(twistedTaperedPrism(Vec3::Zero(), 20, 10, 40, 200, 1.0),
                             boxSurface(Box3(Vec3(20, -5, 0), Vec3(30, 5, 10)))),
                     1.0, Vec3(1e6, 0, 0));
}

TEST(Slice, VerticesAreNumberedInOrderOfFirstUse) {
  // Vertex ids follow the order in which the elements (in order, face by face, corner by
  // corner) first use them, whichever thread made which point: the torus at two sizes, and
  // twisted parts beside a box 1e6 from the origin.
  const TriangleSurface torus = bundledTorus(), parts = twistBesideABoxFarAway();
  for (const auto& [surface, cells] :
       {std::pair{&torus, 14}, std::pair{&torus, 40}, std::pair{&parts, 48}}) {
    SCOPED_TRACE(cells);
    const PolyMesh mesh =
        sliceSurface(*surface, Grid::withCellsAlongLongest(bounds(*surface), cells));
    ASSERT_GT(mesh.numElements(), 500u);
    std::uint32_t next = 0;
    std::size_t outOfOrder = 0;
    for (const Element& element : mesh.elements())
      for (const FaceUse& use : element.faces)
        for (const VertexId v : mesh.face(use.face).vertices) {
          if (v.value == next)
            ++next;
          else if (v.value > next)
            ++outOfOrder;
        }
    EXPECT_EQ(outOfOrder, 0u);
    EXPECT_EQ(next, mesh.numVertices());
  }
}

TEST(Slice, WholeCellFlagsMarkExactGridBoxesAndMergeSliversAlike) {
  // sliceSurface flags the whole cells rounding left alone: each is its cell's box, on the
  // grid's exact node coordinates, six quadrilaterals; merging slivers with the flags (whole
  // cells measured only when a sliver joins them) gives what merging without them gives.
  const TriangleSurface torus = bundledTorus(), parts = twistBesideABoxFarAway();
  const TriangleSurface sphere = icosphere(Vec3(0.1, 0.2, 0.3), 1.0, 3);
  // A box whose side lies one ulp before the grid plane x = 0.25: the slab of that ulp welds
  // onto the plane, moving corners of whole cells beside it, which are then no whole cells.
  const TriangleSurface ulpBeyond =
      boxSurface(Box3(Vec3(std::nextafter(0.25, 0.0), 0.1, 0.1), Vec3(1.1, 1.2, 1.2)));
  Grid quarters;
  quarters.centre = Vec3(0.75, 0.75, 0.75);
  quarters.cellSize = 0.25;
  quarters.cells = {6, 6, 6};
  for (const auto& [surface, cells] : {std::pair{&torus, 24}, std::pair{&parts, 48},
                                       std::pair{&sphere, 20}, std::pair{&ulpBeyond, 0}}) {
    SCOPED_TRACE(cells);
    const Grid grid = cells == 0 ? quarters : Grid::withCellsAlongLongest(bounds(*surface), cells);
    SliceStats stats;
    std::vector<std::array<int, 3>> cell;
    std::vector<char> whole;
    const PolyMesh mesh = sliceSurface(*surface, grid, &stats, &cell, {}, &whole);
    ASSERT_EQ(whole.size(), mesh.numElements());
    std::size_t flagged = 0, notBoxes = 0;
    for (std::size_t e = 0; e < mesh.numElements(); ++e) {
      if (!whole[e]) continue;
      ++flagged;
      const Element& element = mesh.element(ElementId(e));
      bool box = element.faces.size() == 6 && isGridHexahedron(mesh, ElementId(e));
      for (const FaceUse& use : element.faces)
        for (const VertexId v : mesh.face(use.face).vertices)
          for (int a = 0; a < 3; ++a) {
            const double x = mesh.position(v)[a];
            box = box && (x == grid.plane(a, cell[e][a]) || x == grid.plane(a, cell[e][a] + 1));
          }
      box = box && elementVertices(mesh, ElementId(e)).size() == 8;
      notBoxes += !box;
    }
    EXPECT_EQ(notBoxes, 0u);
    EXPECT_GT(flagged, 0u);
    EXPECT_LE(flagged, stats.wholeCells);

    const double threshold = 0.2 * grid.cellVolume();
    SliverMergeReport plain, flags;
    const PolyMesh a = mergeSlivers(mesh, threshold, &plain);
    const PolyMesh b = mergeSlivers(mesh, threshold, &flags, whole);
    if (cells != 0) {  // the box has none
      EXPECT_GT(plain.merged, 0u);
    }
    EXPECT_EQ(flags.slivers, plain.slivers);
    EXPECT_EQ(flags.merged, plain.merged);
    EXPECT_EQ(flags.isolated, plain.isolated);
    EXPECT_EQ(flags.group, plain.group);
    testing::expectIdenticalMeshes(a, b);
  }
}

TEST(Slice, WholeCellsMadeFromTheGridAreThoseSplittingGives) {
  // Boxes of cells the surface does not enter are made from the grid instead of being split
  // cell by cell; the mesh must be the one splitting gives, element by element and face by
  // face. The cases put surfaces on grid planes, within round-off of them (whose slivers
  // welding collapses next to whole cells), through many holes, and 1e6 from the origin.
  struct Case {
    std::string name;
    TriangleSurface surface;
    int cells;
  };
  const TriangleSurface torus = readSurface(std::string(POLYDG_TESTDATA_DIR) + "/torus.obj");
  TriangleSurface parts = twistedTaperedPrism(Vec3::Zero(), 20, 10, 40, 200, 1.0);
  parts = combine(parts, boxSurface(Box3(Vec3(20, -5, 0), Vec3(30, 5, 10))));
  parts = combine(parts, boxSurface(Box3(Vec3(-30, -5, 0), Vec3(-20, 5, 20))));
  parts = combine(parts, boxSurface(Box3(Vec3(-5, 20, 0), Vec3(5, 30, 5))));
  const std::vector<Case> cases = {
      {"torus.obj at 14 cells", torus, 14},
      {"torus.obj at 24 cells", torus, 24},
      {"twist and boxes at 58 cells", parts, 58},
      {"twist and boxes 1e6 away at 48 cells", transformed(parts, 1.0, Vec3(1e6, 0, 0)), 48},
      {"grid-aligned box", boxSurface(Box3(Vec3(0, 0, 0), Vec3(4, 3, 2))), 8},
      {"sphere", icosphere(Vec3(0.1, 0.2, 0.3), 1.0, 3), 20},
      {"holed block", swissCheeseBlock(Box3(Vec3(0, 0, 0), Vec3(9, 9, 9)), {9, 9, 9}), 18},
      // A cavity whose corner (2, 2, 2.5) lies on the grid line x = 2, y = 2, the cavity on
      // its y < 2 side: the cells beyond y = 2 are whole, but a side of theirs has that corner
      // on its edge, so they are split, not made from the grid.
      {"cavity touching a grid line",
       combine(boxSurface(Box3(Vec3(0, 0, 0), Vec3(4, 4, 4))),
               reversedSurface(octahedron(
                   Vec3(2, 1.5, 2.5), {Vec3(0, 0.5, 0), Vec3(0.375, 0, 0), Vec3(0, 0, 0.375)}))),
       8},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Grid grid = Grid::withCellsAlongLongest(bounds(c.surface), c.cells);
    SliceStats shortcut, reference;
    const PolyMesh fast = sliceSurface(c.surface, grid, &shortcut);
    const PolyMesh split = sliceSurfaceSplittingEveryCell(c.surface, grid, &reference);
    EXPECT_GT(shortcut.wholeCells, 0u);
    EXPECT_EQ(reference.wholeCells, 0u);
    EXPECT_LE(shortcut.splits, reference.splits);
    EXPECT_EQ(shortcut.leafCells, reference.leafCells);
    EXPECT_EQ(shortcut.weldedPoints, reference.weldedPoints);
    EXPECT_EQ(shortcut.mergedElements, reference.mergedElements);
    EXPECT_EQ(fast.numVertices(), split.numVertices());
    EXPECT_EQ(fast.numFaces(), split.numFaces());
    ASSERT_EQ(fast.numElements(), split.numElements());
    const auto a = canonicalElements(fast), b = canonicalElements(split);
    std::size_t differing = 0;
    for (std::size_t e = 0; e < a.size(); ++e) differing += a[e] != b[e];
    EXPECT_EQ(differing, 0u);
    EXPECT_TRUE(checkGeometry(fast).passed);
  }
}

}  // namespace
}  // namespace polydg
