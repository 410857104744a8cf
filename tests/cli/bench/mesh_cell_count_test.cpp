// Cell counts read from mesh files' headers (cli/bench/mesh_cell_count.h): the tetrahedra of
// hand-written MSH 4.1 files (blocks of several element types, tags not from 1, 10-node tets not
// counted) and what is refused, and the cells of VTU files polydg writes in every encoding,
// against the mesh written.
#include "cli/bench/mesh_cell_count.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "mesh/primitives.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/util/error.h"
#include "tests/support/temp_dir.h"

namespace polydg::bench {
namespace {

/// A unit cube split into 5 tets (type 4) with its 12 boundary triangles (type 2) in two
/// blocks, a line block (type 1) and one 10-node tet (type 11), as Gmsh 4.8 lays out MSH 4.1:
/// node lines before the $Elements section that a line-by-line reader must skip.
const std::string kCube = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 "solid $Elements"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 1 1 0 0 
1 0 0 0 1 1 1 0 1 1 
$EndEntities
$Nodes
1 8 1 8
3 1 0 8
1
2
3
4
5
6
7
8
0 0 0
1 0 0
0 1 0
1 1 0
0 0 1
1 0 1
0 1 1
1 1 1
$EndNodes
$Elements
5 20 101 120
1 1 1 2
101 1 2 
102 2 4 
2 1 2 6
103 1 2 4 
104 1 4 3 
105 5 8 6 
106 5 7 8 
107 1 5 6 
108 1 6 2 
2 1 2 6
109 3 4 8 
110 3 8 7 
111 1 3 7 
112 1 7 5 
113 2 6 8 
114 2 8 4 
3 1 4 5
115 1 2 4 6 
116 1 4 3 7 
117 1 6 5 7 
118 4 6 8 7 
119 1 4 7 6 
3 1 11 1
120 1 2 4 6 1 2 4 6 1 2 
$EndElements
)";

std::size_t tetrahedra(const std::string& text) {
  std::istringstream in(text);
  return mshTetrahedra(in, "cube.msh");
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

/// The message mshTetrahedra() throws for `text`, or "" if it throws none.
std::string mshError(const std::string& text) {
  try {
    tetrahedra(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MshTetrahedra, CountsTheFourNodeTetsOfEveryBlock) {
  EXPECT_EQ(tetrahedra(kCube), 5u);
  // Two blocks of tets (volumes 1 and 2) add up; CRLF line ends read alike.
  const std::string two = replaced(replaced(kCube, "5 20 101 120", "6 22 101 122"), "$EndElements",
                                   "3 2 4 2\n121 1 2 3 5\n122 2 3 5 6\n$EndElements");
  EXPECT_EQ(tetrahedra(two), 7u);
  std::string crlf;
  for (char c : two) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(tetrahedra(crlf), 7u);
  // No tets at all: a surface mesh.
  const std::size_t tets = kCube.find("3 1 4 5\n");
  const std::string surface =
      replaced(kCube.substr(0, tets) + "$EndElements\n", "5 20 101 120", "3 14 101 114");
  EXPECT_EQ(tetrahedra(surface), 0u);
}

TEST(MshTetrahedra, RefusesWhatItCannotCount) {
  EXPECT_NE(mshError("").find("cube.msh: not a Gmsh MSH file"), std::string::npos);
  EXPECT_NE(mshError(replaced(kCube, "4.1 0 8", "2.2 0 8")).find("MSH version 2.2"),
            std::string::npos);
  EXPECT_NE(mshError(replaced(kCube, "4.1 0 8", "4.1 1 8")).find("binary"), std::string::npos);
  const std::string noElements = kCube.substr(0, kCube.find("$Elements\n"));
  EXPECT_NE(mshError(noElements).find("no $Elements section"), std::string::npos);
  // One element more in the header than in the blocks, and one block more.
  EXPECT_NE(mshError(replaced(kCube, "5 20 101 120", "5 21 101 120"))
                .find("the element blocks hold 20 elements, $Elements says 21"),
            std::string::npos);
  EXPECT_NE(mshError(replaced(kCube, "5 20 101 120", "6 20 101 120")).find("element block 6"),
            std::string::npos);
  // Cut short inside a block, and a block header that is not four whole numbers.
  EXPECT_NE(
      mshError(kCube.substr(0, kCube.find("118 4 6 8 7"))).find("ends inside element block 4"),
      std::string::npos);
  EXPECT_NE(mshError(replaced(kCube, "3 1 4 5", "3 1 4 five")).find("element block 4"),
            std::string::npos);
  EXPECT_NE(mshError(replaced(kCube, "$EndElements", "$EndElement")).find("no $EndElements"),
            std::string::npos);
}

TEST(MshTetrahedra, ReadsAFile) {
  const polydg::testing::TempDir dir("msh_tetrahedra");
  EXPECT_EQ(mshTetrahedra(dir.write("cube.msh", kCube)), 5u);
  EXPECT_THROW(mshTetrahedra(dir.path() / "missing.msh"), InputError);
}

TEST(VtuCells, CountsTheCellsPolydgWrites) {
  const polydg::testing::TempDir dir("vtu_cells");
  const PolyMesh mesh = hexGridMesh(3, 4, 5, Box3(Vec3::Zero(), Vec3(3, 4, 5)));
  for (VtuEncoding encoding : {VtuEncoding::Appended, VtuEncoding::Binary, VtuEncoding::Ascii}) {
    const std::string file = (dir.path() / "grid.vtu").string();
    writeVtu(mesh, file, {encoding});
    EXPECT_EQ(vtuCells(std::filesystem::path(file)), 60u) << static_cast<int>(encoding);
  }
  EXPECT_THROW(vtuCells(dir.path() / "missing.vtu"), InputError);
}

TEST(VtuCells, SumsThePiecesUpToTheAppendedData) {
  // Two pieces, attributes in either quote and spread over lines; after <AppendedData>, bytes
  // that look like a third piece are raw data and not read.
  const std::string text =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n<UnstructuredGrid>\n"
      "<Piece NumberOfPoints=\"8\" NumberOfCells=\"7\">\n</Piece>\n"
      "<Piece\n  NumberOfPoints='4'\n  NumberOfCells = '12' >\n</Piece>\n"
      "<PieceData NumberOfCells=\"1000\"/>\n"
      "</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_\x01\x02<Piece NumberOfCells=\"5\">";
  std::istringstream in(text);
  EXPECT_EQ(vtuCells(in, "two.vtu"), 19u);
  std::istringstream none("<VTKFile><UnstructuredGrid/></VTKFile>");
  EXPECT_THROW(vtuCells(none, "none.vtu"), InputError);
  std::istringstream bad("<VTKFile><Piece NumberOfPoints=\"3\" NumberOfCells=\"-1\"></Piece>");
  try {
    vtuCells(bad, "bad.vtu");
    ADD_FAILURE() << "a negative count was read";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "bad.vtu: Piece 1 has no NumberOfCells that is a whole number");
  }
}

}  // namespace
}  // namespace polydg::bench
