// Tests of polydg/mesh/tet_mesh.h: tet meshes written by small writers here (VTU in three
// encodings, TetGen with index base 0 and 1, Gmsh MSH 4.1), by writeTetVtu and by the real tools
// (testdata/), read back alike; conversion to a PolyMesh; and each refusal naming the element at
// fault.
#include "polydg/mesh/tet_mesh.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/primitives.h"
#include "mesh/vtk_format.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/util/error.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;
using Tet = std::array<std::uint32_t, 4>;

/// Volumes here are sums of a few dozen exact sixths: they agree to round-off.
constexpr double kTetVolumeTolerance = 1e-14;

// ============================================================================================
// Meshes
// ============================================================================================

double volume(const TetMesh& mesh) {
  double six = 0.0;
  for (std::size_t t = 0; t < mesh.numTets(); ++t) six += sixVolume(mesh, t);
  return six / 6.0;
}

/// Index of point p in `mesh`, added if new.
std::uint32_t vertexAt(TetMesh& mesh, const Vec3& p) {
  const auto found = std::find(mesh.vertices.begin(), mesh.vertices.end(), p);
  if (found != mesh.vertices.end())
    return static_cast<std::uint32_t>(found - mesh.vertices.begin());
  mesh.vertices.push_back(p);
  return static_cast<std::uint32_t>(mesh.vertices.size() - 1);
}

/// The six tets of Kuhn's split of the unit cube at `corner` (paths from the corner to the
/// opposite one, one axis at a time), corners in path order: three of them are negatively
/// oriented. The split is the same in every cube, so neighbouring cubes share their faces.
void addKuhnCube(TetMesh& mesh, const Vec3& corner) {
  std::array<int, 3> axes = {0, 1, 2};
  do {
    Vec3 p = corner;
    Tet tet{};
    tet[0] = vertexAt(mesh, p);
    for (std::size_t k = 0; k < 3; ++k) {
      p[axes[k]] += 1.0;
      tet[k + 1] = vertexAt(mesh, p);
    }
    mesh.tets.push_back(tet);
  } while (std::next_permutation(axes.begin(), axes.end()));
}

/// The 2 x 2 x 2 unit cubes of [0,2]^3 in Kuhn's split: 27 vertices, 48 tets of mixed
/// orientation.
TetMesh kuhnCubes() {
  TetMesh mesh;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) addKuhnCube(mesh, Vec3(i, j, k));
  return mesh;
}

/// The 2 x 2 x 2 unit cubes of [0,2]^3 in 5 tets each: a middle tet on the four corners of one
/// parity and a tet at each other corner. With `alternate`, the parity is the corners' global
/// one (x + y + z even), so neighbours split their common face by the same diagonal; without,
/// each cube uses its local parity and neighbours' diagonals cross.
TetMesh fiveTetCubes(bool alternate) {
  TetMesh mesh;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const Vec3 o(i, j, k);
        const int flip = alternate ? (i + j + k) % 2 : 0;
        std::vector<Vec3> even, odd;
        for (int c = 0; c < 8; ++c) {
          const Vec3 p = o + Vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
          (((c & 1) + ((c >> 1) & 1) + ((c >> 2) & 1) + flip) % 2 == 0 ? even : odd).push_back(p);
        }
        mesh.tets.push_back({vertexAt(mesh, even[0]), vertexAt(mesh, even[1]),
                             vertexAt(mesh, even[2]), vertexAt(mesh, even[3])});
        for (const Vec3& corner : odd) {
          Tet tet{vertexAt(mesh, corner), 0, 0, 0};
          std::size_t n = 1;
          for (const Vec3& e : even)
            if ((e - corner).lpNorm<1>() == 1.0) tet[n++] = vertexAt(mesh, e);
          mesh.tets.push_back(tet);
        }
      }
  return mesh;
}

/// The unit cube [0,1]^3 in Kuhn's split beside the cube [1,2] x [0,1]^2 split into a fan of
/// tets from its centre over its faces' triangles. Its face on x = 1 is split into the 4
/// triangles about `m` (a point of that face, not on its border), or, if `m` is not given, by
/// the diagonal the first cube uses there: then the mesh conforms.
TetMesh twoCubes(const Vec3* m) {
  TetMesh mesh;
  addKuhnCube(mesh, Vec3(0, 0, 0));
  const std::uint32_t centre = vertexAt(mesh, Vec3(1.5, 0.5, 0.5));
  auto fan = [&](const std::vector<Vec3>& triangle) {
    mesh.tets.push_back({vertexAt(mesh, triangle[0]), vertexAt(mesh, triangle[1]),
                         vertexAt(mesh, triangle[2]), centre});
  };
  // Each quad's corners in order around it; the first corner starts the diagonal.
  const std::vector<std::vector<Vec3>> quads = {{{2, 0, 0}, {2, 1, 0}, {2, 1, 1}, {2, 0, 1}},
                                                {{1, 0, 0}, {2, 0, 0}, {2, 0, 1}, {1, 0, 1}},
                                                {{1, 1, 0}, {2, 1, 0}, {2, 1, 1}, {1, 1, 1}},
                                                {{1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}},
                                                {{1, 0, 1}, {2, 0, 1}, {2, 1, 1}, {1, 1, 1}}};
  for (const auto& q : quads) {
    fan({q[0], q[1], q[2]});
    fan({q[0], q[2], q[3]});
  }
  const std::vector<Vec3> side = {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}};
  if (m) {
    for (std::size_t i = 0; i < 4; ++i) fan({side[i], side[(i + 1) % 4], *m});
  } else {  // Kuhn's diagonal on x = 1 runs from (1,0,0) to (1,1,1)
    fan({side[0], side[1], side[2]});
    fan({side[0], side[2], side[3]});
  }
  return mesh;
}

/// `mesh` with each negatively oriented tet's last two corners swapped.
TetMesh oriented(TetMesh mesh) {
  for (std::size_t t = 0; t < mesh.numTets(); ++t)
    if (sixVolume(mesh, t) < 0) std::swap(mesh.tets[t][2], mesh.tets[t][3]);
  return mesh;
}

/// Each tet as its corners' positions, sorted: the same for two meshes with the same tets in
/// the same order, whatever their vertex numbering and corner order.
std::vector<std::vector<std::array<double, 3>>> tetPositions(const TetMesh& mesh) {
  std::vector<std::vector<std::array<double, 3>>> out;
  for (const Tet& tet : mesh.tets) {
    std::vector<std::array<double, 3>> corners;
    for (std::uint32_t v : tet)
      corners.push_back({mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()});
    std::sort(corners.begin(), corners.end());
    out.push_back(corners);
  }
  return out;
}

/// Expects `read` to be `source` read back: the same tets in the same order, positively
/// oriented, and with a tet's corners in the file's order when the file had it positive.
void expectSameTets(const TetMesh& source, const TetMesh& read) {
  ASSERT_EQ(read.numTets(), source.numTets());
  EXPECT_EQ(tetPositions(read), tetPositions(source));
  for (std::size_t t = 0; t < read.numTets(); ++t) {
    EXPECT_GT(sixVolume(read, t), 0.0) << "tet " << t;
    if (sixVolume(source, t) > 0) {
      for (std::size_t k = 0; k < 4; ++k)
        EXPECT_EQ(read.vertices[read.tets[t][k]], source.vertices[source.tets[t][k]]) << t;
    }
  }
}

// ============================================================================================
// Checks and PolyMesh
// ============================================================================================

/// Expects `message` to be one line holding each of `parts`.
void expectMentions(const std::string& message, std::initializer_list<std::string> parts) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  for (const std::string& part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

/// The message of the InputError that checkTetMesh throws, or "" (and a failure) if none.
std::string checkError(const TetMesh& mesh) {
  try {
    checkTetMesh(mesh);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "checkTetMesh accepted the mesh";
  return "";
}
/// Vertices 0-3 a tet on the triangle (0, 1, 2) in z = 0; 4 below it, 5 above it, 6 in its
/// plane (TetGen nodes 1-7 when written with index base 1).
const TetMesh kFan = {
    {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, 1}, {0.2, 0.2, -1}, {0.3, 0.3, 2}, {2, 2, 0}}, {}};

TEST(TetMeshCheck, NamesBadTetsByIndex) {
  // Without a file, tets and vertices are named by their 0-based indices.
  TetMesh mesh = kFan;
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 9}};
  expectMentions(checkError(mesh), {"tet 1 has corner index 9", "7 vertices", "fix"});
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 1}};
  expectMentions(checkError(mesh), {"tet 1 has vertex 1 as two of its corners"});
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 6}};
  expectMentions(checkError(mesh), {"tet 1 is flat", "vertex 6"});
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};
  expectMentions(checkError(mesh), {"tet 1 is inverted", "swap two of its corners"});
}

TEST(TetMeshCheck, RefusesNonConformingMeshes) {
  for (const TetMesh& conforming :
       {oriented(kuhnCubes()), oriented(fiveTetCubes(true)), oriented(twoCubes(nullptr))})
    EXPECT_NO_THROW(checkTetMesh(conforming));
  TetMesh mesh = kFan;
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 1, 2, 5}};
  expectMentions(checkError(mesh),
                 {"the face (vertex 0, vertex 2, vertex 1) belongs to 3 tets (tet 0, tet 1 and "
                  "tet 2)"});
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 5, 1}};
  expectMentions(checkError(mesh), {"tet 0 and tet 1 lie on the same side of their common face"});
  const Vec3 inFace(1, 0.5, 0.25);
  expectMentions(checkError(oriented(twoCubes(&inFace))),
                 {"vertex 13 lies inside the boundary face (vertex 1, vertex 2, vertex 3) of "
                  "tet 0"});
  expectMentions(checkError(oriented(fiveTetCubes(false))),
                 {"of tet", "overlaps the boundary face", "T-junction"});
}

TEST(TetMeshCheck, RefusesEveryTetWhoseVolumeComputesNonPositive) {
  // Tets with a corner put in the plane of the other three, then rounded: their exact volume
  // is tiny, of either sign or zero, and sixVolume's rounded one may differ in sign. Whatever
  // the exact sign, none whose computed volume is not positive may pass.
  constexpr std::uint64_t kSeed = 1;
  SCOPED_TRACE("seed " + std::to_string(kSeed));
  std::mt19937_64 random(kSeed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  auto point = [&] { return Vec3(uniform(random), uniform(random), uniform(random)); };
  std::size_t tooThin = 0;
  for (int i = 0; i < 2000; ++i) {
    TetMesh mesh;
    const Vec3 a = point(), b = point(), c = point();
    mesh.vertices = {a, b, c, a + uniform(random) * (b - a) + uniform(random) * (c - a)};
    mesh.tets = {{0, 1, 2, 3}};
    if (sixVolume(mesh, 0) > 0) continue;
    const std::string message = checkError(mesh);
    if (message.find("too thin for double precision") != std::string::npos) ++tooThin;
  }
  // Some are exactly positive but compute as not: the check's last test, not CGAL's, refuses
  // those.
  EXPECT_GT(tooThin, 0u);
}

TEST(TetMeshToPolyMesh, SharesFacesAndPassesCheckGeometry) {
  struct Case {
    std::string name;
    TetMesh mesh;
    std::size_t interior;
  };
  // Both split each of 24 unit squares on the outside in 2 triangles: 48 boundary faces.
  for (const Case& c : {Case{"kuhn", oriented(kuhnCubes()), (4 * 48 - 48) / 2},
                        Case{"five", oriented(fiveTetCubes(true)), (4 * 40 - 48) / 2}}) {
    SCOPED_TRACE(c.name);
    checkTetMesh(c.mesh);
    const PolyMesh poly = toPolyMesh(c.mesh);
    const GeometryCheck check = checkGeometry(poly);
    EXPECT_TRUE(check.passed) << (check.messages.empty() ? "" : check.messages[0]);
    EXPECT_EQ(check.elements, c.mesh.numTets());
    EXPECT_EQ(check.interiorFaces, c.interior);
    EXPECT_EQ(check.boundaryFaces, 48u);
    EXPECT_EQ(check.components, 1u);
    EXPECT_NEAR(check.volume, 8.0, kTetVolumeTolerance);
    EXPECT_NEAR(volume(c.mesh), 8.0, kTetVolumeTolerance);
    EXPECT_EQ(poly.numVertices(), c.mesh.numVertices());
    for (std::size_t f = 0; f < poly.numFaces(); ++f) {
      const Face& face = poly.face(FaceId(f));
      EXPECT_EQ(face.vertices.size(), 3u);
      EXPECT_EQ(face.origin, face.isBoundary() ? FaceOrigin::Surface : FaceOrigin::Interior);
    }
    for (std::size_t t = 0; t < c.mesh.numTets(); ++t) {
      const Element& element = poly.element(ElementId(t));
      ASSERT_EQ(element.faces.size(), 4u);
      // Face k is opposite corner k: it holds the other three.
      for (std::size_t k = 0; k < 4; ++k)
        for (VertexId v : poly.face(element.faces[k].face).vertices)
          EXPECT_NE(v.value, c.mesh.tets[t][k]);
    }
  }
}

TEST(TetMeshFromPolyMesh, GivesBackToPolyMeshsTetsAndRefusesOtherElements) {
  for (const TetMesh& mesh : {oriented(kuhnCubes()), oriented(fiveTetCubes(true))}) {
    PolyMesh poly = toPolyMesh(mesh);
    poly.addVertex(Vec3(9.0, 9.0, 9.0));  // used by no element: dropped
    const TetMesh back = toTetMesh(poly);
    ASSERT_EQ(back.numTets(), mesh.numTets());
    EXPECT_EQ(back.vertices, mesh.vertices);
    for (std::size_t t = 0; t < mesh.numTets(); ++t) {
      // The same apex, and the opposite face's corners in the same cyclic order.
      const auto& a = mesh.tets[t];
      const auto& b = back.tets[t];
      EXPECT_EQ(b[0], a[0]);
      const int shift = static_cast<int>(std::find(b.begin() + 1, b.end(), a[1]) - b.begin()) - 1;
      ASSERT_LT(shift, 3);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(b[1 + (shift + k) % 3], a[1 + k]) << "tet " << t;
    }
  }
  try {
    toTetMesh(boxMesh(Box3(Vec3::Zero(), Vec3::Ones())));
    ADD_FAILURE() << "a hexahedron was taken for a tet";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("element 0 (6 faces, 8 corners) is not a tetrahedron"),
              std::string::npos)
        << e.what();
  }
}

// ============================================================================================
// Writers
// ============================================================================================

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Writes `value` as it reads back exactly.
std::string number(double value) {
  std::ostringstream s;
  s.precision(17);
  s << value;
  return s.str();
}

std::string xyz(const Vec3& p) { return number(p.x()) + " " + number(p.y()) + " " + number(p.z()); }

/// The nodes and tets a file lists for `mesh`: its vertices and corners, with `tenNodes` also a
/// node at each edge's middle per tet (after the corners, in the order 01 02 03 12 13 23).
std::pair<std::vector<Vec3>, std::vector<std::vector<std::size_t>>> fileNodes(const TetMesh& mesh,
                                                                              bool tenNodes) {
  std::vector<Vec3> nodes = mesh.vertices;
  std::vector<std::vector<std::size_t>> tets;
  for (const Tet& t : mesh.tets) {
    std::vector<std::size_t> tet(t.begin(), t.end());
    if (tenNodes)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          tet.push_back(nodes.size());
          nodes.push_back(0.5 * (mesh.vertices[t[a]] + mesh.vertices[t[b]]));
        }
    tets.push_back(tet);
  }
  return {nodes, tets};
}

struct TetgenOptions {
  int base = 1;
  bool tenNodes = false;  ///< tets with 10 nodes: the corners, then 6 extra (mid-edge) nodes
  bool extras = false;    ///< comments, blank lines, attributes, markers, region attributes
};

/// Writes STEM.node and STEM.ele; returns STEM.ele.
fs::path writeTetgen(const fs::path& stem, const TetMesh& mesh, const TetgenOptions& o = {}) {
  auto [nodes, tets] = fileNodes(mesh, o.tenNodes);
  const std::string comment = o.extras ? "  # a comment\n# a line of comment\n\n" : "\n";
  std::string node = std::to_string(nodes.size()) + " 3 " + (o.extras ? "1 1" : "0 0") + comment;
  for (std::size_t i = 0; i < nodes.size(); ++i)
    node += std::to_string(o.base + static_cast<int>(i)) + "  " + xyz(nodes[i]) +
            (o.extras ? " 0.5 " + std::to_string(i % 2) + comment : "\n");
  std::string ele = std::to_string(tets.size()) + (o.tenNodes ? " 10 " : " 4 ") +
                    (o.extras ? "1" : "0") + comment;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    ele += std::to_string(o.base + static_cast<int>(t));
    for (std::size_t v : tets[t]) ele += " " + std::to_string(o.base + static_cast<int>(v));
    ele += o.extras ? " -2.5" + comment : "\n";
  }
  writeText(fs::path(stem).concat(".node"), node);
  const fs::path elePath = fs::path(stem).concat(".ele");
  writeText(elePath, ele + "# Written by tet_mesh_test\n");
  return elePath;
}

struct MshOptions {
  bool tenNodes = false;      ///< element type 11, with 6 extra nodes each
  bool scrambled = false;     ///< node tags not contiguous nor sorted, in two blocks (one
                              ///< parametric), an extra node, points, lines and triangles
  std::int64_t firstTag = 1;  ///< the first tet's element tag; the others follow
};

/// A Gmsh MSH 4.1 ASCII file of `mesh`.
std::string mshText(const TetMesh& mesh, const MshOptions& o = {}) {
  auto [nodes, tets] = fileNodes(mesh, o.tenNodes);
  const std::size_t extra = nodes.size();  // a node only a point element uses
  if (o.scrambled) nodes.push_back(Vec3(5, 5, 5));
  auto tag = [&](std::size_t i) {
    return std::to_string(o.scrambled ? 1000 + 7 * (nodes.size() - i) : i + 1);
  };
  // Nodes in two blocks: the first a point entity, the second a volume with parametric
  // coordinates when scrambled.
  const std::size_t split = o.scrambled ? nodes.size() / 2 : nodes.size();
  std::string text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  if (o.scrambled) text += "$PhysicalNames\n1\n3 1 \"volume\"\n$EndPhysicalNames\n";
  text += "$Nodes\n" + std::to_string(o.scrambled ? 2 : 1) + " " + std::to_string(nodes.size()) +
          " 1 " + std::to_string(nodes.size() + 2000) + "\n";
  auto block = [&](std::size_t begin, std::size_t end, int dim, bool parametric) {
    text += std::to_string(dim) + " 1 " + (parametric ? "1 " : "0 ") + std::to_string(end - begin) +
            "\n";
    for (std::size_t i = begin; i < end; ++i) text += tag(i) + "\n";
    for (std::size_t i = begin; i < end; ++i)
      text += xyz(nodes[i]) + (parametric ? " 0.25 0.5 0.75\n" : "\n");
  };
  block(0, split, o.scrambled ? 0 : 3, false);
  if (o.scrambled) block(split, nodes.size(), 3, true);
  text += "$EndNodes\n$Elements\n";
  const std::size_t lower = o.scrambled ? 3 : 0;  // a point, a line, a triangle
  const std::int64_t after = o.firstTag + static_cast<std::int64_t>(tets.size());
  text += std::to_string(1 + lower) + " " + std::to_string(tets.size() + lower) + " " +
          std::to_string(o.firstTag) + " " + std::to_string(after + 2) + "\n";
  if (o.scrambled) {
    text += "0 1 15 1\n" + std::to_string(after) + " " + tag(extra) + "\n";
    text += "1 1 1 1\n" + std::to_string(after + 1) + " " + tag(0) + " " + tag(1) + "\n";
    text +=
        "2 1 2 1\n" + std::to_string(after + 2) + " " + tag(0) + " " + tag(1) + " " + tag(2) + "\n";
  }
  text += "3 1 " + std::string(o.tenNodes ? "11 " : "4 ") + std::to_string(tets.size()) + "\n";
  for (std::size_t t = 0; t < tets.size(); ++t) {
    text += std::to_string(o.firstTag + static_cast<std::int64_t>(t));
    for (std::size_t v : tets[t]) text += " " + tag(v);
    text += "\n";
  }
  return text + "$EndElements\n";
}

enum class VtuEncoding { Ascii, Binary, Appended };

/// A VTU file of `mesh` with VTK_TETRA cells, or the cell types `types` if given.
std::string vtuText(const TetMesh& mesh, VtuEncoding encoding, std::vector<int> types = {}) {
  if (types.empty()) types.assign(mesh.numTets(), 10);
  std::vector<double> points;
  for (const Vec3& p : mesh.vertices) points.insert(points.end(), {p.x(), p.y(), p.z()});
  std::vector<std::int64_t> connectivity, offsets;
  for (const Tet& t : mesh.tets) {
    connectivity.insert(connectivity.end(), t.begin(), t.end());
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
  }
  std::vector<std::uint8_t> typeBytes(types.begin(), types.end());
  std::string appended;
  auto array = [&](const std::string& type, const std::string& name, int components,
                   const auto& values) {
    std::string head = "<DataArray type=\"" + type + "\" Name=\"" + name +
                       "\" NumberOfComponents=\"" + std::to_string(components) + "\" format=\"";
    if (encoding == VtuEncoding::Ascii) {
      std::string body;
      for (const auto& v : values)
        body += " " + (type == "Float64" ? number(v) : std::to_string(+v));
      return head + "ascii\">" + body + "</DataArray>\n";
    }
    const std::uint64_t size = values.size() * sizeof(values[0]);
    std::string bytes(reinterpret_cast<const char*>(&size), 8);
    bytes.append(reinterpret_cast<const char*>(values.data()), size);
    if (encoding == VtuEncoding::Binary)
      return head + "binary\">" + vtk_format::base64Encode(bytes) + "</DataArray>\n";
    head += "appended\" offset=\"" + std::to_string(appended.size()) + "\"/>\n";
    appended += bytes;
    return head;
  };
  std::string text =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<Piece "
      "NumberOfPoints=\"" +
      std::to_string(mesh.numVertices()) + "\" NumberOfCells=\"" + std::to_string(mesh.numTets()) +
      "\">\n<Points>\n" + array("Float64", "Points", 3, points) + "</Points>\n<Cells>\n" +
      array("Int64", "connectivity", 1, connectivity) + array("Int64", "offsets", 1, offsets) +
      array("UInt8", "types", 1, typeBytes) + "</Cells>\n</Piece>\n</UnstructuredGrid>\n";
  if (encoding == VtuEncoding::Appended)
    text += "<AppendedData encoding=\"raw\">\n_" + appended + "\n</AppendedData>\n";
  return text + "</VTKFile>\n";
}

// ============================================================================================
// Fixture
// ============================================================================================

/// A scratch folder per test, removed at the end.
class TetMeshRead : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("polydg_tet_mesh_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path file(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    writeText(path, text);
    return path;
  }

  fs::path dir_;
};

/// The message of the InputError that reading `path` throws, or "" (and a failure) if none.
std::string readError(const fs::path& path) {
  try {
    readTetMesh(path.string());
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " was read without an error";
  return "";
}

// ============================================================================================
// Reading
// ============================================================================================

TEST_F(TetMeshRead, CubesReadAlikeFromEveryFormat) {
  const TetMesh cubes = kuhnCubes();
  ASSERT_EQ(cubes.numVertices(), 27u);
  ASSERT_EQ(cubes.numTets(), 48u);
  // Half the tets are written negatively oriented: the readers must turn them.
  EXPECT_NEAR(volume(cubes), 0.0, kTetVolumeTolerance);
  std::map<std::string, fs::path> files = {
      {"vtu ascii", file("ascii.vtu", vtuText(cubes, VtuEncoding::Ascii))},
      {"vtu binary", file("binary.vtu", vtuText(cubes, VtuEncoding::Binary))},
      {"vtu appended", file("appended.VTU", vtuText(cubes, VtuEncoding::Appended))},
      {"tetgen base 0", writeTetgen(dir_ / "base0", cubes, {.base = 0})},
      {"tetgen base 1", writeTetgen(dir_ / "base1.1", cubes, {.base = 1})},
      {"msh", file("cubes.msh", mshText(cubes))}};
  for (const auto& [format, path] : files) {
    SCOPED_TRACE(format);
    const TetMesh read = readTetMesh(path.string());
    EXPECT_EQ(read.vertices, cubes.vertices);
    expectSameTets(cubes, read);
    EXPECT_NEAR(volume(read), 8.0, kTetVolumeTolerance);
  }
}

TEST_F(TetMeshRead, WrittenVtuReadsBackBitForBit) {
  // writeTetVtu's file in each encoding: the same vertices (coordinates that are no short
  // decimals, far from the origin) and the same tets, corner for corner.
  TetMesh cubes = oriented(kuhnCubes());
  for (Vec3& p : cubes.vertices) p = p * (1.0 / 3.0) + Vec3(1e6 / 7.0, -0.1, 1e-7);
  // polydg::VtuEncoding, the writer's (VtuEncoding here is this file's writer's).
  for (const polydg::VtuEncoding encoding :
       {polydg::VtuEncoding::Ascii, polydg::VtuEncoding::Binary, polydg::VtuEncoding::Appended}) {
    const fs::path path = dir_ / ("written" + std::to_string(static_cast<int>(encoding)) + ".vtu");
    VtuFieldData fields;
    fields.numbers["cell"] = {0.5};
    writeTetVtu(cubes, path.string(), {.encoding = encoding}, fields);
    const TetMesh read = readTetMesh(path.string());
    EXPECT_EQ(read.vertices, cubes.vertices);
    EXPECT_EQ(read.tets, cubes.tets);
    EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  }
  TetMesh broken = cubes;
  broken.tets[3][2] = 27;
  EXPECT_THROW(writeTetVtu(broken, (dir_ / "broken.vtu").string()), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir_ / "broken.vtu"));
}

TEST_F(TetMeshRead, InvertedTetsAreReoriented) {
  TetMesh inverted = oriented(kuhnCubes());
  for (Tet& t : inverted.tets) std::swap(t[0], t[1]);
  const TetMesh read = readTetMesh(writeTetgen(dir_ / "inverted", inverted).string());
  expectSameTets(inverted, read);
  for (std::size_t t = 0; t < read.numTets(); ++t) {
    // The last two corners swapped, the first two as written.
    EXPECT_EQ(read.tets[t][0], inverted.tets[t][0]);
    EXPECT_EQ(read.tets[t][2], inverted.tets[t][3]);
  }
  EXPECT_NEAR(volume(read), 8.0, kTetVolumeTolerance);
}

TEST_F(TetMeshRead, TetgenCommentsAttributesAndTenNodeTets) {
  const TetMesh cubes = kuhnCubes();
  for (int base : {0, 1}) {
    SCOPED_TRACE(base);
    const fs::path ele = writeTetgen(dir_ / ("extras" + std::to_string(base)), cubes,
                                     {.base = base, .tenNodes = true, .extras = true});
    ASSERT_NE(readText(ele).find("# a comment"), std::string::npos);
    const TetMesh read = readTetMesh(ele.string());
    // The mid-edge nodes are no tet's corners: they are dropped.
    EXPECT_EQ(read.vertices, cubes.vertices);
    expectSameTets(cubes, read);
  }
  // As in TetGen, the headers may stop after the counts.
  const fs::path ele = writeTetgen(dir_ / "short", cubes);
  for (const fs::path& path : {ele, dir_ / "short.node"}) {
    const std::string text = readText(path);
    writeText(path, text.substr(0, text.find(' ')) + text.substr(text.find('\n')));
  }
  ASSERT_EQ(readText(ele).substr(0, 3), "48\n");
  expectSameTets(cubes, readTetMesh(ele.string()));
}

TEST_F(TetMeshRead, GmshNonContiguousTagsMixedElementsAndTenNodeTets) {
  const TetMesh cubes = kuhnCubes();
  for (bool tenNodes : {false, true}) {
    SCOPED_TRACE(tenNodes);
    const std::string text = mshText(cubes, {.tenNodes = tenNodes, .scrambled = true});
    ASSERT_NE(text.find("\n2 1 2 1\n"), std::string::npos);  // a triangle block
    const TetMesh read = readTetMesh(file("scrambled.msh", text).string());
    EXPECT_EQ(read.vertices, cubes.vertices);
    expectSameTets(cubes, read);
  }
}

TEST_F(TetMeshRead, ReadsFilesMadeByTetgenAndGmsh) {
  // testdata/cube_tets.*: the unit cube meshed by TetGen 1.5 and Gmsh 4.8 (how to make them
  // again is in cube_tets.poly and cube_tets.geo).
  const std::string data = POLYDG_TESTDATA_DIR;
  for (const std::string name : {"cube_tets.1.ele", "cube_tets.msh"}) {
    SCOPED_TRACE(name);
    const TetMesh mesh = readTetMesh(data + "/" + name);
    EXPECT_GT(mesh.numTets(), 20u);
    EXPECT_NEAR(volume(mesh), 1.0, kTetVolumeTolerance);
    const GeometryCheck check = checkGeometry(toPolyMesh(mesh));
    EXPECT_TRUE(check.passed) << (check.messages.empty() ? "" : check.messages[0]);
    EXPECT_NEAR(check.volume, 1.0, kTetVolumeTolerance);
  }
}

// ============================================================================================
// Refusals
// ============================================================================================

TEST_F(TetMeshRead, RefusesAFlatTet) {
  TetMesh mesh = kFan;
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 6}};
  const fs::path ele = writeTetgen(dir_ / "flat", mesh);
  expectMentions(readError(ele), {ele.string() + ": ", "tet 2 is flat", "node 7", "remesh"});
}

TEST_F(TetMeshRead, RefusesARepeatedCorner) {
  TetMesh mesh = kFan;
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 1}};
  const fs::path msh = file("repeated.msh", mshText(mesh, {.firstTag = 76}));
  expectMentions(readError(msh), {msh.string() + ": ", "element 77 has node 2 as two"});
}

TEST_F(TetMeshRead, RefusesIndicesOutOfRange) {
  TetMesh mesh = kFan;
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 9}};
  const fs::path ele = writeTetgen(dir_ / "range", mesh);
  expectMentions(readError(ele), {ele.string() + ":3: tet 2 refers to node 10", "1 to 7"});
  const std::string msh = mshText(mesh);
  const fs::path mshPath =
      file("range.msh", msh.substr(0, msh.rfind(" 10\n")) + " 99\n" + "$EndElements\n");
  expectMentions(readError(mshPath), {"element 2 refers to node 99", "$Nodes does not define"});
  const fs::path vtu = file("range.vtu", vtuText(mesh, VtuEncoding::Ascii));
  expectMentions(readError(vtu), {vtu.string() + ": cell 1 refers to point 9"});
  const fs::path zero = dir_ / "zero.ele";
  writeTetgen(dir_ / "zero", kFan);
  writeText(zero, "1 4 0\n1 0 1 2 3\n");
  expectMentions(readError(zero), {"tet 1 refers to node 0", "1 to 7"});
}

TEST_F(TetMeshRead, RefusesAFaceOfThreeTetsAndTetsOnOneSide) {
  TetMesh mesh = kFan;
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 1, 2, 5}};
  const fs::path three = writeTetgen(dir_ / "three", mesh);
  expectMentions(
      readError(three),
      {three.string() + ": the face (node 1, node 3, node 2) belongs to 3 tets (tet 1, tet 2 "
                        "and tet 3)"});
  // Tets 1 and 3 alone overlap: orienting each tet on its own must not hide that.
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 1, 5}};
  const fs::path side = writeTetgen(dir_ / "side", mesh);
  expectMentions(readError(side), {"tet 1 and tet 2 lie on the same side of their common face"});
}

TEST_F(TetMeshRead, RefusesAHangingVertex) {
  // The control: the same cubes sharing whole faces.
  EXPECT_NO_THROW(readTetMesh(writeTetgen(dir_ / "conforming", twoCubes(nullptr)).string()));
  const Vec3 inFace(1, 0.5, 0.25), onEdge(1, 0.5, 0.5);
  for (const Vec3* m : {&inFace, &onEdge}) {
    const fs::path ele = writeTetgen(dir_ / "hanging", twoCubes(m));
    // Node 14 is m; nodes 2, 3 and 4 are (1,0,0), (1,1,0) and (1,1,1), tet 1's side on x = 1.
    expectMentions(readError(ele),
                   {ele.string() + ": node 14 lies inside " + (m == &onEdge ? "an edge of " : "") +
                        "the boundary face (node 2, node 3, node 4) of tet 1",
                    "T-junction", "remesh"});
  }
}

TEST_F(TetMeshRead, RefusesFacesSplitByCrossingDiagonals) {
  EXPECT_NO_THROW(checkTetMesh(oriented(fiveTetCubes(true))));
  const fs::path msh = file("crossing.msh", mshText(fiveTetCubes(false)));
  expectMentions(readError(msh), {"boundary face (node", "of element", "overlaps the boundary face",
                                  "different diagonals", "T-junction"});
}

TEST_F(TetMeshRead, RefusesNonTetCellsAndElements) {
  const TetMesh cubes = kuhnCubes();
  std::vector<int> types(cubes.numTets(), 10);
  types[5] = 12;
  const fs::path vtu = file("hex.vtu", vtuText(cubes, VtuEncoding::Appended, types));
  expectMentions(readError(vtu), {"cell 5 has VTK type 12", "VTK_TETRA"});
  std::string msh = mshText(cubes);
  msh.replace(msh.find("3 1 4 48\n"), 9, "3 1 5 48\n");
  expectMentions(readError(file("hex.msh", msh)), {"element 1 has type 5", "type 4"});
}

TEST_F(TetMeshRead, RefusesTruncatedFiles) {
  TetMesh cubes;  // one cube, so that cutting at every byte stays quick
  addKuhnCube(cubes, Vec3(0, 0, 0));
  // Every cut short of the data's end, in each format. (A TetGen file has no end marker: cut in
  // its last number, it would read as a shorter number, so the cuts stop before that line.)
  const std::string ele = readText(writeTetgen(dir_ / "whole", cubes));
  const std::string node = readText(dir_ / "whole.node");
  struct Case {
    std::string name, text;
    std::size_t end;
  };
  const std::string msh = mshText(cubes), vtu = vtuText(cubes, VtuEncoding::Appended);
  const std::size_t lastTet = ele.rfind('\n', ele.rfind("\n#") - 1);
  // Each case cuts one file; a TetGen pair is read through its .ele with the other file whole.
  const std::vector<Case> cases = {{"cut.ele", ele, lastTet},
                                   {"cut.node", node, node.rfind('\n', node.size() - 2)},
                                   {"cut.msh", msh, msh.size() - 1},
                                   {"cut.vtu", vtu, vtu.find("\n</AppendedData>")}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    if (c.name == "cut.ele") writeText(dir_ / "cut.node", node);
    if (c.name == "cut.node") writeText(dir_ / "cut.ele", ele);
    std::size_t refused = 0;
    for (std::size_t size = 0; size < c.end; ++size) {
      // Removed first: overwriting a file in place can make the file system flush it each time.
      fs::remove(dir_ / c.name);
      writeText(dir_ / c.name, c.text.substr(0, size));
      try {
        readTetMesh((dir_ / (c.name == "cut.node" ? "cut.ele" : c.name)).string());
        ADD_FAILURE() << "a cut after " << size << " bytes was read";
      } catch (const InputError& e) {
        ++refused;
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      }
    }
    EXPECT_EQ(refused, c.end);
  }
  expectMentions(readError(file("short.msh", msh.substr(0, msh.find("\n$EndElements")))),
                 {"short.msh:", "the file ends before '$EndElements'", "truncated"});
}

TEST_F(TetMeshRead, RefusesBadFieldsAndCounts) {
  const TetMesh cubes = kuhnCubes();
  const fs::path ele = writeTetgen(dir_ / "fields", cubes);
  const std::string text = readText(ele);
  writeText(ele, "49" + text.substr(2));
  expectMentions(readError(ele), {"fields.ele:", "the file ends before tet 49", "truncated"});
  writeText(ele, "47" + text.substr(2));
  expectMentions(readError(ele), {"fields.ele:49: a line after the 47 tets"});
  writeText(ele, text.substr(0, text.find("\n3 ")) + "\nx " + text.substr(text.find("\n3 ") + 3));
  expectMentions(readError(ele), {"fields.ele:4: the tet index 'x' is not an integer"});
  writeText(ele, text.substr(0, text.find("\n3 ")) + "\n5 " + text.substr(text.find("\n3 ") + 3));
  expectMentions(readError(ele), {"fields.ele:4: the tet index is 5 where 3 comes next"});
  const std::string node = readText(dir_ / "fields.node");
  writeText(dir_ / "fields.node", node.substr(0, node.find("\n2 ")) + "\n2 1.0 nan 0" +
                                      node.substr(node.find('\n', node.find("\n2 ") + 1)));
  writeText(ele, text);
  expectMentions(readError(ele), {"fields.node:3: node 2: y 'nan' is not a number; fix it"});
  fs::remove(dir_ / "fields.node");
  expectMentions(readError(ele), {"fields.node: cannot open"});
  // One element more than the $Elements header counts.
  std::string msh = mshText(cubes);
  msh.insert(msh.find("$EndElements"), "49 1 2 3 4\n");
  expectMentions(
      readError(file("extra.msh", msh)),
      {"extra.msh:", "expected '$EndElements' after the elements, found '49'", "write it again"});
}

TEST_F(TetMeshRead, RefusesBinaryAndOtherMshVersions) {
  // A binary file's header: the version line, then the integer 1 in the file's byte order.
  const char header[] = "$MeshFormat\n4.1 1 8\n\x01\0\0\0\n$EndMeshFormat\n";
  const fs::path binary = file("binary.msh", std::string(header, sizeof header - 1));
  expectMentions(readError(binary),
                 {"binary.msh:2: a binary MSH file", "gmsh FILE -save -format msh41"});
  const fs::path old = file("old.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
  expectMentions(readError(old), {"old.msh:2: MSH version '2.2'", "-format msh41"});
  const fs::path empty = file("empty.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
  expectMentions(readError(empty), {"holds no tetrahedra", "gmsh -3"});
}

TEST_F(TetMeshRead, RefusesUnknownExtensions) {
  const fs::path stl = file("cube.stl", "solid\n");
  expectMentions(readError(stl),
                 {stl.string() + ": unknown tet mesh extension '.stl'", ".vtu", ".ele", ".msh"});
  expectMentions(readError(file("cube", "")), {"'(none)'"});
}

}  // namespace
}  // namespace polydg
