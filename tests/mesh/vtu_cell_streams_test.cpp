// Tests of mesh/vtu_cell_streams.h: the generated cell arrays hold the layout polydg/mesh/vtu_io.h
// describes (checked against arrays built whole from the mesh, as the writer once held them),
// their largest values are their largest values, and chunks that start and end inside cells
// write the bytes one chunk writes, in every encoding.
#include "mesh/vtu_cell_streams.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/face_triangulation.h"
#include "mesh/vtk_cell_types.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/vtu_encodings.h"
#include "tests/support/vtu_meshes.h"

namespace polydg {
namespace {

using vtk_format::ArrayOut;
using vtk_format::GeneratedInts;

/// One flat cell of two faces, an octagon and the octagon backwards: a record holds all eight
/// points, so the largest value of `faces` is a record's size (8), not a point id (at most 7).
PolyMesh flatPillow() {
  PolyMesh mesh;
  Loop loop;
  for (int i = 0; i < 8; ++i) {
    const double angle = 0.25 * std::numbers::pi * i;
    loop.push_back(mesh.addVertex(Vec3(std::cos(angle), std::sin(angle), 0.0)));
  }
  const FaceId top = mesh.addFace({loop}, FaceOrigin::Box);
  std::reverse(loop.begin(), loop.end());
  const FaceId bottom = mesh.addFace({loop}, FaceOrigin::Box);
  mesh.addElementFromFaces(std::vector<FaceUse>{{top, false}, {bottom, false}});
  return mesh;
}

/// Meshes with every case of the layout: faces with holes (triangle records), cuts (several
/// points per vertex), point counts out of order, a record holding every point of its cell, and
/// a sliced solid of non-convex cells of many sizes, cut across one interior face.
std::vector<std::pair<std::string, PolyMesh>> corpus() {
  std::vector<std::pair<std::string, PolyMesh>> meshes;
  meshes.emplace_back("flat pillow", flatPillow());
  meshes.emplace_back("holed prism", testing::holedPrism());
  meshes.emplace_back("mixed cells", testing::mixedCells());
  meshes.emplace_back("cut boxes", testing::cutBoxes());
  meshes.emplace_back("finite cut", testing::finitelyCutGrid());
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.3), 1.0, 2);
  const PolyMesh sliced = sliceSurface(sphere, Grid::withCellsAlongLongest(bounds(sphere), 5));
  FaceId interior;
  for (std::size_t f = 0; f < sliced.numFaces() && !interior.valid(); ++f)
    if (!sliced.face(FaceId(f)).isBoundary()) interior = FaceId(f);
  meshes.emplace_back("sliced sphere, cut", testing::cutAcross(sliced, interior));
  return meshes;
}

/// The arrays of the file built whole from the mesh, as the writer built them before it
/// generated them: records are a face's loop or its triangles, corners the element's vertices in
/// order of first use by its records, cells the elements by increasing point count (stable).
/// Points are `points`' (tests/mesh/point_groups_test.cpp checks groupPoints).
struct WholeArrays {
  std::vector<ElementId> order;
  std::vector<std::vector<VertexId>> corners;  ///< per element
  std::vector<std::int64_t> connectivity, offsets, types, faces, faceOffsets;
  std::vector<std::int64_t> faceGroup, faceReversed, faceOrigin, element, pointVertex;
};

WholeArrays wholeArrays(const PolyMesh& mesh, const PointGroups& points) {
  auto recordsOf = [&](FaceId f) {
    std::vector<std::vector<VertexId>> records;
    const Face& face = mesh.face(f);
    if (face.numLoops() == 1) records.emplace_back(face.vertices.begin(), face.vertices.end());
    if (face.numLoops() > 1)
      for (const auto& t : triangulateFace(mesh, f)) records.emplace_back(t.begin(), t.end());
    return records;
  };
  WholeArrays w;
  std::vector<std::size_t> cornerBegin{0};
  for (const Element& element : mesh.elements()) {
    std::vector<VertexId> corners;
    for (const FaceUse& use : element.faces)
      for (const auto& record : recordsOf(use.face))
        for (VertexId v : record)
          if (std::find(corners.begin(), corners.end(), v) == corners.end()) corners.push_back(v);
    cornerBegin.push_back(cornerBegin.back() + corners.size());
    w.corners.push_back(std::move(corners));
  }
  for (std::size_t e = 0; e < mesh.numElements(); ++e) w.order.push_back(ElementId(e));
  std::stable_sort(w.order.begin(), w.order.end(), [&](ElementId a, ElementId b) {
    return w.corners[a.index()].size() < w.corners[b.index()].size();
  });
  auto pointOf = [&](ElementId e, VertexId v) {
    const auto& corners = w.corners[e.index()];
    const std::size_t i = std::find(corners.begin(), corners.end(), v) - corners.begin();
    return static_cast<std::int64_t>(
        points.cornerPoint.empty() ? v.value : points.cornerPoint[cornerBegin[e.index()] + i]);
  };
  for (ElementId e : w.order) {
    for (VertexId v : w.corners[e.index()]) w.connectivity.push_back(pointOf(e, v));
    w.offsets.push_back(static_cast<std::int64_t>(w.connectivity.size()));
    w.types.push_back(vtk_format::kVtkPolyhedron);
    const std::size_t countAt = w.faces.size();
    w.faces.push_back(0);
    for (const FaceUse& use : mesh.element(e).faces)
      for (const auto& record : recordsOf(use.face)) {
        ++w.faces[countAt];
        const std::size_t n = record.size();
        w.faces.push_back(static_cast<std::int64_t>(n));
        for (std::size_t i = 0; i < n; ++i)
          w.faces.push_back(pointOf(e, use.reversed ? record[(n - i) % n] : record[i]));
        w.faceGroup.push_back(use.face.value);
        w.faceReversed.push_back(use.reversed ? 1 : 0);
      }
    w.faceOffsets.push_back(static_cast<std::int64_t>(w.faces.size()));
    w.element.push_back(e.value);
  }
  for (const Face& face : mesh.faces())
    w.faceOrigin.push_back(static_cast<std::int64_t>(face.origin));
  for (VertexId v : points.pointVertex) w.pointVertex.push_back(v.value);
  return w;
}

/// Each generated array of `s` beside the same array built whole.
std::vector<std::pair<std::string, std::pair<GeneratedInts, std::vector<std::int64_t>>>> arrays(
    const CellStreams& s, WholeArrays w) {
  return {{"connectivity", {s.connectivity(), std::move(w.connectivity)}},
          {"offsets", {s.offsets(), std::move(w.offsets)}},
          {"types", {s.types(), std::move(w.types)}},
          {"faces", {s.faces(), std::move(w.faces)}},
          {"faceoffsets", {s.faceOffsets(), std::move(w.faceOffsets)}},
          {"face group", {s.faceGroup(), std::move(w.faceGroup)}},
          {"face reversed", {s.faceReversed(), std::move(w.faceReversed)}},
          {"face origin", {s.faceOrigin(), std::move(w.faceOrigin)}},
          {"element", {s.element(), std::move(w.element)}},
          {"point vertex", {s.pointVertex(), std::move(w.pointVertex)}}};
}

/// Element e's corners in s.
std::vector<VertexId> cornersOf(const CellStreams& s, ElementId e) {
  std::vector<VertexId> out;
  s.corners().forEach(e, [&](VertexId v) { out.push_back(v); });
  return out;
}

std::vector<std::int64_t> generate(const GeneratedInts& g) {
  std::vector<std::int64_t> values(g.size, -1);
  g.fill(0, g.size, values.data());
  return values;
}

TEST(VtuCellStreams, ArraysAreTheLayoutOfVtuIoH) {
  for (const auto& [name, mesh] : corpus()) {
    SCOPED_TRACE(name);
    const CellStreams s(mesh);
    const WholeArrays w = wholeArrays(mesh, s.points());
    ASSERT_EQ(s.numCells(), mesh.numElements());
    if (name.find("cut") != std::string::npos) {
      EXPECT_GT(s.points().numPoints(), mesh.numVertices()) << "a cut gives vertices more points";
    }
    EXPECT_TRUE(std::equal(w.order.begin(), w.order.end(), s.elements().begin()));
    for (std::size_t e = 0; e < mesh.numElements(); ++e)
      EXPECT_EQ(cornersOf(s, ElementId(e)), w.corners[e]) << "element " << e;
    for (const auto& [array, pair] : arrays(s, w)) {
      const auto& [generated, whole] = pair;
      EXPECT_EQ(generate(generated), whole) << array;
      const std::int64_t largest =
          whole.empty() ? 0 : *std::max_element(whole.begin(), whole.end());
      EXPECT_EQ(generated.largest, largest) << array;
    }
  }
}

TEST(VtuCellStreams, GridBoxesCountedWithoutNumberingGiveTheSameArrays) {
  // A sliced sphere with slicing's whole-cell flags: the boxes' corners, records and `faces`
  // runs are counted from the flags, and every array is what counting them all gives.
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.3), 1.0, 3);
  std::vector<char> boxes;
  const PolyMesh mesh = sliceSurface(sphere, Grid::withCellsAlongLongest(bounds(sphere), 8),
                                     nullptr, nullptr, {}, &boxes);
  ASSERT_EQ(boxes.size(), mesh.numElements());
  const auto flagged = std::count(boxes.begin(), boxes.end(), 1);
  ASSERT_GT(flagged, 20);
  ASSERT_LT(static_cast<std::size_t>(flagged), mesh.numElements());
  const CellStreams counted(mesh), given(mesh, boxes);
  // The flagged boxes' corners are read from their first two sides, not stored.
  std::size_t read = 0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    ASSERT_EQ(cornersOf(counted, ElementId(e)), cornersOf(given, ElementId(e))) << "element " << e;
    EXPECT_FALSE(counted.corners().isBox(ElementId(e)));
    read += given.corners().isBox(ElementId(e));
  }
  EXPECT_EQ(read, static_cast<std::size_t>(flagged));
  const auto a = arrays(counted, wholeArrays(mesh, counted.points()));
  const auto b = arrays(given, wholeArrays(mesh, given.points()));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(generate(a[i].second.first), generate(b[i].second.first)) << a[i].first;
    EXPECT_EQ(a[i].second.first.largest, b[i].second.first.largest) << a[i].first;
  }
  // An element given as a box that is none (a cut cell, not of six faces) is refused, not
  // written wrong.
  std::vector<char> wrong(mesh.numElements(), 0);
  std::size_t cut = 0;
  while (cut < mesh.numElements() && mesh.element(ElementId(cut)).faces.size() == 6) ++cut;
  ASSERT_LT(cut, mesh.numElements());
  wrong[cut] = 1;
  EXPECT_THROW(CellStreams(mesh, wrong), std::logic_error);
  EXPECT_THROW(CellStreams(mesh, std::vector<char>(3, 1)), std::invalid_argument);
}

TEST(VtuCellStreams, AnElementGivenAsAGridBoxMustHaveItsSixSidesAndEightCorners) {
  // The unit cube's corners and sides, one at a time made other than a grid box's: a ninth
  // corner, a seventh face, a side of three corners. Each is refused when given as a box.
  std::vector<Vec3> corner;
  for (int b = 0; b < 8; ++b) corner.emplace_back(b & 1, b >> 1 & 1, b >> 2 & 1);
  const std::vector<std::vector<std::uint32_t>> sides = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                                         {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  auto element = [&](std::vector<std::vector<std::uint32_t>> loops, bool ninth) {
    PolyMesh mesh;
    for (const Vec3& p : corner) mesh.addVertex(p);
    if (ninth) mesh.addVertex(Vec3(0.5, 0.5, 0));  // replaces corner 0 in one side
    std::vector<FaceUse> uses;
    for (std::size_t k = 0; k < loops.size(); ++k) {
      Loop loop;
      for (std::uint32_t v : loops[k]) loop.push_back(VertexId(ninth && k == 4 && v == 0 ? 8 : v));
      uses.push_back({mesh.addFace({loop}, FaceOrigin::Box), false});
    }
    mesh.addElementFromFaces(uses);
    return mesh;
  };
  const std::vector<char> box = {1};
  EXPECT_NO_THROW(CellStreams(element(sides, false), box));
  // Its corners are its first two sides', read from them; with sides that share a corner first,
  // they are stored, and either way every array is the one without the flag.
  const std::vector<std::vector<std::uint32_t>> adjacentFirst = {sides[0], sides[2], sides[1],
                                                                 sides[3], sides[4], sides[5]};
  for (const auto& order : {sides, adjacentFirst}) {
    const PolyMesh mesh = element(order, false);
    const CellStreams flagged(mesh, box), counted(mesh);
    EXPECT_EQ(flagged.corners().isBox(ElementId(std::size_t(0))), order == sides);
    EXPECT_EQ(cornersOf(flagged, ElementId(std::size_t(0))),
              cornersOf(counted, ElementId(std::size_t(0))));
    for (const auto& [name, pair] : arrays(flagged, wholeArrays(mesh, flagged.points())))
      EXPECT_EQ(generate(pair.first), pair.second) << name;
  }
  std::vector<std::vector<std::uint32_t>> seven = sides, triangle = sides, collapsed = sides;
  seven.push_back({0, 4, 6});  // six sides of four corners still, and a seventh face
  triangle[5] = {4, 5, 7};
  // Corner 7 on corner 3: six loops of four on seven corners, the second with one twice.
  for (auto& side : collapsed) std::replace(side.begin(), side.end(), 7u, 3u);
  EXPECT_THROW(CellStreams(element(sides, true), box), std::logic_error);
  EXPECT_THROW(CellStreams(element(seven, false), box), std::logic_error);
  EXPECT_THROW(CellStreams(element(triangle, false), box), std::logic_error);
  EXPECT_THROW(CellStreams(element(collapsed, false), box), std::logic_error);
}

/// The bytes of `a` in `encoding`: the <DataArray> element, then its appended bytes if any.
std::string written(const ArrayOut& a, VtuEncoding encoding) {
  std::ostringstream os;
  vtk_format::writeDataArray(os, a, encoding, 0);
  if (encoding == VtuEncoding::Appended) vtk_format::writeAppendedBytes(os, a);
  return os.str();
}

class VtuCellStreamsChunks : public ::testing::TestWithParam<VtuEncoding> {};

TEST_P(VtuCellStreamsChunks, ChunksEndingInsideCellsWriteTheBytesOfOneChunk) {
  // Chunks of a few values start and end inside cells: a cell's `faces` run alone holds its
  // record count, and per record a size and at least three points.
  const std::size_t kChunks[] = {1, 2, 3, 5, 7, 13, 64, 1000};
  for (const auto& [name, mesh] : corpus()) {
    SCOPED_TRACE(name);
    const CellStreams s(mesh);
    const GeneratedInts faces = s.faces();
    const std::vector<std::int64_t> faceEnds = generate(s.faceOffsets());
    EXPECT_FALSE(std::binary_search(faceEnds.begin(), faceEnds.end(), 7));
    for (const auto& [array, pair] : arrays(s, wholeArrays(mesh, s.points()))) {
      const auto& [generated, whole] = pair;
      ArrayOut a = vtk_format::generatedIntArray("  ", array, generated, true);
      a.chunk = std::max<std::size_t>(generated.size, 1);
      const std::string oneChunk = written(a, GetParam());
      EXPECT_EQ(oneChunk, written(vtk_format::intArray("  ", array, whole, true), GetParam()))
          << array;
      for (std::size_t chunk : kChunks) {
        a.chunk = chunk;
        EXPECT_EQ(written(a, GetParam()), oneChunk) << array << " in chunks of " << chunk;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Encodings, VtuCellStreamsChunks, polydg::testing::allEncodings(),
                         polydg::testing::encodingName);

TEST(VtuCellStreams, RunningEndsFindTheCellOfEachPosition) {
  const RunningEnds ends({2, 0, 3, 1});
  EXPECT_EQ(ends.total(), 6u);
  const std::size_t cellOf[] = {0, 0, 2, 2, 2, 3};
  for (std::uint64_t at = 0; at < 6; ++at) EXPECT_EQ(ends.cellAt(at), cellOf[at]) << at;
  EXPECT_EQ(ends.begin(2), 2u);
  EXPECT_EQ(ends.end(2), 5u);
  // A total beyond 32 bits is kept in 64.
  const RunningEnds wide({0xffffffffu, 1u, 2u});
  EXPECT_EQ(wide.total(), 0x100000002u);
  EXPECT_EQ(wide.cellAt(0xffffffffu), 1u);
  EXPECT_EQ(wide.cellAt(0x100000001u), 2u);
}

}  // namespace
}  // namespace polydg
