// Tests of mesh/surface_io.h: the testdata models read with exact counts, closure, volumes and
// areas; double precision for OBJ/OFF/PLY/STL, as CGAL's readers read them, and the fallback to
// assimp;
// welding, degenerate and point/line handling; one-line errors; no crash and no output over
// assimp's own test models; agreement with meshio's and VTK's volumes
// (tests/mesh/surface_volume.py).
#include "polydg/mesh/surface_io.h"
#include "mesh/surface_text_check.h"
#include "tests/support/assimp_models.h"
#include "tests/support/exact_figures.h"
#include "tests/support/packages.h"
#include "tests/support/temp_dir.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OBJ.h>
#include <CGAL/IO/STL/STL_reader.h>
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace polydg {
namespace {

namespace fs = std::filesystem;

/// VTK's volume against polydg's: the tolerance the CLI test uses.
constexpr double kVtkRelTol = 1e-9;
/// Address space allowed while reading foreign or corrupt files (see AddressSpaceCap).
constexpr rlim_t kReadAddressSpace = rlim_t{4} << 30;

using polydg::corpus::kAssimpModels;
using polydg::packages::kSystemPython;
using polydg::testing::kExactRelTol;  // the testdata models' coordinates are dyadic
using polydg::testing::relativeError;
using polydg::testing::TempDir;

std::string testdata(const std::string& name) {
  return (fs::path(POLYDG_TESTDATA_DIR) / name).string();
}

fs::path volumeScript() {
  return fs::path(POLYDG_TESTDATA_DIR).parent_path() / "tests" / "mesh" / "surface_volume.py";
}

/// Caps this process's address space for its lifetime, so that a reader allocating what a
/// corrupt header declares fails with std::bad_alloc instead of exhausting the machine's memory
/// (assimp's invalid/OutOfMemory.off made an uncapped assimp take 16 GB).
class AddressSpaceCap {
 public:
  explicit AddressSpaceCap(rlim_t bytes) {
    getrlimit(RLIMIT_AS, &saved_);
    rlimit cap = saved_;
    if (cap.rlim_cur == RLIM_INFINITY || cap.rlim_cur > bytes) cap.rlim_cur = bytes;
    setrlimit(RLIMIT_AS, &cap);
  }
  ~AddressSpaceCap() { setrlimit(RLIMIT_AS, &saved_); }
  AddressSpaceCap(const AddressSpaceCap&) = delete;
  AddressSpaceCap& operator=(const AddressSpaceCap&) = delete;

 private:
  rlimit saved_{};
};

/// The message of the std::runtime_error that reading `path` throws ("" if it reads).
std::string readError(const std::string& path) {
  try {
    readSurface(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// --- the testdata models ----------------------------------------------------------------------

struct ModelCase {
  std::string file;
  std::size_t meshes, polygons, vertices, triangles, components;
  double volume, area;
  std::string reader;  // "cgal" for OBJ, OFF, PLY and STL
};

void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.file; }

class TestModel : public ::testing::TestWithParam<ModelCase> {};

TEST_P(TestModel, ReadsClosedWithExactCountsVolumeAndArea) {
  const ModelCase& c = GetParam();
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata(c.file), &info);
  EXPECT_EQ(s.vertices.size(), c.vertices);
  EXPECT_EQ(s.triangles.size(), c.triangles);
  EXPECT_EQ(info.meshes, c.meshes);
  EXPECT_EQ(info.polygons, c.polygons);
  EXPECT_EQ(info.fannedPolygons, 0u);
  EXPECT_EQ(info.weldedVertices, c.vertices);
  EXPECT_EQ(info.triangles, c.triangles);
  EXPECT_GE(info.inputVertices, c.vertices);
  EXPECT_EQ(info.droppedDegenerate, 0u);
  EXPECT_EQ(info.ignoredPoints, 0u);
  EXPECT_EQ(info.ignoredLines, 0u);
  EXPECT_EQ(info.reader, c.reader);

  const SurfaceTopology topo = analyzeTopology(s);
  EXPECT_TRUE(topo.closed()) << topo.boundaryEdges << " boundary, " << topo.nonManifoldEdges
                             << " non-manifold, " << topo.misorientedEdges << " misoriented edges";
  EXPECT_EQ(topo.components, c.components);
  EXPECT_EQ(topo.degenerateTriangles, 0u);
  // The volume is positive only if the file's outward winding survived; the area (sum of
  // unsigned triangle areas) exceeds the exact one if a non-convex face was triangulated with
  // overlapping triangles, which the signed volume would not notice.
  EXPECT_LT(relativeError(enclosedVolume(s), c.volume), kExactRelTol) << enclosedVolume(s);
  EXPECT_LT(relativeError(surfaceArea(s), c.area), kExactRelTol) << surfaceArea(s);
}

INSTANTIATE_TEST_SUITE_P(
    Testdata, TestModel,
    ::testing::Values(
        // Unit cube of six quads: 24 OBJ corners weld to 8 vertices, quads become 12 triangles.
        ModelCase{"cube.obj", 1, 6, 8, 12, 1, 1.0, 6.0, "cgal"},
        // Octahedron (+-1, 0, 0), (0, +-2, 0), (0, 0, +-3): volume 4/3 * 1 * 2 * 3, eight faces
        // of area 7/2 each. Some zeros are written -0, so the weld must treat -0.0 as 0.0.
        ModelCase{"octahedron.stl", 1, 0, 6, 8, 1, 8.0, 28.0, "cgal"},
        // Tetrahedron with legs 2, 3, 4 along the axes: volume 2 * 3 * 4 / 6; right faces of
        // area 3, 4 and 6 and a slanted one of area |(12, 8, 6)| / 2 = sqrt(61).
        ModelCase{"tetra.off", 1, 0, 4, 4, 1, 4.0, 13.0 + std::sqrt(61.0), "cgal"},
        // L-shaped hexagon of area 3 extruded to height 1.5: two non-convex hexagons (4
        // triangles each) and six quads; area 2 * 3 + perimeter 8 * 1.5. (assimp 5.2.5's
        // aiProcess_Triangulate gets the top hexagon wrong: area 19.)
        ModelCase{"Lprism.ply", 1, 8, 12, 20, 1, 4.5, 18.0, "cgal"},
        // Cubes of volume 1 and 8 in two objects; the second cube is split over the two
        // materials (meshes), so it is closed only if vertices weld across meshes.
        ModelCase{"two_cubes.obj", 2, 12, 16, 24, 2, 9.0, 30.0, "cgal"},
        // One unit-cube mesh used by two glTF nodes (one scaled by 2) under a translated root:
        // closed with two components only if node transforms are baked per instance.
        ModelCase{"instanced_cubes.gltf", 1, 0, 16, 24, 2, 9.0, 30.0, "assimp"}),
    [](const ::testing::TestParamInfo<ModelCase>& info) {
      std::string name = info.param.file;
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

TEST(ReadSurface, WeldsStlCornersIncludingNegativeZero) {
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata("octahedron.stl"), &info);
  EXPECT_EQ(info.reader, "cgal");
  EXPECT_EQ(info.inputVertices, 24u);  // STL repeats every corner
  ASSERT_EQ(s.vertices.size(), 6u);
  for (const Vec3& p : s.vertices)
    for (int i = 0; i < 3; ++i) EXPECT_FALSE(p[i] == 0.0 && std::signbit(p[i])) << p.transpose();
}

// The welding rule (mesh/surface_io.h): corners become one vertex exactly when their
// coordinates are bitwise equal, -0.0 counting as 0.0. Two triangles share the corners (0, 0, 0)
// and (1, 0, 0); the second writes the first as (-0, -0.0, -0) and has the corner
// (0, 1.0000000000000002, 0), one ulp from the first triangle's (0, 1, 0). Without welding the
// file has 6 vertices, without the -0.0 rule 5, with any tolerance 3; exact welding gives 4.
TEST(ReadSurface, WeldsBitwiseEqualCornersWithNegativeZeroAsZeroAndNothingCloser) {
  const TempDir dir("weld_rule");
  const std::string corners =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -0 -0.0 -0\nv 1 0 0\nv 0 1.0000000000000002 0\n"
      "f 1 2 3\nf 4 5 6\n";
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(dir.write("weld_rule.obj", corners), &info);
  EXPECT_EQ(info.reader, "cgal");
  EXPECT_EQ(info.inputVertices, 6u);
  ASSERT_EQ(s.vertices.size(), 4u);
  EXPECT_EQ(info.weldedVertices, 4u);
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.triangles[1][0], s.triangles[0][0]);  // -0 welded to 0
  EXPECT_EQ(s.triangles[1][1], s.triangles[0][1]);  // (1, 0, 0) twice
  EXPECT_NE(s.triangles[1][2], s.triangles[0][2]);  // one ulp apart: two vertices
  EXPECT_EQ(s.vertices[s.triangles[1][2]].y(), std::nextafter(1.0, 2.0));
  EXPECT_EQ(s.vertices[s.triangles[0][2]].y(), 1.0);
  for (const Vec3& p : s.vertices)
    for (int i = 0; i < 3; ++i) EXPECT_FALSE(std::signbit(p[i])) << p.transpose();

  // The same corners through assimp (an unused homogeneous vertex with w != 1, which CGAL would
  // misread, makes it the reader), in single precision: 1.0000000000000002 is 1.0f, so that
  // corner welds too; -0 still welds to 0.
  SurfaceReadInfo single;
  const TriangleSurface t =
      readSurface(dir.write("weld_rule_assimp.obj", corners + "v 5 5 5 2\n"), &single);
  EXPECT_EQ(single.reader, "assimp");
  ASSERT_EQ(t.vertices.size(), 3u);
  for (const Vec3& p : t.vertices)
    for (int i = 0; i < 3; ++i) EXPECT_FALSE(std::signbit(p[i])) << p.transpose();
}

TEST(ReadSurface, BakesNodeTransformsOfInstancedMeshes) {
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata("instanced_cubes.gltf"), &info);
  EXPECT_EQ(info.inputVertices, 16u);  // the 8-vertex mesh once per node
  // Root translation (0, 0, 1); instances [0,1]^3 + (-2, 0, 0) and 2 * [0,1]^3 + (3, 0, 0).
  const Box3 box = bounds(s);
  EXPECT_EQ(box.min(), Vec3(-2, 0, 1));
  EXPECT_EQ(box.max(), Vec3(5, 2, 3));
}

TEST(ReadSurface, DropsOnlyTrianglesWithRepeatedVertices) {
  // The tetrahedron of tetra.off, plus vertex 5 = vertex 1 written as (-0, -0, 0), vertex 6 on
  // edge 1-2, a triangle 1 5 2 that welding makes degenerate and a zero-area triangle 1 6 2
  // with three distinct vertices, which is kept.
  const TempDir dir("weld");
  const std::string path = dir.write("weld.obj",
                                     "v 0 0 0\nv 2 0 0\nv 0 3 0\nv 0 0 4\nv -0 -0 0\nv 1 0 0\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 5 2\nf 1 6 2\n");
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.droppedDegenerate, 1u);
  EXPECT_EQ(info.triangles, 5u);
  EXPECT_EQ(s.triangles.size(), 5u);
  EXPECT_EQ(s.vertices.size(), 5u);  // vertex 5 welded into vertex 1
  const SurfaceTopology topo = analyzeTopology(s);
  EXPECT_EQ(topo.degenerateTriangles, 1u);  // the zero-area triangle
  EXPECT_EQ(topo.nonManifoldEdges, 1u);     // edge 1-2, now used three times
  EXPECT_EQ(topo.boundaryEdges, 2u);        // edges 1-6 and 6-2
  EXPECT_LT(relativeError(enclosedVolume(s), 4.0), kExactRelTol);
}

TEST(ReadSurface, SkipsAndCountsPointsAndLinesBesideTriangles) {
  std::ifstream cube(testdata("cube.obj"));
  const std::string text((std::istreambuf_iterator<char>(cube)), std::istreambuf_iterator<char>());
  const TempDir dir("mixed");
  // Two points and a polyline of two segments.
  const std::string path = dir.write("mixed.obj", text + "p 1 2\nl 1 2 3\n");
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.reader, "cgal");  // p and l lines are counted and removed before CGAL reads
  EXPECT_EQ(info.ignoredPoints, 2u);
  EXPECT_EQ(info.ignoredLines, 2u);
  EXPECT_EQ(s.triangles.size(), 12u);
  EXPECT_EQ(s.vertices.size(), 8u);
  EXPECT_TRUE(analyzeTopology(s).closed());
}

TEST(ReadSurface, FansPolygonsThatHaveNoExactTriangulation) {
  // A self-crossing quad (a bow tie) and four collinear corners (zero area).
  const TempDir dir("fan");
  const std::string path = dir.write("fan.obj",
                                     "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n"
                                     "v 0 0 5\nv 1 0 5\nv 2 0 5\nv 3 0 5\nf 5 6 7 8\n");
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.polygons, 2u);
  EXPECT_EQ(info.fannedPolygons, 2u);
  EXPECT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(analyzeTopology(s).degenerateTriangles, 2u);  // the collinear fan
}

// --- double precision (CGAL) and the fallback to assimp ------------------------------------------

/// True if `x` has no float32 representation: reading it in single precision would change it.
bool needsDouble(double x) { return static_cast<double>(static_cast<float>(x)) != x; }

/// The corners of box [x0,x1] x [y0,y1] x [z0,z1] in OBJ order (bit 0: x, bit 1: y, bit 2: z)
/// and its six faces as outward quads of 1-based indices.
const std::array<std::array<int, 4>, 6> kBoxQuads = {
    {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}}};

std::string boxQuadLines() {
  std::string text;
  for (const auto& q : kBoxQuads)
    text += "f " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
            " " + std::to_string(q[3]) + "\n";
  return text;
}

TEST(ReadSurfaceDouble, ObjCoordinatesAreTheCorrectlyRoundedDoublesOfTheText) {
  // A box about 1e3 in size, far from the origin, whose coordinates float32 cannot hold: 17
  // significant digits and offsets of 1e-9 and 3e-13 from round numbers.
  const std::array<std::array<std::string, 2>, 3> text = {{
      {"1000.1234567890123456", "2000.000000001"},
      {"-999.999999999", "0.1234567890123456"},
      {"1e3", "2.0000000000003e3"},
  }};
  std::string obj = "# box with coordinates that need double precision\n";
  std::vector<Vec3> expected;
  for (int corner = 0; corner < 8; ++corner) {
    const std::string& x = text[0][corner & 1];
    const std::string& y = text[1][(corner >> 1) & 1];
    const std::string& z = text[2][(corner >> 2) & 1];
    obj += "v " + x + " " + y + " " + z + "\n";
    expected.emplace_back(std::stod(x), std::stod(y), std::stod(z));
  }
  for (const auto& pair : text)
    for (const std::string& value : pair) {
      if (value == "1e3") continue;
      EXPECT_TRUE(needsDouble(std::stod(value))) << value;
    }
  const TempDir dir("double_obj");
  const std::string path = dir.write("box.obj", obj + boxQuadLines());
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.reader, "cgal");
  EXPECT_EQ(info.inputVertices, 8u);
  ASSERT_EQ(s.vertices.size(), 8u);
  for (const Vec3& p : expected) {
    const auto found = std::find_if(s.vertices.begin(), s.vertices.end(), [&](const Vec3& q) {
      return std::memcmp(p.data(), q.data(), sizeof(double) * 3) == 0;
    });
    EXPECT_NE(found, s.vertices.end()) << "missing bitwise " << p.transpose();
  }
  EXPECT_TRUE(analyzeTopology(s).closed());
  const double volume = (expected[7] - expected[0]).prod();
  EXPECT_LT(relativeError(enclosedVolume(s), volume), kExactRelTol)
      << enclosedVolume(s) << " vs " << volume;
}

/// The volume of the OBJ file's `v`/`f` geometry, parsed here with std::stod and summed in
/// double over a fan of each face: sum of a . (b x c) / 6 about the bounding-box centre.
double objTextVolume(const std::string& path) {
  std::ifstream in(path);
  std::vector<Vec3> points;
  std::vector<std::vector<std::size_t>> faces;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "v") {
      std::string x, y, z;
      words >> x >> y >> z;
      points.emplace_back(std::stod(x), std::stod(y), std::stod(z));
    } else if (keyword == "f") {
      faces.emplace_back();
      for (std::string corner; words >> corner;)  // "i", "i/t", "i//n" or "i/t/n"
        faces.back().push_back(std::stoul(corner.substr(0, corner.find('/'))) - 1);
    }
  }
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 centre = 0.5 * (lo + hi);
  double sum = 0;
  for (const auto& f : faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k)
      sum += (points[f[0]] - centre).dot((points[f[k]] - centre).cross(points[f[k + 1]] - centre));
  return sum / 6;
}

TEST(ReadSurfaceDouble, TorusVolumeIsThatOfTheDoublePrecisionGeometry) {
  // testdata/torus.obj: R = 1, r = 0.4, written with 17 significant digits. Its double
  // geometry encloses 3.1329805058038223 (meshio agrees); assimp's floats gave 3.1329804237.
  constexpr double kDoubleVolume = 3.1329805058038223;
  const double independent = objTextVolume(testdata("torus.obj"));
  EXPECT_LT(relativeError(independent, kDoubleVolume), kExactRelTol) << independent;
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata("torus.obj"), &info);
  EXPECT_EQ(info.reader, "cgal");
  ASSERT_TRUE(analyzeTopology(s).closed());
  const double volume = enclosedVolume(s);
  EXPECT_LT(relativeError(volume, independent), kExactRelTol) << volume;
  EXPECT_LT(relativeError(volume, kDoubleVolume), kExactRelTol) << volume;
  EXPECT_GT(relativeError(volume, 3.1329804237), 1e-8) << "single-precision volume";
}

/// A binary STL: 80-byte header, facet count, then per facet a normal, three corners and two
/// attribute bytes, all little-endian float32.
std::string binaryStl(const std::string& header,
                      const std::vector<std::array<std::array<float, 3>, 3>>& facets) {
  std::string data = header;
  data.resize(80, ' ');
  const auto append = [&](const void* bytes, std::size_t size) {
    data.append(static_cast<const char*>(bytes), size);
  };
  const std::uint32_t count = static_cast<std::uint32_t>(facets.size());
  append(&count, sizeof count);
  for (const auto& facet : facets) {
    const float normal[3] = {0, 0, 0};
    append(normal, sizeof normal);
    for (const auto& corner : facet) append(corner.data(), sizeof(float) * 3);
    append("\0\0", 2);
  }
  return data;
}

/// (vertex of the result, corner of tetraFacets) pairs: corners are numbered in order of first
/// use, 0 2 1 3.
constexpr std::array<std::pair<int, int>, 4> kFirstUse = {{{0, 0}, {1, 2}, {2, 1}, {3, 3}}};

/// The tetrahedron with corners `p` (outward faces 0 2 1, 0 1 3, 0 3 2, 1 2 3).
template <typename Point>
std::vector<std::array<Point, 3>> tetraFacets(const std::array<Point, 4>& p) {
  return {{p[0], p[2], p[1]}, {p[0], p[1], p[3]}, {p[0], p[3], p[2]}, {p[1], p[2], p[3]}};
}

TEST(ReadSurfaceDouble, BinaryStlReadsExactlyItsFloatValues) {
  static_assert(std::endian::native == std::endian::little, "binary STL is little-endian");
  const std::array<std::array<float, 3>, 4> corners = {{{0.1f, -0.2f, 1000.3f},
                                                        {2.7182817f, -0.2f, 1000.3f},
                                                        {0.1f, 3.1415927f, 1000.3f},
                                                        {0.1f, -0.2f, 1004.123456f}}};
  const TempDir dir("binary_stl");
  // A binary header starting with "solid" must not make the file ASCII.
  for (const char* header : {"polydg binary STL", "solid but binary"}) {
    const std::string path = dir.write("tetra.stl", binaryStl(header, tetraFacets(corners)));
    SurfaceReadInfo info;
    const TriangleSurface s = readSurface(path, &info);
    EXPECT_EQ(info.reader, "cgal") << header;
    EXPECT_EQ(info.inputVertices, 12u);
    ASSERT_EQ(s.vertices.size(), 4u) << header;
    // Corners in order of first use: 0, 2, 1, 3.
    for (const auto& [index, corner] : kFirstUse)
      for (int i = 0; i < 3; ++i)
        EXPECT_EQ(s.vertices[index][i], static_cast<double>(corners[corner][i])) << header;
    EXPECT_TRUE(analyzeTopology(s).closed()) << header;
  }
}

/// Expects `ours`, read from the STL file at `path`, to be what CGAL's binary or ASCII STL parser
/// reads (it merges bit-equal points as it reads): `points` points, the same bits in the same
/// order (of first use), and the same triangles.
void expectCgalsStl(const TriangleSurface& ours, const std::string& path, bool binary,
                    std::size_t points) {
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  std::vector<Point> cgal;
  std::vector<std::array<std::size_t, 3>> triangles;
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(binary ? CGAL::IO::internal::parse_binary_STL(in, cgal, triangles)
                     : CGAL::IO::internal::parse_ASCII_STL(in, cgal, triangles));
  ASSERT_EQ(cgal.size(), points);
  ASSERT_EQ(ours.vertices.size(), cgal.size());
  for (std::size_t v = 0; v < cgal.size(); ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(ours.vertices[v][k]),
                std::bit_cast<std::uint64_t>(cgal[v][k]))
          << "vertex " << v << ", coordinate " << k;
  ASSERT_EQ(ours.triangles.size(), triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_EQ(ours.triangles[t][k], triangles[t][k]) << "triangle " << t;
}

TEST(ReadSurfaceDouble, BinaryStlReadsWhatCgalsBinaryParserReads) {
  // polydg reads a binary STL's facets itself; CGAL's binary parser, which merges bit-equal
  // points as it reads, is the reference: the welded surface has CGAL's points, in CGAL's order
  // (of first use), bit for bit, and CGAL's triangles. A wavy 16 x 12 patch of float
  // coordinates far from the origin, each inner point shared by six facets.
  std::vector<std::array<std::array<float, 3>, 3>> facets;
  const auto at = [](int i, int j) {
    return std::array<float, 3>{
        1.0e4f + 0.1f * static_cast<float>(i), -3.3f + 0.37f * static_cast<float>(j),
        std::sin(0.7f * static_cast<float>(i)) * 0.01f + static_cast<float>(j * j) * 1.0e-3f};
  };
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 12; ++j) {
      facets.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      facets.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  const TempDir dir("binary_stl_cgal");
  const std::string path = dir.write("patch.stl", binaryStl("patch", facets));
  SurfaceReadInfo info;
  const TriangleSurface ours = readSurface(path, &info);
  expectCgalsStl(ours, path, /*binary=*/true, 17 * 13);
  EXPECT_EQ(info.inputVertices, 3 * facets.size());
}

TEST(ReadSurfaceDouble, PlainAsciiStlReadsWhatCgalsAsciiParserReads) {
  // A plain ASCII STL file's facets are read while its text is checked; CGAL's ASCII parser
  // (which merges bit-equal points) is the reference, bit for bit: the wavy patch of the binary
  // test in double precision, written with 17 digits, exponents, tabs and CR LF line ends, in
  // two solids one after the other.
  const auto at = [](int i, int j) {
    return std::array<double, 3>{1.0e4 + 0.1 * i, -3.3 + 0.37 * j,
                                 std::sin(0.7 * i) * 0.01 + j * j * 1.0e-3};
  };
  const auto number = [](double x, bool exponent) {
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, exponent ? "%.16e" : "%.17g", x);
    return std::string(buffer);
  };
  std::string text = "solid patch\r\n";
  int count = 0;
  for (int i = 0; i < 8; ++i) {
    if (i == 4) text += "endsolid patch\nsolid second part\n";
    for (int j = 0; j < 6; ++j)
      for (const auto& facet : {std::array{at(i, j), at(i + 1, j), at(i + 1, j + 1)},
                                std::array{at(i, j), at(i + 1, j + 1), at(i, j + 1)}}) {
        text += "  facet normal 0 0 1\r\n    outer loop\r\n";
        for (const auto& p : facet)
          text += "\tvertex " + number(p[0], count % 2 == 0) + " " + number(p[1], false) + "\t" +
                  number(p[2], count % 3 == 0) + "\r\n";
        text += "    endloop\r\n  endfacet\r\n";
        ++count;
      }
  }
  text += "endsolid second part\n";
  ReadWarnings warnings("patch.stl");
  StlRecords records;
  checkAsciiStlText("patch.stl", text, warnings, &records);
  ASSERT_TRUE(records.plain);
  EXPECT_EQ(records.corners.size(), 3u * 96u);
  const TempDir dir("ascii_stl_cgal");
  const std::string path = dir.write("patch.stl", text);
  const TriangleSurface ours = readSurface(path);
  expectCgalsStl(ours, path, /*binary=*/false, 9 * 7);

  // What is not plain goes to CGAL's parser as before: a solid opened inside another (CGAL
  // stops there), a keyword in a solid's name (CGAL reads it as one), no endsolid (CGAL fails),
  // a line the check warns about.
  const std::string facet =
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
      "endfacet\n";
  for (const std::string& variant : {"solid a\n" + facet + "solid b\n" + facet + "endsolid b\n",
                                     "solid facet\n" + facet + "endsolid\n", "solid a\n" + facet,
                                     "solid a\n" + facet + "colour red\nendsolid a\n"}) {
    ReadWarnings quiet("variant.stl");
    StlRecords read;
    checkAsciiStlText("variant.stl", variant, quiet, &read);
    EXPECT_FALSE(read.plain) << variant;
    EXPECT_TRUE(read.corners.empty()) << variant;
  }
  ReadWarnings quiet("plain.stl");
  StlRecords read;
  checkAsciiStlText("plain.stl", "solid a\n" + facet + "endsolid a\n", quiet, &read);
  EXPECT_TRUE(read.plain);
  EXPECT_EQ(read.corners.size(), 3u);
}

TEST(ReadSurfaceDouble, AsciiPlyKeepsDoubleValuesAndRoundsFloatOnesOnce) {
  const std::array<std::array<std::string, 3>, 4> text = {{
      {"0.1234567890123456", "-0.000000001", "1000.000000000001"},
      {"2.1234567890123456", "-0.000000001", "1000.000000000001"},
      {"0.1234567890123456", "3.000000000007", "1000.000000000001"},
      {"0.1234567890123456", "-0.000000001", "1004.4444444444444"},
  }};
  const TempDir dir("ply");
  for (const std::string type : {"double", "float"}) {
    std::string ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty " + type +
                      " x\nproperty " + type + " y\nproperty " + type +
                      " z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto& v : text) ply += v[0] + " " + v[1] + " " + v[2] + "\n";
    ply += "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    SurfaceReadInfo info;
    const TriangleSurface s = readSurface(dir.write(type + ".ply", ply), &info);
    EXPECT_EQ(info.reader, "cgal");
    ASSERT_EQ(s.vertices.size(), 4u);
    for (const auto& [index, corner] : kFirstUse)
      for (int i = 0; i < 3; ++i) {
        const std::string& value = text[corner][i];
        // A float property is the float nearest the text, widened exactly.
        const double wanted =
            type == "double" ? std::stod(value) : static_cast<double>(std::stof(value));
        EXPECT_EQ(s.vertices[index][i], wanted) << type << " " << value;
        if (type == "double") {
          EXPECT_TRUE(needsDouble(wanted)) << value;
        }
      }
    EXPECT_TRUE(analyzeTopology(s).closed());
  }
}

TEST(ReadSurfaceDouble, ObjVariantsCgalReads) {
  const std::string tetra = "v 0 0 0\nv 2 0 0\nv 0 3 0\nv 0 0 4\n";
  const TempDir dir("obj_variants");
  const std::vector<std::pair<std::string, std::string>> files = {
      {"negative.obj", tetra + "f -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n"},
      {"slashes_tabs_comments.obj",
       "v\t0 0 0\nv 2\t0 0\r\nv 0 3 0\nv 0 0 4\nvt 0 0\nvn 0 0 1\n"
       "f\t1/1/1\t3/1/1\t2/1/1\nf 1//1 2//1 4//1\r\nf 1 4 3 # comment\nf 2/1 3/1 4/1#c\n"},
      {"forward.obj", "v 0 0 0\nf 1 3 2\nv 2 0 0\nv 0 3 0\nv 0 0 4\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"},
      {"weight_one.obj",
       "v 0 0 0 1\nv 2 0 0 1.0\nv 0 3 0 1\nv 0 0 4 1\n"
       "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"},
      {"short_faces.obj", tetra + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 2\nf 3\n"},
  };
  for (const auto& [name, text] : files) {
    SurfaceReadInfo info;
    const TriangleSurface s = readSurface(dir.write(name, text), &info);
    EXPECT_EQ(info.reader, "cgal") << name;
    EXPECT_EQ(s.vertices.size(), 4u) << name;
    EXPECT_EQ(s.triangles.size(), 4u) << name;
    EXPECT_TRUE(analyzeTopology(s).closed()) << name;
    EXPECT_LT(relativeError(enclosedVolume(s), 4.0), kExactRelTol) << name;
    if (name == "short_faces.obj") {  // faces of two and one corners count as a line and a point
      EXPECT_EQ(info.ignoredLines, 1u);
      EXPECT_EQ(info.ignoredPoints, 1u);
      EXPECT_EQ(info.warnings.size(), 2u);
    } else {  // tabs, CR LF line ends, comments, attributes and forward references are no defects
      EXPECT_TRUE(info.warnings.empty()) << name << ": " << info.warnings.front();
    }
  }
}

TEST(ReadSurfaceDouble, PlainOffReadsWhatCgalsReaderReads) {
  // A plain OFF file's records are read while its text is checked, not by CGAL's stream
  // parser; a comment anywhere sends the same records to CGAL. Both must give the same
  // surface, bit for bit: signs, a leading '+', 17 and 30 significant digits, a subnormal,
  // exponents, forms without a digit before or after the point, quads and a pentagon.
  const std::array<std::array<std::string, 2>, 3> text = {{
      {"-0", "0.30000000000000004441"},
      {"+1.5", "1.500000000000000222044604925031308"},
      {"4.9406564584124654e-324", "1E5"},
  }};
  std::string records;
  for (int corner = 0; corner < 8; ++corner)
    records += text[0][corner & 1] + " " + text[1][(corner >> 1) & 1] + "\t" +
               text[2][(corner >> 2) & 1] + "\n";
  // The box's sides, outward; -z as a pentagon with a repeated corner's neighbour in line.
  records += "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  const std::string header = "OFF\n8 6 0\n";
  const TempDir dir("plain_off");
  const std::string plain = dir.write("plain.off", header + records);
  const std::string commented = dir.write("commented.off", header + "# to CGAL\n" + records);
  SurfaceReadInfo plainInfo, cgalInfo;
  const TriangleSurface a = readSurface(plain, &plainInfo);
  const TriangleSurface b = readSurface(commented, &cgalInfo);
  ASSERT_EQ(a.vertices.size(), 8u);
  ASSERT_EQ(b.vertices.size(), a.vertices.size());
  for (std::size_t v = 0; v < a.vertices.size(); ++v)
    EXPECT_EQ(std::memcmp(a.vertices[v].data(), b.vertices[v].data(), 3 * sizeof(double)), 0)
        << v << ": " << a.vertices[v].transpose() << " vs " << b.vertices[v].transpose();
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(plainInfo.inputVertices, cgalInfo.inputVertices);
  EXPECT_EQ(plainInfo.polygons, 6u);
  EXPECT_EQ(cgalInfo.polygons, 6u);
  // The values are the text's, correctly rounded (the subnormal kept; -0 is welded as 0).
  EXPECT_EQ(a.vertices[0].x(), 0.0);
  EXPECT_EQ(a.vertices[0].z(), std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(a.vertices[1].x(), 0.30000000000000004);
  EXPECT_EQ(a.vertices[3].y(), std::nextafter(1.5, 2.0));
  EXPECT_TRUE(analyzeTopology(a).closed());
}

TEST(ReadSurfaceDouble, ObjRecordsAreWhatCgalsObjReaderReads) {
  // polydg reads an OBJ file's vertices and faces while it checks the text (checkObjText); CGAL's
  // OBJ reader, run on the same text, is the reference: the same points, bit for bit (signs, a
  // leading '+', 17 and 30 significant digits, a subnormal, exponents, forms without a digit
  // before or after the point), and the same faces: corners with texture and normal references,
  // indices counted back from -1 and forward references, quads and a pentagon, among
  // comments, groups, materials, tabs, CR LF line ends, a colour and a weight of 1.
  const std::string text =
      "# corners of a box\r\n"
      "mtllib box.mtl\r\n"
      "v -0 0.30000000000000004441 4.9406564584124654e-324\r\n"
      "v +1.5 0.30000000000000004441 4.9406564584124654e-324 1\n"
      "v -0 1.500000000000000222044604925031308\t1E5\n"
      "vt 0.5 0.5\n"
      "vn 0 0 1\n"
      "g side\n"
      "usemtl red\n"
      "f 1/1/1 3//1 8 6  # a forward reference\n"
      "v +1.5 1.500000000000000222044604925031308 1E5 0.2 0.3 0.4\n"
      "v -0 .5 5. \n"
      "f -5 -1 -3\n"
      "v 1.5 .5 5.\n"
      "v .25 -2.5e-3 -1e+2\n"
      "v 7 8 9\n"
      "f 2 4 8 7 5\n"
      "o second\n"
      "f 6/2 5/2 4/2 3/2\n"
      "f 1 -2 8 # the last vertex read is 8, -2 is 7\n";
  ReadWarnings warnings("records.obj");
  const ObjText ours = checkObjText("records.obj", text, warnings);
  EXPECT_TRUE(warnings.lines().empty()) << warnings.lines().front();
  ASSERT_TRUE(ours.assimpReason.empty()) << ours.assimpReason;
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  std::istringstream in(text);
  ASSERT_TRUE(CGAL::IO::read_OBJ(in, points, polygons));
  ASSERT_EQ(ours.positions.size(), points.size());
  for (std::size_t v = 0; v < points.size(); ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(ours.positions[v][static_cast<std::size_t>(k)]),
                std::bit_cast<std::uint64_t>(points[v][k]))
          << "vertex " << v << ", coordinate " << k;
  EXPECT_EQ(ours.polygons, polygons);
  // What both read, spelled out: the relative corners resolved and the forward reference kept.
  ASSERT_EQ(ours.polygons.size(), 5u);
  EXPECT_EQ(ours.polygons[1], (std::vector<std::size_t>{0, 4, 2}));
  EXPECT_EQ(ours.polygons[0], (std::vector<std::size_t>{0, 2, 7, 5}));
  EXPECT_EQ(ours.polygons[4], (std::vector<std::size_t>{0, 6, 7}));
  EXPECT_EQ(ours.positions[1][1], 0.30000000000000004);
  EXPECT_EQ(ours.positions[0][2], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(ours.positions[6][1], -2.5e-3);
}

TEST(ReadSurfaceDouble, FallsBackToAssimpForWhatCgalDoesNotRead) {
  const TempDir dir("fallback");
  const std::string faces = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const std::string plyFaces =
      "element face 4\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  const std::vector<std::pair<std::string, std::string>> files = {
      // Homogeneous coordinates: CGAL would ignore w; assimp divides by it.
      {"homogeneous.obj", "v 0 0 0 2\nv 4 0 0 2\nv 0 6 0 2\nv 0 0 8 2\n" + faces},
      // A line continuation, which CGAL does not join.
      {"continued.obj",
       "v 0 0 0\nv 2 0 0\nv 0 3 0\nv 0 0 4\nf 1 3 \\\n 2\nf 1 2 4\nf 1 4 3\n"
       "f 2 3 4\n"},
      // Integer coordinates, on which CGAL's PLY reader asserts.
      {"int_coordinates.ply",
       "ply\nformat ascii 1.0\nelement vertex 4\nproperty int x\n"
       "property int y\nproperty int z\n" +
           plyFaces +
           "0 0 0\n2 0 0\n0 3 0\n0 0 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n"
           "3 1 2 3\n"},
      // 32-bit list counts, which CGAL allocates without a bound.
      {"uint_counts.ply",
       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
       "property float y\nproperty float z\nelement face 4\n"
       "property list uint int vertex_indices\nend_header\n"
       "0 0 0\n2 0 0\n0 3 0\n0 0 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"},
      // Indices of type ushort, which CGAL's PLY reader does not look for.
      {"ushort_indices.ply",
       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
       "property float y\nproperty float z\nelement face 4\n"
       "property list uchar ushort vertex_indices\nend_header\n"
       "0 0 0\n2 0 0\n0 3 0\n0 0 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"},
  };
  for (const auto& [name, text] : files) {
    SurfaceReadInfo info;
    const TriangleSurface s = readSurface(dir.write(name, text), &info);
    EXPECT_EQ(info.reader, "assimp") << name;
    EXPECT_EQ(s.triangles.size(), 4u) << name;
    EXPECT_TRUE(analyzeTopology(s).closed()) << name;
    EXPECT_LT(relativeError(enclosedVolume(s), 4.0), kExactRelTol) << name;
  }
  // An ASCII STL file without endsolid, which CGAL rejects and assimp reads.
  SurfaceReadInfo info;
  const TriangleSurface stl =
      readSurface(dir.write("open_solid.stl",
                            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"),
                  &info);
  EXPECT_EQ(info.reader, "assimp");
  EXPECT_EQ(stl.triangles.size(), 1u);
  EXPECT_TRUE(info.warnings.empty());
}

// --- errors -----------------------------------------------------------------------------------

TEST(ReadSurfaceErrors, MissingFile) {
  const std::string path = testdata("no_such_model.obj");
  EXPECT_EQ(readError(path), path + ": no such file");
}

TEST(ReadSurfaceErrors, Directory) {
  const std::string path = POLYDG_TESTDATA_DIR;
  EXPECT_EQ(readError(path), path + ": is a directory; give the path of a mesh file");
}

TEST(ReadSurfaceErrors, UnknownFormatQuotesAssimpOnOneLine) {
  const TempDir dir("unknown");
  const std::string path = dir.write("notes.xyz", "hello\nworld\n");
  const std::string message = readError(path);
  EXPECT_EQ(message.rfind(path + ": assimp cannot read it (", 0), 0u) << message;
  EXPECT_NE(message.find("No suitable reader"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(ReadSurfaceErrors, HeaderCountsLargerThanTheFile) {
  const AddressSpaceCap cap(kReadAddressSpace);
  const TempDir dir("counts");
  const std::string off =
      dir.write("faces.off",
                "OFF\n# corrupt face count\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n"
                "3 0 1 2\n");
  EXPECT_EQ(readError(off), off + ": header declares 4000000000 faces but the file has only " +
                                std::to_string(fs::file_size(off)) + " bytes; the file is corrupt");
  const std::string ply = dir.write(
      "faces.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1500000000\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(readError(ply), ply +
                                ": header declares 1500000000 'face' elements but the file "
                                "has only " +
                                std::to_string(fs::file_size(ply)) + " bytes; the file is corrupt");
}

TEST(ReadSurfaceErrors, OnlyPointsOrLines) {
  const TempDir dir("points");
  const std::string expected =
      ": contains only points/lines, no triangles; polydg needs a "
      "surface mesh";
  const std::string points = dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2\np 3\n");
  EXPECT_EQ(readError(points), points + expected);
  const std::string lines = dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
  EXPECT_EQ(readError(lines), lines + expected);
  const std::string cloud = dir.write("cloud.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_EQ(readError(cloud), cloud + expected);
}

TEST(ReadSurfaceErrors, SceneWithoutMeshes) {
  const TempDir dir("nomesh");
  const std::string path = dir.write(
      "empty.gltf", R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}]})");
  EXPECT_EQ(readError(path), path + ": contains no meshes");
}

TEST(ReadSurfaceErrors, OnlyDegenerateTriangles) {
  const TempDir dir("degenerate");
  const std::string path = dir.write("flat.obj", "v 0 0 0\nv 0 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(readError(path), path +
                                 ": no face has three distinct vertices (1 degenerate); "
                                 "polydg needs a surface mesh");
}

TEST(ReadSurfaceErrors, NonFiniteCoordinate) {
  // In text checked line by line, the line; in what assimp reads (a homogeneous OBJ file, whose
  // x = 1e39 overflows assimp's single precision), the file.
  const TempDir dir("nonfinite");
  for (const char* value : {"inf", "nan"}) {
    const std::string path = dir.write(std::string(value) + ".obj", std::string("v ") + value +
                                                                        " 0 0\nv 1 0 0\nv 0 1 0\n"
                                                                        "f 1 2 3\n");
    EXPECT_EQ(readError(path), path + ":1: coordinate '" + value + "' is not a number; correct it");
  }
  const std::string path = dir.write("w2.obj", "v 1e39 0 0 2\nv 1 0 0 2\nv 0 1 0 2\nf 1 2 3\n");
  EXPECT_EQ(readError(path),
            path + ": a vertex has a non-finite coordinate (NaN or infinity); fix the file");
}

TEST(ReadSurfaceErrors, NonFiniteFloatInBinaryStl) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::array<std::array<float, 3>, 4> corners = {
      {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {nan, 0, 4}}};
  const TempDir dir("nan_stl");
  const std::string path = dir.write("nan.stl", binaryStl("nan", tetraFacets(corners)));
  EXPECT_EQ(readError(path),
            path + ": a vertex has a non-finite coordinate (NaN or infinity); fix the file");
}

TEST(ReadSurfaceErrors, UnreadableByBothReadersQuotesAssimpAndCgal) {
  const TempDir dir("both");
  // A binary PLY file (no lines to check) whose face names vertex 7 of 3.
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::int32_t indices[3] = {0, 1, 7};
  ply.append(reinterpret_cast<const char*>(corners), sizeof corners);
  ply += '\3';
  ply.append(reinterpret_cast<const char*>(indices), sizeof indices);
  // Each file, and a word of CGAL's reason (CGAL's own message or polydg's check before it).
  const std::vector<std::pair<std::string, std::string>> files = {
      {dir.write("range.ply", ply), "beyond"},
      {dir.write("continued.obj", "v 0 0 0\nv 2 0 0\nv 0 3 \\\n 0\nf 1 2 3\nf 1 2 x\n"),
       "continuation"},
      {dir.write("neither.stl", "this is not an STL file\n"), "neither binary"},
  };
  for (const auto& [path, reason] : files) {
    const std::string message = readError(path);
    EXPECT_EQ(message.rfind(path + ": assimp cannot read it (", 0), 0u) << path << ": " << message;
    const std::size_t cgal = message.find("; nor can CGAL (");
    ASSERT_NE(cgal, std::string::npos) << message;
    EXPECT_NE(message.find(reason, cgal), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

/// Reads every regular file under `root` whose name passes `wanted`, in sorted order, with the
/// address space capped; returns per file "closed", "open" or "error: <message>". Fails the
/// test on any exception other than a one-line std::runtime_error naming the file, and if
/// reading printed anything to stdout or stderr.
std::map<std::string, std::string> readAll(const fs::path& root, bool (*wanted)(const fs::path&)) {
  std::vector<std::string> paths;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file() && wanted(entry.path())) paths.push_back(entry.path().string());
  std::map<std::string, std::string> outcome;
  const AddressSpaceCap cap(kReadAddressSpace);
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  for (const std::string& path : paths) {
    try {
      outcome[path] = analyzeTopology(readSurface(path)).closed() ? "closed" : "open";
    } catch (const std::runtime_error& e) {
      outcome[path] = std::string("error: ") + e.what();
    } catch (const std::exception& e) {
      outcome[path] = std::string("unexpected exception: ") + e.what();
    }
  }
  const std::string printed =
      ::testing::internal::GetCapturedStdout() + ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "") << "reading files under " << root << " printed output";
  for (auto& [path, what] : outcome) {
    EXPECT_EQ(what.rfind("unexpected", 0), std::string::npos) << path << ": " << what;
    if (what.rfind("error: ", 0) != 0) continue;
    const std::string message = what.substr(7);
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    // "FILE: what", or "FILE:LINE: what" for a malformed line.
    EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
    const std::size_t start = path.size() + (message.compare(path.size(), 2, ": ") == 0 ? 2 : 1);
    what = "error: " + message.substr(std::min(message.size(), start));
  }
  return outcome;
}

TEST(ReadSurfaceErrors, AssimpInvalidModelsFailCleanly) {
  const fs::path dir = kAssimpModels / "invalid";
  ASSERT_TRUE(packages::assimpTestModels());
  const auto outcome = readAll(dir, [](const fs::path&) { return true; });
  ASSERT_FALSE(outcome.empty());
  for (const auto& [path, what] : outcome) {
    const std::string name = fs::path(path).filename().string();
    std::cout << "  " << name << ": " << what << "\n";
    // Empty files, out-of-range face indices and absurd counts cannot make a surface.
    if (name.starts_with("empty") || name == "malformed.obj" || name == "OutOfMemory.off") {
      EXPECT_TRUE(what.starts_with("error: ")) << path;
    }
  }
}

TEST(ReadSurface, PrintsNothing) {
  // Readable models and each kind of error; assimp's corpus is checked the same way below.
  const TempDir dir("quiet");
  std::vector<std::string> paths;
  for (const char* name : {"cube.obj", "octahedron.stl", "tetra.off", "Lprism.ply", "two_cubes.obj",
                           "instanced_cubes.gltf", "no_such_model.obj"})
    paths.push_back(testdata(name));
  paths.push_back(dir.write("points.obj", "v 0 0 0\nv 1 0 0\np 1 2\n"));
  paths.push_back(dir.write("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"));
  paths.push_back(dir.write("notes.xyz", "hello\n"));
  // CGAL's readers print in verbose mode: PLY faces without vertex indices and a binary STL
  // (whose header CGAL echoes to std::cout) reach them; an unknown OBJ keyword, a non-triangular
  // STL facet and a truncated OFF file, which once did, are now stopped or removed by the line
  // checks before CGAL.
  paths.push_back(dir.write("keyword.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nbogus\n"));
  paths.push_back(dir.write("quad.stl",
                            "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
                            "endfacet\nendsolid q\n"));
  paths.push_back(dir.write("noindex.ply",
                            "ply\nformat ascii 1.0\nelement vertex 3\n"
                            "property float x\nproperty float y\n"
                            "property float z\nelement face 1\n"
                            "property list uchar int corners\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  paths.push_back(dir.write("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"));
  // CGAL still sees these: an OBJ file of comments only ("empty file?") and an ASCII STL file
  // without endsolid.
  paths.push_back(dir.write("comments.obj", "# nothing but a comment\n"));
  paths.push_back(dir.write("open_solid.stl",
                            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"));
  paths.push_back(dir.write(
      "binary.stl", binaryStl("solid-looking header", {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}})));
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  for (const std::string& path : paths) readError(path);
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}

// --- assimp's test models ---------------------------------------------------------------------

using polydg::corpus::isSupportedModel;

TEST(AssimpModels, EveryModelReadsOrFailsWithOneLine) {
  ASSERT_TRUE(packages::assimpTestModels());
  const auto outcome = readAll(kAssimpModels, isSupportedModel);
  std::size_t closed = 0, open = 0, errors = 0;
  for (const auto& [path, what] : outcome) {
    std::cout << "  " << fs::relative(path, kAssimpModels).string() << ": " << what << "\n";
    closed += what == "closed";
    open += what == "open";
    errors += what.rfind("error", 0) == 0;
  }
  std::cout << outcome.size() << " models: " << closed << " closed, " << open << " open, " << errors
            << " errors\n";
  EXPECT_EQ(closed + open + errors, outcome.size());
  // Known outcomes, one per kind, so that a reader that fails everything cannot pass.
  const auto expect = [&](const char* model, const std::string& what) {
    const auto it = outcome.find((kAssimpModels / model).string());
    ASSERT_NE(it, outcome.end()) << model;
    EXPECT_EQ(it->second.substr(0, what.size()), what) << model;
  };
  expect("OBJ/box.obj", "closed");
  expect("glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", "closed");
  expect("STL/triangle.stl", "open");
  expect("PLY/points.ply", "error: contains only points/lines");
  // Malformed lines: the first one is named (malformed.obj's face index 12 of 8 vertices, line 23).
  expect("invalid/malformed.obj", "error: 23: face index 12 is beyond the 8 vertices");
  expect("OBJ/number_formats.obj", "error: 11: coordinate '3.1+e2' is not a number");
  // assimp rejected its empty second solid; CGAL reads the triangle of the first.
  expect("STL/triangle_with_empty_solid.stl", "open");
}

// --- meshio's and VTK's independent volume -----------------------------------------------------

/// What tests/mesh/surface_volume.py --verbose printed for one model.
struct ScriptResult {
  int status = -1;
  std::string volume;  ///< stdout: one JSON number
  std::string reader;  ///< "meshio" or "vtk" (stderr), when it succeeded
};

/// Runs tests/mesh/surface_volume.py --verbose on `path`.
ScriptResult scriptVolume(const std::string& path) {
  const TempDir dir("script");
  const std::string errors = dir.write("stderr.txt", "");
  const std::string command = kSystemPython.string() + " '" + volumeScript().string() +
                              "' --verbose '" + path + "' 2>'" + errors + "'";
  ScriptResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 256> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.volume += buffer.data();
  result.status = pclose(pipe);
  std::ifstream(errors) >> result.reader;
  return result;
}

TEST(VolumeScript, AgreesWithExactAndReadVolumes) {
  ASSERT_TRUE(packages::pythonModule("vtkmodules.vtkFiltersCore", "python3-vtk9"));
  ASSERT_TRUE(packages::pythonModule("meshio", "python3-meshio"));
  ASSERT_TRUE(packages::assimpTestModels());
  // Testdata models, read by meshio in double precision, against their exact volumes (the
  // torus: that of its double-precision geometry) and readSurface's.
  const std::vector<std::pair<std::string, double>> exact = {
      {"cube.obj", 1.0},      {"octahedron.stl", 8.0}, {"Lprism.ply", 4.5},
      {"two_cubes.obj", 9.0}, {"tetra.off", 4.0},      {"torus.obj", 3.1329805058038223}};
  for (const auto& [name, volume] : exact) {
    const ScriptResult r = scriptVolume(testdata(name));
    ASSERT_EQ(r.status, 0) << name;
    EXPECT_EQ(r.reader, "meshio") << name;
    EXPECT_LT(relativeError(std::stod(r.volume), volume), kExactRelTol) << name << ": " << r.volume;
    EXPECT_LT(relativeError(std::stod(r.volume), enclosedVolume(readSurface(testdata(name)))),
              kExactRelTol)
        << name;
  }
  // Closed models of assimp's corpus whose faces are planar, so that the script's fan
  // triangulation and readSurface's give the same volume. meshio 5.0 cannot read some of them
  // (cube_usemtl.obj: fewer normals than vertices; cube.ply: "list uint8 int32"), which VTK
  // then reads in single precision: exact here, as their coordinates are small dyadics.
  for (const char* model : {"OBJ/box.obj", "OBJ/cube_usemtl.obj", "OBJ/testmixed.obj",
                            "PLY/cube.ply", "PLY/cube_binary.ply", "STL/Spider_binary.stl"}) {
    const std::string path = (kAssimpModels / model).string();
    const TriangleSurface s = readSurface(path);
    const ScriptResult r = scriptVolume(path);
    ASSERT_EQ(r.status, 0) << model;
    EXPECT_TRUE(r.reader == "meshio" || r.reader == "vtk") << model << ": " << r.reader;
    if (!analyzeTopology(s).closed()) continue;  // the volume of an open surface is arbitrary
    EXPECT_LT(relativeError(std::stod(r.volume), std::abs(enclosedVolume(s))), kVtkRelTol) << model;
  }
  // An OFF file of quads: meshio reads only triangles, and VTK has no OFF reader.
  EXPECT_NE(scriptVolume((kAssimpModels / "OFF/Cube.off").string()).status, 0);
  // Failures: a format the script does not handle, and a file with no polygons.
  EXPECT_NE(scriptVolume(testdata("instanced_cubes.gltf")).status, 0);
  const TempDir dir("vtk");
  EXPECT_NE(scriptVolume(dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n")).status,
            0);
}

}  // namespace
}  // namespace polydg
