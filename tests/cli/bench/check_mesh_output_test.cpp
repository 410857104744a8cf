// checkMesh's output read (cli/bench/check_mesh_output.h): a mesh that passes and one that fails
// two checks, in OpenFOAM v1912's wording (the passing one as it printed for snappyHexMesh's
// torus at 12 cells), and output without a verdict.
#include "cli/bench/check_mesh_output.h"

#include <gtest/gtest.h>

#include <string>

namespace polydg::bench {
namespace {

const std::string kPassing = R"(Mesh stats
    points:           300
    faces:            720
    internal faces:   512
    cells:            240
    faces per cell:   5.1333333333333337
    boundary patches: 1

Overall number of cells of each type:
    hexahedra:     112
    polyhedra:     32

Checking geometry...
    Max cell openness = 2.2075328762835493e-16 OK.
    Max aspect ratio = 4.3337853749627726 OK.
    Minimum face area = 0.017686599767269322. Maximum face area = 0.11279128004183234.  Face area magnitudes OK.
    Min volume = 0.0025877545013383305. Max volume = 0.02542097919199196.  Total volume = 2.8287815954227651.  Cell volumes OK.
    Mesh non-orthogonality Max: 26.725795740312648 average: 14.275310493301021
    Non-orthogonality check OK.
    Face pyramids OK.
    Max skewness = 0.60429660496230908 OK.
    Coupled point location match (average 0) OK.

Mesh OK.

End
)";

const std::string kFailing = R"(Mesh stats
    points:           5600
    cells:            1816

Checking geometry...
 ***High aspect ratio cells found, Max aspect ratio: 1038.27, number of cells 20
  <<Writing 20 cells with high aspect ratio to set highAspectRatioCells
    Min volume = 1.5e-09. Max volume = 0.0127.  Total volume = 3.1.  Cell volumes OK.
    Mesh non-orthogonality Max: 41.5 average: 6.2
 ***Max skewness = 18.1, 1432 highly skew faces detected which may impair the quality of the results
  <<Writing 1432 skew faces to set skewFaces

Failed 2 mesh checks.

End
)";

TEST(CheckMeshOutput, ReadsAPassingMesh) {
  const CheckMeshSummary s = parseCheckMesh(kPassing);
  EXPECT_EQ(s.verdict, "Mesh OK");
  EXPECT_EQ(s.failedChecks, 0);
  EXPECT_EQ(s.cells, 240u);
  EXPECT_EQ(s.totalVolume, 2.8287815954227651);
  EXPECT_EQ(s.maxNonOrthogonality, 26.725795740312648);
  EXPECT_EQ(s.maxSkewness, 0.60429660496230908);
  EXPECT_EQ(s.maxAspectRatio, 4.3337853749627726);
  EXPECT_TRUE(s.failures.empty());
}

TEST(CheckMeshOutput, ReadsFailedChecksAndTheirFigures) {
  const CheckMeshSummary s = parseCheckMesh(kFailing);
  EXPECT_EQ(s.verdict, "Failed 2 mesh checks");
  EXPECT_EQ(s.failedChecks, 2);
  EXPECT_EQ(s.cells, 1816u);
  EXPECT_EQ(s.totalVolume, 3.1);
  EXPECT_EQ(s.maxAspectRatio, 1038.27);
  EXPECT_EQ(s.maxSkewness, 18.1);
  ASSERT_EQ(s.failures.size(), 2u);
  EXPECT_EQ(s.failures[1],
            "Max skewness = 18.1, 1432 highly skew faces detected which may impair the quality of "
            "the results");
}

TEST(CheckMeshOutput, OutputWithoutAVerdict) {
  const CheckMeshSummary s = parseCheckMesh("--> FOAM FATAL ERROR:\ncannot find file\n");
  EXPECT_EQ(s.verdict, "no verdict");
  EXPECT_FALSE(s.cells || s.totalVolume || s.maxSkewness);
}

}  // namespace
}  // namespace polydg::bench
