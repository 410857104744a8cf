// OpenFOAM's ASCII polyMesh read back (cli/bench/foam_boundary.h): one cube and two cubes side
// by side, written as OpenFOAM writes them (header, comments, short lists on one line, a
// uniform list, faceList and faceCompactList), their boundary faces, samples and volume; and
// what the reader refuses, naming the file.
#include "cli/bench/foam_boundary.h"

#include <gtest/gtest.h>

#include <string>

#include "polydg/util/error.h"
#include "tests/support/temp_dir.h"

namespace polydg::bench {
namespace {

using polydg::testing::TempDir;

const std::string kHeader =
    R"(/*--------------------------------*- C++ -*----------------------------------*\
| =========                 |                                                 |
\*---------------------------------------------------------------------------*/
FoamFile
{
    version     2.0;
    format      ascii;
    class       %CLASS%;
    location    "constant/polyMesh";
    object      %OBJECT%;
}
// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

)";

std::string header(const std::string& cls, const std::string& object) {
  std::string h = kHeader;
  h.replace(h.find("%CLASS%"), 7, cls);
  h.replace(h.find("%OBJECT%"), 8, object);
  return h;
}

/// The points of two unit cubes along x: x = 0, 1, 2 by y, z = 0, 1; point 4 i + 2 j + k is
/// (i, j, k). Written as OpenFOAM does a list of more than ten: one item a line.
std::string twoCubePoints() {
  std::string text = header("vectorField", "points") + "\n12\n(\n";
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        text += "(" + std::to_string(i) + " " + std::to_string(j) + " " + std::to_string(k) + ")\n";
  return text + ")\n\n// ***** //\n";
}

/// Cube c's six faces, outward (normals by the right-hand rule), its x = 1 face first when
/// c = 0 (the internal face of the two cubes, out of its owner).
std::vector<std::string> cubeFaces(int c) {
  auto p = [c](int i, int j, int k) { return std::to_string(4 * (i + c) + 2 * j + k); };
  auto quad = [](const std::string& a, const std::string& b, const std::string& d,
                 const std::string& e) { return "4(" + a + " " + b + " " + d + " " + e + ")"; };
  return {quad(p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1)),   // x = 1
          quad(p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0)),   // x = 0
          quad(p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1)),   // y = 0
          quad(p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0)),   // y = 1
          quad(p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0)),   // z = 0
          quad(p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1))};  // z = 1
}

/// Two cubes: the internal face (cube 0's x = 1), then patch "ends" (x = 0 of cube 0, x = 2 of
/// cube 1) and patch "sides" (the other eight).
void writeTwoCubes(const TempDir& dir) {
  const std::vector<std::string> a = cubeFaces(0), b = cubeFaces(1);
  const std::vector<std::string> faces = {a[0], a[1], b[0], a[2], a[3], a[4],
                                          a[5], b[2], b[3], b[4], b[5]};
  std::string text = header("faceList", "faces") + "\n11\n(\n";
  for (const std::string& f : faces) text += f + "\n";
  dir.write("constant/polyMesh/faces", text + ")\n");
  dir.write("constant/polyMesh/points", twoCubePoints());
  dir.write("constant/polyMesh/boundary", header("polyBoundaryMesh", "boundary") + R"(
2
(
    ends
    {
        type            wall;
        inGroups        1(wall);
        nFaces          2;
        startFace       1;
    }
    sides  // a comment, and an entry with a sub-dictionary
    {
        type            patch;
        extra { a 1; b (1 2); }
        nFaces          8;
        startFace       3;
    }
)
)");
}

TEST(FoamBoundary, ReadsThePatchFacesOfTwoCubes) {
  const TempDir dir("foam_two_cubes");
  writeTwoCubes(dir);
  const FoamBoundary b = readFoamBoundary(dir.path());
  ASSERT_EQ(b.points.size(), 12u);
  EXPECT_EQ(b.points[7], Vec3(1, 1, 1));
  ASSERT_EQ(b.patches.size(), 2u);
  EXPECT_EQ(b.patches[0].name, "ends");
  EXPECT_EQ(b.patches[0].start, 1u);
  EXPECT_EQ(b.patches[1].name, "sides");
  EXPECT_EQ(b.patches[1].faces, 8u);
  ASSERT_EQ(b.faces.size(), 10u);  // the internal face left out
  EXPECT_EQ(b.faces[0], (std::vector<std::uint32_t>{0, 1, 3, 2}));
  // The faces enclose the two cubes, from any reference point (exactly: every product is of
  // small integers, halves and quarters).
  for (const Vec3& reference : {Vec3(0.5, 0.5, 0.5), Vec3(-3, 7, 0.25)})
    EXPECT_EQ(enclosedVolume(b, reference), 2.0) << reference.transpose();
  // Samples: 4 vertices, 4 edge midpoints and the centre of each face.
  const std::vector<Vec3> samples = boundarySamples(b);
  ASSERT_EQ(samples.size(), 90u);
  EXPECT_EQ(samples[0], Vec3(0, 0, 0));
  EXPECT_EQ(samples[1], Vec3(0, 0, 0.5));
  EXPECT_EQ(samples[8], Vec3(0, 0.5, 0.5));
}

TEST(FoamBoundary, ReadsCompactFacesShortAndUniformLists) {
  // One cube: points as a short list on one line, faces as faceCompactList (offsets, then
  // indices), one patch.
  const TempDir dir("foam_one_cube");
  std::string points = header("vectorField", "points") + "8((0 0 0) (0 0 1) (0 1 0) (0 1 1) " +
                       "(1 0 0) (1 0 1) (1 1 0) (1 1 1))\n";
  dir.write("constant/polyMesh/points", points);
  std::string indices;
  for (const std::string& f : cubeFaces(0)) indices += f.substr(2, f.size() - 3) + "\n";
  dir.write("constant/polyMesh/faces",
            header("faceCompactList", "faces") + "7(0 4 8 12 16 20 24)\n24\n(\n" + indices + ")\n");
  dir.write("constant/polyMesh/boundary", header("polyBoundaryMesh", "boundary") +
                                              "1\n(\nwalls\n{\n type wall;\n nFaces 6;\n"
                                              " startFace 0;\n}\n)\n");
  const FoamBoundary b = readFoamBoundary(dir.path());
  ASSERT_EQ(b.faces.size(), 6u);
  EXPECT_EQ(b.faces[5], (std::vector<std::uint32_t>{1, 5, 7, 3}));
  EXPECT_NEAR(enclosedVolume(b, Vec3(0.1, 0.2, 0.3)), 1.0, 1e-15);
  // A uniform list (N{value}) where a list of labels is read: offsets of one face of no
  // points, in no patch.
  dir.write("constant/polyMesh/faces", header("faceCompactList", "faces") + "2{0}\n0()\n");
  dir.write("constant/polyMesh/boundary", header("polyBoundaryMesh", "boundary") + "0\n(\n)\n");
  EXPECT_TRUE(readFoamBoundary(dir.path()).faces.empty());
}

/// The message of the InputError that reading `dir` throws ("" if none).
std::string refusal(const TempDir& dir) {
  try {
    readFoamBoundary(dir.path());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FoamBoundary, RefusesWhatItCannotRead) {
  const TempDir dir("foam_refusals");
  EXPECT_NE(refusal(dir).find("points not found"), std::string::npos) << refusal(dir);
  writeTwoCubes(dir);
  std::string points = twoCubePoints();
  dir.write("constant/polyMesh/points", points.replace(points.find("ascii"), 5, "binary"));
  EXPECT_NE(refusal(dir).find("writeFormat ascii"), std::string::npos) << refusal(dir);
  points = twoCubePoints();
  dir.write("constant/polyMesh/points", points.replace(points.find("(1 1 1)"), 7, "(1 x 1)"));
  const std::string bad = refusal(dir);
  EXPECT_NE(bad.find("points:"), std::string::npos) << bad;  // FILE:LINE
  EXPECT_NE(bad.find("found 'x'"), std::string::npos) << bad;
  writeTwoCubes(dir);
  dir.write("constant/polyMesh/boundary", header("polyBoundaryMesh", "boundary") +
                                              "1\n(\nall\n{\n nFaces 11;\n startFace 1;\n}\n)\n");
  EXPECT_NE(refusal(dir).find("patch all names faces beyond"), std::string::npos) << refusal(dir);
}

}  // namespace
}  // namespace polydg::bench
