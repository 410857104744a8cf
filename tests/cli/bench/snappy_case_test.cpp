// The snappyHexMesh case of the openfoam suite (cli/bench/snappy_case.h): its block is polydg's
// grid and one more cell around it, its locationInMesh a block cell centre wholly inside the
// surface, and its STL the surface bit for bit.
#include "cli/bench/snappy_case.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/util/error.h"
#include "tests/support/temp_dir.h"

namespace polydg::bench {
namespace {

std::string readText(const std::filesystem::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The vector "(x y z)" in `text`, read back in double precision.
Vec3 vectorIn(const std::string& text) {
  std::istringstream in(text.substr(text.find('(') + 1));
  Vec3 v;
  in >> v.x() >> v.y() >> v.z();
  return v;
}

TEST(SnappyCase, TheBlockIsPolydgsGridWithOneMoreCellAround) {
  const TriangleSurface ring = torus(Vec3(0.1, 0, 0), 1.0, 0.4, 64, 32);
  const SurfaceDistance distance(ring);
  for (int n : {12, 24}) {
    const Grid grid = Grid::withCellsAlongLongest(bounds(ring), n);
    const SnappySetup s = snappySetup(ring, distance, n, "torus");
    EXPECT_EQ(s.cellSize, grid.cellSize);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(s.blockCells[a], grid.cells[a] + 2) << "n " << n << " axis " << a;
      EXPECT_EQ(s.blockMin[a], grid.plane(a, 0) - grid.cellSize);
      EXPECT_EQ(s.blockMax[a], grid.plane(a, grid.cells[a]) + grid.cellSize);
      // A cell centre: half a cell past a block plane (never on a face of the background mesh).
      const double index = (s.locationInMesh[a] - s.blockMin[a]) / s.cellSize;
      EXPECT_NEAR(index - std::floor(index), 0.5, 1e-9) << "n " << n << " axis " << a;
    }
    EXPECT_TRUE(distance.inside(s.locationInMesh));
    EXPECT_DOUBLE_EQ(distance.distance(s.locationInMesh), s.depth);
    EXPECT_GT(s.depth, 0.5 * std::sqrt(3.0) * s.cellSize);  // its cell wholly inside
  }
  // A tube thinner than a cell has no such cell.
  const TriangleSurface thin = torus(Vec3::Zero(), 1.0, 0.05, 64, 16);
  EXPECT_THROW(snappySetup(thin, SurfaceDistance(thin), 12, "thin"), InputError);
}

TEST(SnappyCase, WritesTheDictionariesAndTheSurface) {
  const polydg::testing::TempDir dir("snappy_case");
  const TriangleSurface ring = torus(Vec3::Zero(), 1.0, 0.4, 32, 16);
  const SnappySetup s = snappySetup(ring, SurfaceDistance(ring), 12, "ring");
  writeSnappyCase(dir.path() / "case", ring, s);
  const std::filesystem::path c = dir.path() / "case";
  for (const char* file : {"controlDict", "fvSchemes", "fvSolution", "blockMeshDict",
                           "surfaceFeatureExtractDict", "snappyHexMeshDict"})
    EXPECT_TRUE(std::filesystem::exists(c / "system" / file)) << file;
  const std::string block = readText(c / "system" / "blockMeshDict");
  EXPECT_NE(block.find("(14 14 6) simpleGrading (1 1 1)"), std::string::npos) << block;
  // The block's first and seventh corners are its min and max, and locationInMesh a cell
  // centre, all exactly: blockMesh's planes are then polydg's grid planes.
  const std::string listStart = "vertices\n(\n";
  const std::size_t list = block.find(listStart);
  ASSERT_NE(list, std::string::npos) << block;
  std::istringstream corners(block.substr(list + listStart.size()));
  std::vector<Vec3> corner;
  for (std::string line; std::getline(corners, line) && line.find('(') != std::string::npos;)
    corner.push_back(vectorIn(line));
  ASSERT_EQ(corner.size(), 8u) << block;
  EXPECT_EQ(corner[0], s.blockMin);
  EXPECT_EQ(corner[6], s.blockMax);
  const std::string snappy = readText(c / "system" / "snappyHexMeshDict");
  const std::size_t location = snappy.find("locationInMesh (");
  ASSERT_NE(location, std::string::npos);
  EXPECT_EQ(vectorIn(snappy.substr(location, snappy.find(')', location) - location + 1)),
            s.locationInMesh);
  for (const char* entry :
       {"castellatedMesh true;", "snap true;", "addLayers false;", "level (0 0);",
        "file \"ring.extendedFeatureEdgeMesh\"; level 0;", "locationInMesh (", "ring.stl"})
    EXPECT_NE(snappy.find(entry), std::string::npos) << entry;
  EXPECT_NE(readText(c / "system" / "surfaceFeatureExtractDict").find("includedAngle 150;"),
            std::string::npos);
  EXPECT_NE(readText(c / "system" / "controlDict").find("writeFormat ascii;"), std::string::npos);
  // The STL holds the surface's coordinates exactly (17 significant digits).
  const TriangleSurface back = readSurface((c / "constant" / "triSurface" / "ring.stl").string());
  ASSERT_EQ(back.triangles.size(), ring.triangles.size());
  ASSERT_EQ(back.vertices.size(), ring.vertices.size());
  for (std::size_t t = 0; t < ring.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(back.vertices[back.triangles[t][k]], ring.vertices[ring.triangles[t][k]]);
}

}  // namespace
}  // namespace polydg::bench
