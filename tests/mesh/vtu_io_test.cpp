// Tests of mesh/vtu_io.h (VTU writing and reading, field data) and mesh/face_triangulation.h.
//
// Two groups only run when ctest sets an environment variable (they skip otherwise):
//   POLYDG_VTK_FILES=DIR/vtk_cells.vtu: files written by VTK itself (tests/mesh/vtk_check.py
//     --write-vtk), read back with known exact volumes and field data;
//   POLYDG_VTU_OUT_DIR=DIR: writes polydg files into DIR for vtk_check.py to open with VTK and
//     meshio (volumes, regions, field data).
#include "polydg/mesh/vtu_io.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <gtest/gtest.h>

#include "mesh/face_triangulation.h"
#include "mesh/primitives.h"
#include "mesh/vtu_layout.h"
#include "polydg/mesh/geometry.h"
#include "tests/support/vtu_encodings.h"
#include "tests/support/vtu_meshes.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;

/// Relative tolerance for volumes and areas computed in different ways from the same numbers.
constexpr double kRelativeTolerance = 1e-12;

/// A fresh, empty directory for the current test.
fs::path testDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(info->test_suite_name()) + "_" + info->name();
  std::replace(name.begin(), name.end(), '/', '_');
  const fs::path dir = fs::path(::testing::TempDir()) / "polydg_vtu_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Removes the <FieldData> section (polydg's own arrays) from the file at `path`, as a file
/// written by another program would lack it. False if the file has none.
bool dropFieldData(const fs::path& path) {
  std::string text = readText(path);
  const auto begin = text.find("<FieldData>");
  const auto end = text.find("</FieldData>");
  if (begin == std::string::npos || end == std::string::npos) return false;
  text.erase(begin, end + std::string("</FieldData>").size() - begin);
  writeText(path, text);
  return true;
}

/// The message of the std::runtime_error that `f` throws ("" if it throws nothing).
template <class F>
std::string errorMessage(F&& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// --- meshes --------------------------------------------------------------------------------

using testing::cutAcross;
using testing::cutBoxes;
using testing::faceBetween;
using testing::finitelyCutGrid;
using testing::holedPrism;
using testing::kUArea;
using testing::mixedCells;
using testing::skewGrid;
using testing::uWithHoles;

// --- comparisons ---------------------------------------------------------------------------

/// True if `b` is the cycle `a`, possibly starting elsewhere.
bool sameCycle(std::span<const VertexId> a, std::span<const VertexId> b) {
  if (a.size() != b.size() || a.empty()) return a.size() == b.size();
  const auto start = std::find(b.begin(), b.end(), a[0]);
  if (start == b.end()) return false;
  const std::size_t s = static_cast<std::size_t>(start - b.begin());
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i] != b[(s + i) % b.size()]) return false;
  return true;
}

/// Same vertices (bitwise), faces (outer loop as a cycle, holes as cycles in any order, as in
/// isReverseOf), sides, origins, element face uses, and signed volumes.
void expectSameMesh(const PolyMesh& expected, const PolyMesh& actual) {
  ASSERT_EQ(expected.numVertices(), actual.numVertices());
  ASSERT_EQ(expected.numFaces(), actual.numFaces());
  ASSERT_EQ(expected.numElements(), actual.numElements());
  for (std::size_t v = 0; v < expected.numVertices(); ++v)
    EXPECT_EQ(expected.position(VertexId(v)), actual.position(VertexId(v))) << "vertex " << v;
  for (std::size_t i = 0; i < expected.numFaces(); ++i) {
    const Face& a = expected.face(FaceId(i));
    const Face& b = actual.face(FaceId(i));
    EXPECT_EQ(toString(a.origin), toString(b.origin)) << "face " << i;
    EXPECT_EQ(a.front, b.front) << "face " << i;
    EXPECT_EQ(a.back, b.back) << "face " << i;
    ASSERT_EQ(a.numLoops(), b.numLoops()) << "face " << i;
    EXPECT_TRUE(sameCycle(a.loop(0), b.loop(0))) << "outer loop of face " << i;
    std::vector<bool> matched(b.numLoops(), false);
    for (std::size_t k = 1; k < a.numLoops(); ++k) {
      bool found = false;
      for (std::size_t j = 1; j < b.numLoops() && !found; ++j)
        if (!matched[j] && sameCycle(a.loop(k), b.loop(j))) matched[j] = found = true;
      EXPECT_TRUE(found) << "hole " << k << " of face " << i;
    }
  }
  for (std::size_t i = 0; i < expected.numElements(); ++i) {
    const ElementId e(i);
    const auto& a = expected.element(e).faces;
    const auto& b = actual.element(e).faces;
    ASSERT_EQ(a.size(), b.size()) << "element " << i;
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].face, b[k].face) << "element " << i << " use " << k;
      EXPECT_EQ(a[k].reversed, b[k].reversed) << "element " << i << " use " << k;
    }
    const double va = signedVolume(expected, e);
    EXPECT_NEAR(va, signedVolume(actual, e), kRelativeTolerance * std::abs(va)) << "element " << i;
  }
}

/// The NumberOfPoints of the file's Piece.
std::size_t pointsInFile(const fs::path& path) {
  const std::string text = readText(path);
  const std::string key = "NumberOfPoints=\"";
  const auto at = text.find(key);
  if (at == std::string::npos) return 0;
  return std::stoul(text.substr(at + key.size()));
}

std::size_t countInteriorFaces(const PolyMesh& mesh) {
  return static_cast<std::size_t>(std::count_if(mesh.faces().begin(), mesh.faces().end(),
                                                [](const Face& f) { return !f.isBoundary(); }));
}

// --- face triangulation --------------------------------------------------------------------

/// Checks that `triangles` tile face `f`: total area equals the face's, each triangle is
/// oriented like the face, and each loop edge is an edge of exactly one triangle, in the loop's
/// direction (so the element stays closed).
void expectTilesFace(const PolyMesh& mesh, FaceId f,
                     const std::vector<std::array<VertexId, 3>>& triangles) {
  const Vec3 faceArea = areaVector(mesh, f);
  double sum = 0.0;
  std::map<std::pair<VertexId, VertexId>, int> edges;
  for (const auto& t : triangles) {
    const Vec3 a = 0.5 * (mesh.position(t[1]) - mesh.position(t[0]))
                             .cross(mesh.position(t[2]) - mesh.position(t[0]));
    EXPECT_GT(a.dot(faceArea), 0.0) << "triangle oriented against the face";
    EXPECT_NEAR(a.cross(faceArea).norm(), 0.0, kRelativeTolerance * faceArea.squaredNorm());
    sum += a.norm();
    for (int i = 0; i < 3; ++i) ++edges[{t[i], t[(i + 1) % 3]}];
  }
  EXPECT_NEAR(sum, faceArea.norm(), kRelativeTolerance * faceArea.norm());
  const Face& face = mesh.face(f);
  for (std::size_t k = 0; k < face.numLoops(); ++k) {
    const auto loop = face.loop(k);
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const auto edge = std::make_pair(loop[i], loop[(i + 1) % loop.size()]);
      EXPECT_EQ(edges[edge], 1) << "loop " << k << " edge " << i;
    }
  }
}

TEST(FaceTriangulation, SquareWithSquareHoleGivesEightTriangles) {
  PolyMesh mesh;
  Loop outer, hole;
  for (const Vec2& p : std::vector<Vec2>{{0, 0}, {4, 0}, {4, 4}, {0, 4}})
    outer.push_back(mesh.addVertex(Vec3(p.x(), p.y(), 1.0)));
  for (const Vec2& p : std::vector<Vec2>{{1, 1}, {1, 3}, {3, 3}, {3, 1}})  // clockwise
    hole.push_back(mesh.addVertex(Vec3(p.x(), p.y(), 1.0)));
  const FaceId f = mesh.addFace({outer, hole}, FaceOrigin::Box);
  const auto triangles = triangulateFace(mesh, f);
  EXPECT_EQ(triangles.size(), 8u);
  EXPECT_DOUBLE_EQ(areaVector(mesh, f).norm(), 12.0);
  expectTilesFace(mesh, f, triangles);
}

TEST(FaceTriangulation, TiltedFaceFacingNegativeAxis) {
  // The square-with-hole face, turned so that its normal is mostly -x; orientation must survive
  // the projection that drops x.
  PolyMesh mesh;
  auto place = [&](double u, double v) { return mesh.addVertex(Vec3(0.3 * v - 2.0, v, u)); };
  Loop outer, hole;
  for (const Vec2& p : std::vector<Vec2>{{0, 0}, {4, 0}, {4, 4}, {0, 4}})
    outer.push_back(place(p.x(), p.y()));
  for (const Vec2& p : std::vector<Vec2>{{1, 1}, {1, 3}, {3, 3}, {3, 1}})
    hole.push_back(place(p.x(), p.y()));
  const FaceId f = mesh.addFace({outer, hole}, FaceOrigin::Box);
  ASSERT_LT(areaVector(mesh, f).x(), 0.0);
  const auto triangles = triangulateFace(mesh, f);
  EXPECT_EQ(triangles.size(), 8u);
  expectTilesFace(mesh, f, triangles);
}

TEST(FaceTriangulation, PrismCapsWithHolesAreTiled) {
  const PolyMesh mesh = holedPrism();
  int capped = 0;
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const FaceId f(i);
    const Face& face = mesh.face(f);
    if (face.numLoops() == 1) continue;
    ++capped;
    const auto triangles = triangulateFace(mesh, f);
    // n vertices in all and h holes give n + 2h - 2 triangles.
    EXPECT_EQ(triangles.size(), face.vertices.size() + 2 * (face.numLoops() - 1) - 2);
    EXPECT_NEAR(areaVector(mesh, f).norm(), kUArea, kRelativeTolerance * kUArea);
    expectTilesFace(mesh, f, triangles);
  }
  EXPECT_EQ(capped, 2);
}

TEST(FaceTriangulation, CrossingLoopsThrow) {
  PolyMesh mesh;
  Loop outer, hole;
  for (const Vec2& p : std::vector<Vec2>{{0, 0}, {4, 0}, {4, 4}, {0, 4}})
    outer.push_back(mesh.addVertex(Vec3(p.x(), p.y(), 0.0)));
  for (const Vec2& p : std::vector<Vec2>{{1, 1}, {1, 5}, {3, 5}, {3, 1}})  // sticks out
    hole.push_back(mesh.addVertex(Vec3(p.x(), p.y(), 0.0)));
  const FaceId f = mesh.addFace({outer, hole}, FaceOrigin::Box);
  EXPECT_THROW(triangulateFace(mesh, f), std::runtime_error);
}

// --- round trips ---------------------------------------------------------------------------

struct RoundTripCase {
  std::string name;
  PolyMesh (*make)();
  VtuEncoding encoding;
};

void PrintTo(const RoundTripCase& c, std::ostream* os) { *os << c.name; }

class VtuRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(VtuRoundTrip, RestoresTheMeshExactly) {
  const PolyMesh mesh = GetParam().make();
  const fs::path path = testDir() / "mesh.vtu";
  writeVtu(mesh, path.string(), {.encoding = GetParam().encoding});
  expectSameMesh(mesh, readVtu(path.string()));
}

TEST_P(VtuRoundTrip, WithoutPolydgFieldDataSharesFacesByMatching) {
  // Strip the field data: faces are then matched between cells; simple faces come back
  // the same, faces with holes as their triangles, and every boundary face is Imported.
  const PolyMesh mesh = GetParam().make();
  const fs::path path = testDir() / "mesh.vtu";
  writeVtu(mesh, path.string(), {.encoding = GetParam().encoding});
  ASSERT_TRUE(dropFieldData(path));

  const PolyMesh read = readVtu(path.string());
  ASSERT_EQ(read.numElements(), mesh.numElements());
  EXPECT_EQ(countInteriorFaces(read), countInteriorFaces(mesh));
  double total = 0.0, expectedTotal = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    total += signedVolume(read, ElementId(e));
    expectedTotal += signedVolume(mesh, ElementId(e));
  }
  EXPECT_NEAR(total, expectedTotal, kRelativeTolerance * expectedTotal);
  for (const Face& f : read.faces()) {
    EXPECT_EQ(f.numLoops(), 1u);
    if (f.isBoundary()) {
      EXPECT_EQ(toString(f.origin), "imported");
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Meshes, VtuRoundTrip,
    ::testing::Values(RoundTripCase{"HexGridAscii", skewGrid, VtuEncoding::Ascii},
                      RoundTripCase{"HexGridBinary", skewGrid, VtuEncoding::Binary},
                      RoundTripCase{"HoledPrismAscii", holedPrism, VtuEncoding::Ascii},
                      RoundTripCase{"HoledPrismBinary", holedPrism, VtuEncoding::Binary},
                      RoundTripCase{"MixedCellsAscii", mixedCells, VtuEncoding::Ascii},
                      RoundTripCase{"MixedCellsBinary", mixedCells, VtuEncoding::Binary},
                      RoundTripCase{"HexGridAppended", skewGrid, VtuEncoding::Appended},
                      RoundTripCase{"HoledPrismAppended", holedPrism, VtuEncoding::Appended},
                      RoundTripCase{"MixedCellsAppended", mixedCells, VtuEncoding::Appended},
                      RoundTripCase{"CutBoxesAppended", cutBoxes, VtuEncoding::Appended},
                      RoundTripCase{"CutBoxesAscii", cutBoxes, VtuEncoding::Ascii},
                      RoundTripCase{"FinitelyCutGridBinary", finitelyCutGrid, VtuEncoding::Binary}),
    [](const auto& info) { return info.param.name; });

TEST(VtuRoundTrip, InteriorFaceWhoseFrontIsTheLaterElement) {
  // Faces are added first and used with the later element in front, which the reader can
  // only restore from polydg_face_reversed.
  PolyMesh mesh = hexGridMesh(2, 1, 1, Box3(Vec3(0, 0, 0), Vec3(2, 1, 1)));
  PolyMesh swapped;
  for (const Vec3& p : mesh.positions()) swapped.addVertex(p);
  for (const Face& f : mesh.faces()) {
    std::vector<Loop> loops;
    for (std::size_t k = 0; k < f.numLoops(); ++k)
      loops.emplace_back(f.loop(k).begin(), f.loop(k).end());
    swapped.addFace(loops, f.origin);
  }
  for (std::size_t e = mesh.numElements(); e-- > 0;)
    swapped.addElementFromFaces(mesh.element(ElementId(e)).faces);
  ASSERT_EQ(countInteriorFaces(swapped), 1u);
  const fs::path path = testDir() / "swapped.vtu";
  writeVtu(swapped, path.string());
  expectSameMesh(swapped, readVtu(path.string()));
}

// --- cuts: the two sides of a Cut face have their own points ------------------------------

TEST(VtuCut, TheTwoSidesOfACutGetTheirOwnPoints) {
  const PolyMesh mesh = cutBoxes();
  ASSERT_EQ(mesh.numVertices(), 12u);
  ASSERT_EQ(countInteriorFaces(mesh), 0u);
  const fs::path path = testDir() / "cut.vtu";
  writeVtu(mesh, path.string());
  // The four vertices of the cut polygon are written once per side.
  EXPECT_EQ(pointsInFile(path), 16u);
  const PolyMesh read = readVtu(path.string());
  expectSameMesh(mesh, read);
  std::size_t cutFaces = 0;
  for (const Face& f : read.faces()) cutFaces += f.origin == FaceOrigin::Cut;
  EXPECT_EQ(cutFaces, 2u);
}

TEST(VtuCut, AFiniteCutSharesPointsOnlyAlongItsFront) {
  const PolyMesh mesh = finitelyCutGrid();
  ASSERT_EQ(mesh.numVertices(), 18u);
  const fs::path path = testDir() / "finite_cut.vtu";
  writeVtu(mesh, path.string());
  // Of the cut's four corners, the two on its front (x = 1, y = 1) stay shared by all four
  // elements; the two at y = 0 touch only the two sides of the cut and are split.
  EXPECT_EQ(pointsInFile(path), 20u);
  expectSameMesh(mesh, readVtu(path.string()));
}

/// The values of an ascii DataArray named `name` in `text`.
std::vector<double> asciiValues(const std::string& text, const std::string& name) {
  const std::size_t at = text.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const std::size_t first = text.find('>', at) + 1, last = text.find("</DataArray>", first);
  std::istringstream in(text.substr(first, last - first));
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

TEST(VtuWrite, WritesTheVolumesItIsGiven) {
  // Cells of different point counts, so that the file's cell order is not the elements'.
  const PolyMesh mesh = mixedCells();
  const fs::path path = testDir() / "given_volumes.vtu";
  std::vector<double> given(mesh.numElements());
  for (std::size_t e = 0; e < given.size(); ++e) given[e] = 0.25 + static_cast<double>(e);
  writeVtu(mesh, path.string(), {.encoding = VtuEncoding::Ascii}, {}, {}, {}, {}, given);
  std::string text = readText(path);
  const std::vector<double> cellElement = asciiValues(text, "polydg_element");
  std::vector<double> written = asciiValues(text, "volume");
  ASSERT_EQ(cellElement.size(), mesh.numElements());
  ASSERT_EQ(written.size(), mesh.numElements());
  bool reordered = false;
  for (std::size_t c = 0; c < written.size(); ++c) {
    const auto e = static_cast<std::size_t>(cellElement[c]);
    EXPECT_EQ(written[c], given[e]) << "cell " << c;
    reordered = reordered || e != c;
  }
  EXPECT_TRUE(reordered);
  // Without them, the writer computes signedVolumes().
  writeVtu(mesh, path.string(), {.encoding = VtuEncoding::Ascii});
  text = readText(path);
  written = asciiValues(text, "volume");
  const std::vector<double> computed = signedVolumes(mesh);
  ASSERT_EQ(written.size(), mesh.numElements());
  for (std::size_t c = 0; c < written.size(); ++c)
    EXPECT_DOUBLE_EQ(written[c], computed[static_cast<std::size_t>(cellElement[c])]);
  // Not one per element: refused, and the file is left as it was.
  EXPECT_THROW(writeVtu(mesh, path.string(), {}, {}, {}, {}, {}, std::vector<double>(1, 1.0)),
               std::invalid_argument);
  EXPECT_EQ(readText(path), text);
  // Box flags: one per element, and only for grid boxes (the prism and the pyramid are none).
  EXPECT_THROW(writeVtu(mesh, path.string(), {}, {}, {}, {}, {}, {}, std::vector<char>(1, 0)),
               std::invalid_argument);
  EXPECT_THROW(writeVtu(mesh, path.string(), {}, {}, {}, {}, {}, {},
                        std::vector<char>(mesh.numElements(), 1)),
               std::logic_error);
  EXPECT_EQ(readText(path), text);
}

TEST(VtuCut, CornerDataIsAveragedPerSideOfACut) {
  // Each element's value is its index. The cut's two corners at y = 0 are written once per
  // side: one point holds element 0's value, the other element 1's. The corners on the cut's
  // front (x = 1, y = 1) stay one point per vertex, the mean of all four elements.
  const PolyMesh mesh = finitelyCutGrid();
  const CornerArray index{"element_index", 1, [](ElementId e, VertexId, double* out) {
                            out[0] = static_cast<double>(e.index());
                          }};
  const fs::path path = testDir() / "corners.vtu";
  writeVtu(mesh, path.string(), {.encoding = VtuEncoding::Ascii}, {}, {}, {index});
  const std::string text = readText(path);
  const std::vector<double> points = asciiValues(text, "Points");
  const std::vector<double> values = asciiValues(text, "element_index");
  ASSERT_EQ(points.size(), 3 * 20u);
  ASSERT_EQ(values.size(), 20u);
  std::vector<double> cutCorner, front;
  for (std::size_t p = 0; p < 20; ++p) {
    const Vec3 x(points[3 * p], points[3 * p + 1], points[3 * p + 2]);
    if (x.x() == 1.0 && x.y() == 0.0) cutCorner.push_back(values[p]);
    if (x.x() == 1.0 && x.y() == 1.0) front.push_back(values[p]);
    if (x.x() == 0.0 && x.y() == 0.0) {
      EXPECT_EQ(values[p], 0.0);  // element 0's alone
    }
  }
  std::sort(cutCorner.begin(), cutCorner.end());
  EXPECT_EQ(cutCorner, (std::vector<double>{0.0, 0.0, 1.0, 1.0}));  // z = 0 and z = 1
  EXPECT_EQ(front, (std::vector<double>{1.5, 1.5}));
  // A corner array is checked like the others.
  EXPECT_THROW(
      writeVtu(mesh, path.string(), {}, {}, {}, {CornerArray{"volume_like", 2, index.value}}),
      std::invalid_argument);
  EXPECT_THROW(writeVtu(mesh, path.string(), {}, {}, {}, {CornerArray{"no_function", 1, {}}}),
               std::invalid_argument);
}

TEST(VtuLayout, WritesTheBytesOfItsMeshAndRefusesItOnceEdited) {
  // A mesh whose cut sides have their own points, with corner and cell data: what a layout
  // keeps (streams, points per side, volumes) and what each file brings (the arrays).
  PolyMesh mesh = finitelyCutGrid();
  const CornerArray index{"element_index", 1, [](ElementId e, VertexId v, double* out) {
                            out[0] = static_cast<double>(e.index()) + 0.25 * v.index();
                          }};
  std::vector<double> values(mesh.numElements());
  for (std::size_t e = 0; e < values.size(); ++e) values[e] = -1.5 * static_cast<double>(e);
  const std::vector<CellArray> cells{CellArray{"minus", 1, values}};
  const fs::path dir = testDir();
  const VtuLayout layout(mesh);
  EXPECT_TRUE(layout.fits(mesh));
  for (VtuEncoding encoding : {VtuEncoding::Ascii, VtuEncoding::Binary, VtuEncoding::Appended}) {
    writeVtu(mesh, (dir / "mesh.vtu").string(), {encoding}, cells, {}, {index});
    writeVtu(layout, (dir / "layout.vtu").string(), {encoding}, cells, {}, {index});
    EXPECT_EQ(readText(dir / "layout.vtu"), readText(dir / "mesh.vtu"));
  }
  // A grid whose face stream the writer asks for in two chunks (1.11 million values, chunks of
  // 2^20): the layout's held stream gives the second chunk its own values.
  const PolyMesh grid = hexGridMesh(33, 33, 33, Box3(Vec3::Zero(), Vec3(1, 2, 3)));
  const VtuLayout gridLayout(grid);
  writeVtu(grid, (dir / "grid.vtu").string());
  writeVtu(gridLayout, (dir / "grid_layout.vtu").string(), {}, {}, {}, {});
  EXPECT_EQ(readText(dir / "grid_layout.vtu"), readText(dir / "grid.vtu"));
  // Arrays are checked as writeVtu(mesh, ...) checks them.
  EXPECT_THROW(
      writeVtu(layout, (dir / "bad.vtu").string(), {}, {}, {}, {CornerArray{"no_function", 1, {}}}),
      std::invalid_argument);
  // Another mesh with the same counts, and this one with a vertex more, do not fit.
  const PolyMesh copy = finitelyCutGrid();
  EXPECT_FALSE(layout.fits(copy));
  mesh.addVertex(Vec3(5, 5, 5));
  EXPECT_FALSE(layout.fits(mesh));
  EXPECT_THROW(writeVtu(layout, (dir / "stale.vtu").string(), {}, {}, {}, {}), std::logic_error);
  EXPECT_FALSE(fs::exists(dir / "stale.vtu"));
}

TEST(VtuCut, MeshesWithoutCutsWriteOnePointPerVertex) {
  const PolyMesh mesh = skewGrid();
  const fs::path path = testDir() / "grid.vtu";
  writeVtu(mesh, path.string());
  EXPECT_EQ(pointsInFile(path), mesh.numVertices());
  EXPECT_EQ(readText(path).find("polydg_point_vertex"), std::string::npos);
}

TEST(VtuCut, WithoutFieldDataTheSidesStayApart) {
  // Without polydg's field data every point is a vertex: the cut's sides are not matched.
  const PolyMesh mesh = cutBoxes();
  const fs::path path = testDir() / "cut.vtu";
  writeVtu(mesh, path.string(), {.encoding = VtuEncoding::Ascii});
  ASSERT_TRUE(dropFieldData(path));
  const PolyMesh read = readVtu(path.string());
  EXPECT_EQ(read.numVertices(), 16u);
  EXPECT_EQ(countInteriorFaces(read), 0u);
  EXPECT_NEAR(signedVolume(read, ElementId(0)) + signedVolume(read, ElementId(1)), 2.0,
              kRelativeTolerance);
}

// --- writer --------------------------------------------------------------------------------

TEST(VtuWrite, LeavesNoTemporaryFileAndReplacesAnOldFile) {
  const fs::path path = testDir() / "grid.vtu";
  writeText(path, "old contents");
  writeVtu(skewGrid(), path.string());
  EXPECT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  EXPECT_EQ(readVtu(path.string()).numElements(), 12u);
}

TEST(VtuWrite, UnwritablePathThrowsNamingTheFile) {
  const fs::path path = testDir() / "no_such_dir" / "grid.vtu";
  const std::string message = errorMessage([&] { writeVtu(skewGrid(), path.string()); });
  EXPECT_NE(message.find("cannot write " + path.string()), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST(VtuWrite, WritesCallerArraysAndVolume) {
  const PolyMesh mesh = skewGrid();
  CellArray id{"element_id", 1, {}};
  CellArray centre{"centre", 3, {}};
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    id.values.push_back(static_cast<double>(e));
    const Vec3 c = elementReferencePoint(mesh, ElementId(e));
    centre.values.insert(centre.values.end(), {c.x(), c.y(), c.z()});
  }
  PointArray height{"height & \"z\"", 1, {}};
  for (const Vec3& p : mesh.positions()) height.values.push_back(p.z());
  const fs::path path = testDir() / "data.vtu";
  writeVtu(mesh, path.string(), {.encoding = VtuEncoding::Ascii}, {id, centre}, {height});
  const std::string text = readText(path);
  EXPECT_NE(text.find("Name=\"volume\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"element_id\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"centre\" NumberOfComponents=\"3\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"height &amp; &quot;z&quot;\""), std::string::npos);
  EXPECT_EQ(readVtu(path.string()).numElements(), mesh.numElements());
}

TEST(VtuWrite, RejectsMalformedArrays) {
  const PolyMesh mesh = skewGrid();
  const std::string path = (testDir() / "bad.vtu").string();
  EXPECT_THROW(writeVtu(mesh, path, {}, {CellArray{"short", 1, {1.0}}}), std::invalid_argument);
  EXPECT_THROW(writeVtu(mesh, path, {}, {CellArray{"volume", 1, std::vector<double>(12)}}),
               std::invalid_argument);
  EXPECT_THROW(writeVtu(mesh, path, {}, {CellArray{"pair", 2, std::vector<double>(24)}}),
               std::invalid_argument);
  EXPECT_THROW(writeVtu(mesh, path, {}, {}, {PointArray{"", 1, std::vector<double>(48)}}),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

// --- reader errors and hand-written files --------------------------------------------------

TEST(VtuRead, MissingFileThrowsNamingTheFile) {
  const std::string path = (testDir() / "missing.vtu").string();
  const std::string message = errorMessage([&] { readVtu(path); });
  EXPECT_EQ(message.rfind(path + ": cannot open", 0), 0u) << message;
}

TEST(VtuRead, OtherXmlThrowsNotAVtkFile) {
  const fs::path path = testDir() / "page.vtu";
  writeText(path, "<?xml version=\"1.0\"?>\n<html><body>hello</body></html>\n");
  EXPECT_EQ(errorMessage([&] { readVtu(path.string()); }),
            path.string() + ": not a VTK UnstructuredGrid file");
  writeText(path, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\"><PolyData/></VTKFile>\n");
  EXPECT_EQ(errorMessage([&] { readVtu(path.string()); }),
            path.string() + ": not a VTK UnstructuredGrid file");
}

TEST(VtuRead, TruncatedFilesThrowNamingTheFile) {
  for (VtuEncoding encoding : {VtuEncoding::Ascii, VtuEncoding::Binary}) {
    const fs::path path = testDir() / "cut.vtu";
    writeVtu(holedPrism(), path.string(), {.encoding = encoding});
    const std::string text = readText(path);
    for (double fraction : {0.3, 0.6, 0.95}) {
      writeText(path, text.substr(0, static_cast<std::size_t>(fraction * text.size())));
      const std::string message = errorMessage([&] { readVtu(path.string()); });
      EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

/// Twelve points p(i, j, k) = i + 3 j + 6 k at (i, j, k), i < 3, j, k < 2; `cells` is the
/// inside of <Cells>, `fieldData` (if not empty) the inside of <FieldData>.
std::string handWrittenVtu(int numCells, const std::string& cells,
                           const std::string& fieldData = "") {
  std::string points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i)
        points += std::to_string(i) + " " + std::to_string(j) + " " + std::to_string(k) + " ";
  return "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "<UnstructuredGrid>" +
         (fieldData.empty() ? "" : "<FieldData>\n" + fieldData + "</FieldData>\n") +
         "<Piece NumberOfPoints=\"12\" NumberOfCells=\"" + std::to_string(numCells) +
         "\">\n<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">" +
         points + "</DataArray></Points>\n<Cells>" + cells +
         "</Cells></Piece></UnstructuredGrid></VTKFile>\n";
}

std::string asciiArray(const char* type, const char* name, const std::string& values) {
  return std::string("<DataArray type=\"") + type + "\" Name=\"" + name + "\" format=\"ascii\">" +
         values + "</DataArray>\n";
}

TEST(VtuRead, InvalidSharingBuildsDuplicateFacesWithoutThrowing) {
  // Cell 0: unit cube [0,1]^3 as a VTK hexahedron; cell 1: [1,2]x[0,1]^2 as a polyhedron
  // sharing x = 1 with cell 0; cell 2: cell 0 again, whose faces then have the same
  // orientation as cell 0's (or, at x = 1, would be used a third time): all duplicated.
  const std::string cells =
      asciiArray("Int32", "connectivity", "0 1 4 3 6 7 10 9  1 2 5 4 7 8 11 10  0 1 4 3 6 7 10 9") +
      asciiArray("Int32", "offsets", "8 16 24") + asciiArray("UInt8", "types", "12 42 12") +
      asciiArray("Int32", "faces",
                 "6 4 1 7 10 4  4 2 5 11 8  4 1 2 8 7  4 4 10 11 5  4 1 4 5 2  4 7 8 11 10") +
      asciiArray("Int32", "faceoffsets", "-1 31 -1");
  const fs::path path = testDir() / "duplicates.vtu";
  writeText(path, handWrittenVtu(3, cells));
  const PolyMesh mesh = readVtu(path.string());
  ASSERT_EQ(mesh.numElements(), 3u);
  EXPECT_EQ(mesh.numVertices(), 12u);
  EXPECT_EQ(mesh.numFaces(), 6u + 5u + 6u);
  EXPECT_EQ(countInteriorFaces(mesh), 1u);
  for (std::size_t e = 0; e < 3; ++e) {
    EXPECT_EQ(mesh.element(ElementId(e)).faces.size(), 6u);
    EXPECT_NEAR(signedVolume(mesh, ElementId(e)), 1.0, kRelativeTolerance);
  }
  for (const Face& f : mesh.faces())
    if (f.isBoundary()) {
      EXPECT_EQ(toString(f.origin), "imported");
    }
}

TEST(VtuRead, UnsupportedCellTypeThrows) {
  const std::string cells = asciiArray("Int32", "connectivity", "0 1 4") +
                            asciiArray("Int32", "offsets", "3") + asciiArray("UInt8", "types", "5");
  const fs::path path = testDir() / "triangle.vtu";
  writeText(path, handWrittenVtu(1, cells));
  EXPECT_EQ(errorMessage([&] { readVtu(path.string()); }),
            path.string() +
                ": cell 0 has VTK type 5, which polydg does not read; only 3D linear cells and "
                "polyhedra are supported");
}

TEST(VtuRead, PointIdOutOfRangeThrows) {
  const std::string cells = asciiArray("Int32", "connectivity", "0 1 4 12") +
                            asciiArray("Int32", "offsets", "4") +
                            asciiArray("UInt8", "types", "10");
  const fs::path path = testDir() / "range.vtu";
  writeText(path, handWrittenVtu(1, cells));
  const std::string message = errorMessage([&] { readVtu(path.string()); });
  EXPECT_EQ(message.rfind(path.string() + ": cell 0 refers to point 12", 0), 0u) << message;
}

// --- field data ----------------------------------------------------------------------------

/// Field data that tries the format: -0.0, a subnormal, the ends of the double range, an empty
/// array; text with XML's special characters, quotes, non-ASCII UTF-8 (two, three and four bytes),
/// CR, LF, a tab, a control character, a NUL, and an empty text; names with XML's special
/// characters and a non-ASCII letter, one key used for a number array and a text, and a name
/// that starts with "polydg_" without a reserved prefix.
VtuFieldData hostileFieldData() {
  using namespace std::string_literals;
  VtuFieldData d;
  d.numbers["grid_cell_size"] = {0.125};
  d.numbers["extremes"] = {-0.0, 1e-300, 1e300,     4.9e-324,
                           -2.5, 0.1,    1.0 / 3.0, -1.7976931348623157e308};
  d.numbers["empty"] = {};
  d.numbers["name with \"quotes\" & <brackets> \u00e9"] = {42.0};
  d.numbers["polydg_sliver_tau"] = {0.01};
  d.strings["input_file"] = "/data/my models/torus \"v2\".obj";
  d.strings["hostile"] =
      "a \"q\" 'x' <b>&amp; ]]> \u00e9 \u4e2d\u6587 \U0001F600\nline\r\n\ttab \x01 nul:\0:end"s;
  d.strings["empty"] = "";
  return d;
}

/// Same names; numbers equal bit for bit (so -0.0 is not 0.0); texts equal byte for byte.
void expectSameFieldData(const VtuFieldData& expected, const VtuFieldData& actual) {
  ASSERT_EQ(expected.numbers.size(), actual.numbers.size());
  for (const auto& [name, values] : expected.numbers) {
    ASSERT_TRUE(actual.numbers.contains(name)) << name;
    const std::vector<double>& read = actual.numbers.at(name);
    ASSERT_EQ(read.size(), values.size()) << name;
    for (std::size_t i = 0; i < values.size(); ++i)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(read[i]), std::bit_cast<std::uint64_t>(values[i]))
          << name << "[" << i << "]: " << read[i] << " instead of " << values[i];
  }
  EXPECT_EQ(expected.strings, actual.strings);
}

class VtuFieldDataRoundTrip : public ::testing::TestWithParam<VtuEncoding> {};

TEST_P(VtuFieldDataRoundTrip, NumbersAndTextComeBackExactly) {
  // A finite cut, so that polydg_point_vertex is among the restore arrays too.
  const PolyMesh mesh = finitelyCutGrid();
  const VtuFieldData written = hostileFieldData();
  const fs::path path = testDir() / "field_data.vtu";
  writeVtu(mesh, path.string(), {.encoding = GetParam()}, {}, {}, {}, written);
  VtuFieldData read;
  read.numbers["stale"] = {1.0};  // replaced, not merged
  read.strings["stale"] = "old";
  const PolyMesh back = readVtu(path.string(), &read);
  expectSameFieldData(written, read);
  expectSameMesh(mesh, back);
  expectSameMesh(mesh, readVtu(path.string()));
}

TEST_P(VtuFieldDataRoundTrip, FollowsTheRestoreArraysNumbersFirst) {
  VtuFieldData data;
  data.numbers["b_number"] = {1.0};
  data.numbers["a_number"] = {2.0};
  data.strings["a_text"] = "x";
  const fs::path path = testDir() / "order.vtu";
  writeVtu(finitelyCutGrid(), path.string(), {.encoding = GetParam()}, {}, {}, {}, data);
  const std::string text = readText(path);
  const auto at = [&](const std::string& name) { return text.find("Name=\"" + name + "\""); };
  ASSERT_NE(at("polydg_point_vertex"), std::string::npos);
  EXPECT_LT(at("polydg_point_vertex"), at("a_number"));
  EXPECT_LT(at("a_number"), at("b_number"));
  EXPECT_LT(at("b_number"), at("a_text.utf8"));
  EXPECT_LT(at("a_text.utf8"), text.find("</FieldData>"));
  EXPECT_NE(text.find("<DataArray type=\"Float64\" Name=\"a_number\" NumberOfTuples=\"1\""),
            std::string::npos);
  EXPECT_NE(text.find("<DataArray type=\"UInt8\" Name=\"a_text.utf8\" NumberOfTuples=\"1\""),
            std::string::npos);
}

/// The Name and offset of each appended <DataArray> of `text`, in document order.
std::vector<std::pair<std::string, std::size_t>> appendedOffsets(const std::string& text) {
  std::vector<std::pair<std::string, std::size_t>> out;
  const std::size_t end = text.find("<AppendedData");
  for (std::size_t at = text.find("<DataArray"); at < end; at = text.find("<DataArray", at + 1)) {
    const std::size_t name = text.find("Name=\"", at) + 6;
    const std::size_t offset = text.find("offset=\"", at) + 8;
    out.emplace_back(text.substr(name, text.find('"', name) - name),
                     std::stoul(text.substr(offset)));
  }
  return out;
}

TEST(VtuFieldData, AppendedAfterTheMeshLastArrayFirst) {
  // The caller's arrays follow every array of polydg's in the appended data, in reverse order
  // (see mesh/vtu_writer.cpp), and polydg's arrays keep the offsets of a file without them.
  const PolyMesh mesh = finitelyCutGrid();
  const fs::path plain = testDir() / "plain.vtu", with = testDir() / "with.vtu";
  writeVtu(mesh, plain.string());
  writeVtu(mesh, with.string(), {}, {}, {}, {}, hostileFieldData());
  const auto polydgArrays = appendedOffsets(readText(plain));
  const auto all = appendedOffsets(readText(with));
  std::vector<std::pair<std::string, std::size_t>> kept, caller;
  for (const auto& a : all) {
    const bool ours = std::any_of(polydgArrays.begin(), polydgArrays.end(),
                                  [&](const auto& p) { return p.first == a.first; });
    (ours ? kept : caller).push_back(a);
  }
  EXPECT_EQ(kept, polydgArrays);
  ASSERT_EQ(caller.size(), 8u);  // five number arrays and three texts
  // The last caller array in the document starts where polydg's appended bytes end.
  const std::string plainText = readText(plain);
  const std::size_t begin = plainText.find('_', plainText.find("<AppendedData")) + 1;
  const std::size_t polydgBytes = plainText.rfind("\n  </AppendedData>") - begin;
  EXPECT_EQ(caller.back().second, polydgBytes);
  for (std::size_t i = 1; i < caller.size(); ++i)
    EXPECT_LT(caller[i].second, caller[i - 1].second) << caller[i].first;
}

INSTANTIATE_TEST_SUITE_P(Encodings, VtuFieldDataRoundTrip, polydg::testing::allEncodings(),
                         polydg::testing::encodingName);

/// The message of the std::invalid_argument that writing `data` throws ("" if none), after
/// checking that the file at `path` (written before) is left as it was.
std::string fieldDataError(const VtuFieldData& data) {
  const fs::path path = testDir() / "refused.vtu";
  writeText(path, "old contents");
  std::string message;
  try {
    writeVtu(skewGrid(), path.string(), {}, {}, {}, {}, data);
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  EXPECT_EQ(readText(path), "old contents");
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  return message;
}

TEST(VtuFieldData, NonFiniteNumbersAreRefusedNamingTheArray) {
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()}) {
    VtuFieldData data;
    data.numbers["cell_size"] = {0.5, bad};
    const std::string message = fieldDataError(data);
    EXPECT_NE(message.find("'cell_size'"), std::string::npos) << message;
    EXPECT_NE(message.find("index 1"), std::string::npos) << message;
  }
}

TEST(VtuFieldData, InvalidNamesAreRefused) {
  const std::string kBadNames[] = {
      "polydg_face_count",           "polydg_element", "polydg_elements",
      "polydg_point_scale",          "two\nlines",     "tab\there",
      std::string("nul\0inside", 10)};
  for (const std::string& name : kBadNames) {
    for (bool text : {false, true}) {
      VtuFieldData data;
      if (text)
        data.strings[name] = "x";
      else
        data.numbers[name] = {1.0};
      EXPECT_NE(fieldDataError(data), "") << name << (text ? " (text)" : " (numbers)");
    }
  }
  VtuFieldData unnamed;
  unnamed.numbers[""] = {1.0};
  EXPECT_NE(fieldDataError(unnamed).find("no name"), std::string::npos);
  VtuFieldData reserved;
  reserved.strings["polydg_point_note"] = "x";
  EXPECT_NE(fieldDataError(reserved).find("'polydg_point_note' is reserved"), std::string::npos);
  // Text "a" is stored as "a.utf8", which the number array already names.
  VtuFieldData clash;
  clash.numbers["a.utf8"] = {1.0};
  clash.strings["a"] = "x";
  EXPECT_NE(fieldDataError(clash).find("'a.utf8'"), std::string::npos);
}

TEST(VtuFieldData, AFileWithoutAnyGivesNone) {
  const fs::path path = testDir() / "plain.vtu";
  writeVtu(skewGrid(), path.string());
  VtuFieldData read;
  read.numbers["stale"] = {1.0};
  read.strings["stale"] = "old";
  readVtu(path.string(), &read);
  EXPECT_TRUE(read.numbers.empty());
  EXPECT_TRUE(read.strings.empty());
}

/// A tetrahedron (points 0, 1, 3, 6 of handWrittenVtu) with `fieldData` inside <FieldData>.
std::string tetrahedronWithFieldData(const std::string& fieldData) {
  const std::string cells = asciiArray("Int32", "connectivity", "0 1 3 6") +
                            asciiArray("Int32", "offsets", "4") +
                            asciiArray("UInt8", "types", "10");
  return handWrittenVtu(1, cells, fieldData);
}

TEST(VtuFieldData, OtherWritersArraysAreReadAsVtuIoHDescribes) {
  // Numbers of any type, widened (2^53 + 1 rounds to 2^53) with components interleaved; UInt8
  // NAME.utf8 and String arrays as text (String values joined by NUL); Bit arrays, restore
  // prefixes and unnamed arrays skipped; of two arrays with one name, the later.
  const std::string fieldData =
      "<DataArray type=\"Int32\" Name=\"counts\" NumberOfComponents=\"2\" NumberOfTuples=\"2\" "
      "format=\"ascii\">1 2 3 -4</DataArray>\n"
      "<DataArray type=\"Float32\" Name=\"scale\" format=\"ascii\">0.5</DataArray>\n"
      "<DataArray type=\"Float32\" Name=\"scale\" format=\"ascii\">0.75</DataArray>\n"
      "<DataArray type=\"Int64\" Name=\"big\" format=\"ascii\">9007199254740993 -7</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"mask\" format=\"ascii\">0 1 255</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"path.utf8\" format=\"ascii\">97 195 188</DataArray>\n"
      "<Array type=\"String\" Name=\"note\" NumberOfTuples=\"2\" format=\"ascii\">104 105 0 -61 "
      "-87 0</Array>\n"
      "<DataArray type=\"Bit\" Name=\"flags\" format=\"ascii\">1 0 1</DataArray>\n"
      "<DataArray type=\"Int32\" Name=\"polydg_point_extra\" format=\"ascii\">5</DataArray>\n"
      "<DataArray type=\"Int32\" format=\"ascii\">6</DataArray>\n";
  const fs::path path = testDir() / "other.vtu";
  writeText(path, tetrahedronWithFieldData(fieldData));
  VtuFieldData read;
  const PolyMesh mesh = readVtu(path.string(), &read);
  EXPECT_NEAR(signedVolume(mesh, ElementId(0)), 1.0 / 6.0, kRelativeTolerance);
  VtuFieldData expected;
  expected.numbers["counts"] = {1, 2, 3, -4};
  expected.numbers["scale"] = {0.75};
  expected.numbers["big"] = {9007199254740992.0, -7};
  expected.numbers["mask"] = {0, 1, 255};
  expected.strings["path"] = "a\u00fc";
  expected.strings["note"] = std::string("hi\0\u00e9", 5);  // é is two bytes
  expectSameFieldData(expected, read);
}

TEST(VtuFieldData, ABrokenArrayFailsOnlyWhenFieldDataIsAsked) {
  const fs::path path = testDir() / "broken.vtu";
  writeText(path,
            tetrahedronWithFieldData(
                "<DataArray type=\"Float64\" Name=\"size\" format=\"ascii\">1 x</DataArray>\n"));
  EXPECT_EQ(readVtu(path.string()).numElements(), 1u);
  VtuFieldData read;
  read.strings["kept"] = "as it was";
  const std::string message = errorMessage([&] { readVtu(path.string(), &read); });
  EXPECT_EQ(message, path.string() + ": array 'size' has an invalid number 'x'");
  EXPECT_EQ(read.strings.at("kept"), "as it was");
}

// --- files written by VTK (ctest fixture: vtk_check.py --write-vtk) -------------------------

/// The path of a file made by vtk_check.py --write-vtk: `suffix` "" for the main file.
std::optional<fs::path> vtkFile(const std::string& suffix) {
  const char* main = std::getenv("POLYDG_VTK_FILES");
  if (main == nullptr || *main == '\0') return std::nullopt;
  const fs::path path(main);
  return path.parent_path() / (path.stem().string() + suffix + ".vtu");
}

#define REQUIRE_VTK_FILE(var, suffix)                                                        \
  const auto var = vtkFile(suffix);                                                          \
  if (!var) GTEST_SKIP() << "POLYDG_VTK_FILES is not set; ctest runs this as vtu_vtk_files"; \
  ASSERT_TRUE(fs::exists(*var)) << *var

/// The VTK-written mesh: cell 0 the unit cube, cell 1 an L-shaped prism of volume 3 sharing the
/// cube's x = 1 face, cell 2 a pyramid of volume 1/3 on the cube's top; 19 points, 18 faces.
const double kVtkCellVolumes[] = {1.0, 3.0, 1.0 / 3.0};

class VtkWrittenFile : public ::testing::TestWithParam<std::string> {};

TEST_P(VtkWrittenFile, ReadsWithExactVolumes) {
  REQUIRE_VTK_FILE(path, GetParam());
  const PolyMesh mesh = readVtu(path->string());
  ASSERT_EQ(mesh.numElements(), 3u);
  EXPECT_EQ(mesh.numVertices(), 19u);
  EXPECT_EQ(mesh.numFaces(), 18u);
  EXPECT_EQ(countInteriorFaces(mesh), 2u);
  for (std::size_t e = 0; e < 3; ++e)
    EXPECT_NEAR(signedVolume(mesh, ElementId(e)), kVtkCellVolumes[e], kRelativeTolerance)
        << "element " << e;
  for (const Face& f : mesh.faces())
    EXPECT_EQ(toString(f.origin), f.isBoundary() ? "imported" : "interior");
}

TEST_P(VtkWrittenFile, ReturnsItsFieldData) {
  // vtk_check.py's add_field_data(): a vtkDoubleArray, a vtkFloatArray, a two-component
  // vtkIntArray, a vtkUnsignedCharArray, a vtkIdTypeArray, two vtkStringArrays (one value with
  // XML's special characters, a non-ASCII letter, a newline and a tab; two values), text by
  // polydg's convention (UInt8 "input_file.utf8"), and a vtkBitArray (skipped).
  REQUIRE_VTK_FILE(path, GetParam());
  VtuFieldData read;
  readVtu(path->string(), &read);
  VtuFieldData expected;
  expected.numbers["cell_size"] = {0.125};
  expected.numbers["scale"] = {0.25};
  expected.numbers["counts"] = {1, 2, 3, -4};
  expected.numbers["mask"] = {0, 1, 255};
  expected.numbers["ids"] = {-7, 2147483647};
  expected.strings["note"] = "a \"q\" <b> & \u00e9\nx\ttab";
  expected.strings["tags"] = std::string("first\0second", 12);
  expected.strings["input_file"] = "torus \u00fc.obj";
  expectSameFieldData(expected, read);
}

// Suffixes of vtk_check.py --write-vtk: defaults (appended, base64, zlib, UInt32 headers, Int64
// ids); appended raw with UInt64 headers; inline binary; ascii; uncompressed raw with Int32 ids
// and Float32 points; inline binary uncompressed with UInt64 headers.
INSTANTIATE_TEST_SUITE_P(Encodings, VtkWrittenFile,
                         ::testing::Values("", "_raw", "_binary", "_ascii", "_uncompressed",
                                           "_binary_uncompressed"),
                         [](const auto& info) {
                           return info.param.empty() ? std::string("Default")
                                                     : info.param.substr(1);
                         });

TEST(VtkWrittenFiles, InvertedCopyReadsWithNegativeVolumes) {
  REQUIRE_VTK_FILE(path, "_inverted");
  const PolyMesh mesh = readVtu(path->string());
  ASSERT_EQ(mesh.numElements(), 3u);
  EXPECT_EQ(mesh.numFaces(), 18u);
  EXPECT_EQ(countInteriorFaces(mesh), 2u);
  for (std::size_t e = 0; e < 3; ++e)
    EXPECT_NEAR(signedVolume(mesh, ElementId(e)), -kVtkCellVolumes[e], kRelativeTolerance);
}

TEST(VtkWrittenFiles, LeakyCopyReadsWithAFaceMissing) {
  REQUIRE_VTK_FILE(path, "_leaky");
  const PolyMesh mesh = readVtu(path->string());
  ASSERT_EQ(mesh.numElements(), 3u);
  EXPECT_EQ(mesh.numFaces(), 17u);
  EXPECT_EQ(mesh.element(ElementId(1)).faces.size(), 8u);  // the L prism lost its top
}

TEST(VtkWrittenFiles, LinearCellsBecomeOutwardPolyhedra) {
  // One cell of each 3D linear type, then a polyhedron, each positively oriented in VTK's
  // numbering: tetra 1/6, voxel 1, hexahedron 2, wedge 1/2, pyramid 1/3, pentagonal prism 3,
  // hexagonal prism 6, polyhedron (unit cube) 1.
  REQUIRE_VTK_FILE(path, "_linear");
  const PolyMesh mesh = readVtu(path->string());
  const double volumes[] = {1.0 / 6.0, 1.0, 2.0, 0.5, 1.0 / 3.0, 3.0, 6.0, 1.0};
  const std::size_t faces[] = {4, 6, 6, 5, 5, 7, 8, 6};
  ASSERT_EQ(mesh.numElements(), 8u);
  for (std::size_t e = 0; e < 8; ++e) {
    EXPECT_EQ(mesh.element(ElementId(e)).faces.size(), faces[e]) << "element " << e;
    EXPECT_NEAR(signedVolume(mesh, ElementId(e)), volumes[e], kRelativeTolerance)
        << "element " << e;
  }
}

TEST(VtkWrittenFiles, TruncatedAppendedDataThrows) {
  REQUIRE_VTK_FILE(path, "");
  const std::string text = readText(*path);
  const fs::path cut = testDir() / "cut.vtu";
  writeText(cut, text.substr(0, text.size() * 8 / 10));
  const std::string message = errorMessage([&] { readVtu(cut.string()); });
  EXPECT_EQ(message.rfind(cut.string() + ": truncated appended data", 0), 0u) << message;
}

// --- files for vtk_check.py (ctest fixture) ------------------------------------------------

TEST(WriteForVtkCheck, HexGridHoledPrismAndMixedCells) {
  const char* dir = std::getenv("POLYDG_VTU_OUT_DIR");
  if (dir == nullptr || *dir == '\0')
    GTEST_SKIP() << "POLYDG_VTU_OUT_DIR is not set; ctest runs this before vtk_check.py";
  fs::create_directories(dir);
  // tests/CMakeLists.txt checks the volumes: 3 * 1.2 * 1.7 = 6.12 in 12 cells,
  // 22.25 * 1.5 = 33.375 in one cell, and 1 + 3 + 1/3 in three cells.
  writeVtu(skewGrid(), (fs::path(dir) / "hex_grid.vtu").string());
  writeVtu(skewGrid(), (fs::path(dir) / "hex_grid_ascii.vtu").string(),
           {.encoding = VtuEncoding::Ascii});
  writeVtu(holedPrism(), (fs::path(dir) / "holed_prism.vtu").string());
  writeVtu(holedPrism(), (fs::path(dir) / "holed_prism_ascii.vtu").string(),
           {.encoding = VtuEncoding::Ascii});
  writeVtu(mixedCells(), (fs::path(dir) / "mixed_cells.vtu").string());
  writeVtu(cutBoxes(), (fs::path(dir) / "cut_boxes.vtu").string());
  writeVtu(finitelyCutGrid(), (fs::path(dir) / "finite_cut.vtu").string());
}

/// `bytes` as lowercase hex, two digits a byte.
std::string hex(std::string_view bytes) {
  static const char kDigits[] = "0123456789abcdef";
  std::string out;
  for (unsigned char c : bytes) {
    out += kDigits[c >> 4];
    out += kDigits[c & 15];
  }
  return out;
}

TEST(WriteForVtkCheck, FieldDataInEveryEncoding) {
  const char* dir = std::getenv("POLYDG_VTU_OUT_DIR");
  if (dir == nullptr || *dir == '\0')
    GTEST_SKIP() << "POLYDG_VTU_OUT_DIR is not set; ctest runs this before vtk_check.py";
  fs::create_directories(dir);
  // The skew grid (6.12 in 12 cells) with hostileFieldData(), for vtk_check.py --field-data
  // field_data.json: names and text as hex of their bytes, numbers as hex floats.
  const VtuFieldData data = hostileFieldData();
  const std::pair<const char*, VtuEncoding> kFiles[] = {
      {"field_data_ascii", VtuEncoding::Ascii},
      {"field_data_binary", VtuEncoding::Binary},
      {"field_data_appended", VtuEncoding::Appended}};
  for (const auto& [name, encoding] : kFiles)
    writeVtu(skewGrid(), (fs::path(dir) / (std::string(name) + ".vtu")).string(),
             {.encoding = encoding}, {}, {}, {}, data);
  std::string json = "{\"numbers\": {";
  for (const auto& [name, values] : data.numbers) {
    if (json.back() != '{') json += ", ";
    json += "\"" + hex(name) + "\": [";
    for (std::size_t i = 0; i < values.size(); ++i) {
      char number[64];
      std::snprintf(number, sizeof number, "%a", values[i]);
      json += (i > 0 ? ", \"" : "\"") + std::string(number) + "\"";
    }
    json += "]";
  }
  json += "}, \"strings\": {";
  for (const auto& [name, text] : data.strings) {
    if (json.back() != '{') json += ", ";
    json += "\"" + hex(name) + "\": \"" + hex(text) + "\"";
  }
  json += "}}\n";
  writeText(fs::path(dir) / "field_data.json", json);
}

}  // namespace
}  // namespace polydg
