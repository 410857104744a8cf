// readVtu (polydg/mesh/vtu_io.h): VTK XML UnstructuredGrid files into a PolyMesh, restored exactly
// from polydg's field data when a file has it.
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include <pugixml.hpp>

#include "mesh/vtk_cell_types.h"
#include "mesh/vtk_format.h"
#include "mesh/vtu_restore_arrays.h"
#include "polydg/mesh/vtu_io.h"

namespace polydg {

namespace {

using vtk_format::FileLayout;
using vtk_format::findArray;
using vtk_format::FormatError;
using vtk_format::kVtkPolyhedron;
using vtk_format::readArray;
using vtk_format::readCount;

std::string errnoText(int error) { return error != 0 ? std::strerror(error) : "I/O error"; }

// ============================================================================================
// Cells to face records
// ============================================================================================

/// Every cell's faces, each one loop of vertex ids oriented out of the cell, flattened.
struct CellFaces {
  std::vector<std::size_t> cellEnd;    ///< records of cell c: [cellEnd[c-1], cellEnd[c])
  std::vector<std::size_t> recordEnd;  ///< vertices of record r: [recordEnd[r-1], recordEnd[r])
  std::vector<VertexId> vertices;

  std::size_t numCells() const { return cellEnd.size(); }
  std::size_t cellBegin(std::size_t c) const { return c == 0 ? 0 : cellEnd[c - 1]; }
  std::span<const VertexId> record(std::size_t r) const {
    const std::size_t begin = r == 0 ? 0 : recordEnd[r - 1];
    return {vertices.data() + begin, recordEnd[r] - begin};
  }
};

/// Reads one Piece: appends its points to `points` and its cells' faces to `cells`.
void readPiece(pugi::xml_node piece, const FileLayout& layout, std::vector<Vec3>& points,
               CellFaces& cells) {
  const std::uint64_t numPoints = readCount(piece, "NumberOfPoints");
  const std::uint64_t numCells = readCount(piece, "NumberOfCells");
  const std::size_t pointBase = points.size();
  const std::size_t cellBase = cells.numCells();

  if (numPoints > 0) {
    const pugi::xml_node array = piece.child("Points").child("DataArray");
    if (!array) throw FormatError("Piece has no Points array");
    if (array.attribute("NumberOfComponents").as_int(1) != 3)
      throw FormatError("Points array does not have 3 components");
    const std::vector<double> xyz = readArray<double>(array, layout);
    if (xyz.size() != 3 * numPoints)
      throw FormatError("Points array has " + std::to_string(xyz.size()) + " values, expected " +
                        std::to_string(3 * numPoints));
    for (std::size_t i = 0; i < numPoints; ++i)
      points.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  }
  if (numCells == 0) return;

  const pugi::xml_node cellsNode = piece.child("Cells");
  auto required = [&](const char* name) {
    const pugi::xml_node a = findArray(cellsNode, name);
    if (!a) throw FormatError(std::string("Cells has no '") + name + "' array");
    std::vector<std::int64_t> values = readArray<std::int64_t>(a, layout);
    return values;
  };
  const std::vector<std::int64_t> types = required("types");
  const std::vector<std::int64_t> offsets = required("offsets");
  const std::vector<std::int64_t> connectivity = required("connectivity");
  if (types.size() != numCells || offsets.size() != numCells)
    throw FormatError("Cells arrays 'types' and 'offsets' need " + std::to_string(numCells) +
                      " values");
  std::vector<std::int64_t> faces, faceOffsets;
  if (std::find(types.begin(), types.end(), kVtkPolyhedron) != types.end()) {
    faces = required("faces");
    faceOffsets = required("faceoffsets");
    if (faceOffsets.size() != numCells)
      throw FormatError("Cells array 'faceoffsets' needs " + std::to_string(numCells) + " values");
  }

  auto cellError = [&](std::size_t c, const std::string& problem) {
    return FormatError("cell " + std::to_string(cellBase + c) + " " + problem);
  };
  auto vertex = [&](std::size_t c, std::int64_t id) {
    if (id < 0 || static_cast<std::uint64_t>(id) >= numPoints)
      throw cellError(c, "refers to point " + std::to_string(id) + ", but its piece has " +
                             std::to_string(numPoints) + " points");
    return VertexId(pointBase + static_cast<std::size_t>(id));
  };
  auto endRecord = [&](std::size_t c) {
    const std::size_t begin = cells.recordEnd.empty() ? 0 : cells.recordEnd.back();
    if (cells.vertices.size() - begin < 3)
      throw cellError(c, "has a face with fewer than 3 points");
    cells.recordEnd.push_back(cells.vertices.size());
  };

  std::int64_t connectivityBegin = 0;
  std::int64_t facesBegin = 0;
  for (std::size_t c = 0; c < numCells; ++c) {
    const std::int64_t connectivityEnd = offsets[c];
    if (connectivityEnd < connectivityBegin ||
        connectivityEnd > static_cast<std::int64_t>(connectivity.size()))
      throw cellError(c, "has an invalid offset into 'connectivity'");
    const std::int64_t type = types[c];
    if (type == kVtkPolyhedron) {
      const std::int64_t end = faceOffsets[c];
      if (end < facesBegin || end > static_cast<std::int64_t>(faces.size()) || end == facesBegin)
        throw cellError(c, "has an invalid 'faceoffsets' entry");
      std::int64_t at = facesBegin;
      const std::int64_t count = faces[at++];
      for (std::int64_t k = 0; k < count; ++k) {
        if (at >= end) throw cellError(c, "has a 'faces' run shorter than its face count");
        const std::int64_t n = faces[at++];
        if (n < 0 || n > end - at) throw cellError(c, "has a face running past its 'faces' run");
        for (std::int64_t i = 0; i < n; ++i) cells.vertices.push_back(vertex(c, faces[at++]));
        endRecord(c);
      }
      if (at != end) throw cellError(c, "has a 'faces' run longer than its faces");
      facesBegin = end;
    } else if (const vtk_format::LinearCellType* linear = vtk_format::linearCellType(type)) {
      const std::size_t n = static_cast<std::size_t>(connectivityEnd - connectivityBegin);
      if (n != linear->points)
        throw cellError(c, "has VTK type " + std::to_string(type) + " and " + std::to_string(n) +
                               " points; that type has " + std::to_string(linear->points));
      for (const auto& face : linear->faces) {
        for (int p : face) cells.vertices.push_back(vertex(c, connectivity[connectivityBegin + p]));
        endRecord(c);
      }
    } else {
      throw cellError(c, "has VTK type " + std::to_string(type) +
                             ", which polydg does not read; only 3D linear cells and polyhedra "
                             "are supported");
    }
    if (!faceOffsets.empty() && faceOffsets[c] >= 0 && type != kVtkPolyhedron)
      facesBegin = std::max(facesBegin, faceOffsets[c]);
    cells.cellEnd.push_back(cells.recordEnd.size());
    connectivityBegin = connectivityEnd;
  }
}

// ============================================================================================
// Faces from records
// ============================================================================================

/// Builds faces by matching: a record whose vertex set and reversed cycle equal those of an
/// open face of an earlier cell shares it; any other record becomes a new face.
void buildByMatching(PolyMesh& mesh, const CellFaces& cells) {
  struct OpenFace {
    FaceId face;
    std::size_t cell;
  };
  std::unordered_map<std::uint64_t, std::vector<OpenFace>> open;
  for (std::size_t c = 0; c < cells.numCells(); ++c) {
    std::vector<FaceUse> uses;
    for (std::size_t r = cells.cellBegin(c); r < cells.cellEnd[c]; ++r) {
      const auto record = cells.record(r);
      const std::vector<Loop> loops{Loop(record.begin(), record.end())};
      auto& candidates = open[vertexSetKey(record)];
      const auto match = std::find_if(candidates.begin(), candidates.end(), [&](const OpenFace& o) {
        return o.cell != c && isReverseOf(mesh.face(o.face), loops);
      });
      if (match != candidates.end()) {
        uses.push_back({match->face, true});
        candidates.erase(match);
      } else {
        const FaceId f = mesh.addFace(loops, FaceOrigin::Imported);
        candidates.push_back({f, c});
        uses.push_back({f, false});
      }
    }
    mesh.addElementFromFaces(uses);
  }
}

/// The polydg field data of a file, if present.
struct PolydgFields {
  std::vector<std::int64_t> group, reversed, origin, element, pointVertex;
  bool hasReversed = false;
};

/// The vertex of each of `points` points: without polydg_point_vertex each point is its own
/// vertex; with it, the leading points p with value p are the vertices and every later point
/// names one of them. Empty if the array does not fit.
std::optional<std::vector<std::size_t>> pointVertices(const PolydgFields& fields,
                                                      std::size_t points) {
  std::vector<std::size_t> vertexOf(points);
  std::iota(vertexOf.begin(), vertexOf.end(), std::size_t{0});
  if (fields.pointVertex.empty()) return vertexOf;
  if (fields.pointVertex.size() != points) return std::nullopt;
  std::size_t vertices = 0;
  while (vertices < points && fields.pointVertex[vertices] == static_cast<std::int64_t>(vertices))
    ++vertices;
  for (std::size_t p = vertices; p < points; ++p) {
    const std::int64_t v = fields.pointVertex[p];
    if (v < 0 || static_cast<std::size_t>(v) >= vertices) return std::nullopt;
    vertexOf[p] = static_cast<std::size_t>(v);
  }
  return vertexOf;
}

/// A mesh's faces and elements, ready to be added.
struct FacePlan {
  std::vector<std::vector<Loop>> loops;    ///< per face
  std::vector<FaceOrigin> origins;         ///< per face
  std::vector<std::vector<FaceUse>> uses;  ///< per element
};

double loopArea(const PolyMesh& mesh, const Loop& loop) {
  Vec3 twice = Vec3::Zero();
  const Vec3& c = mesh.position(loop[0]);
  for (std::size_t i = 1; i + 1 < loop.size(); ++i)
    twice += (mesh.position(loop[i]) - c).cross(mesh.position(loop[i + 1]) - c);
  return 0.5 * twice.norm();
}

/// The loops bounding the union of `records` (triangles of one face, in the face's
/// orientation): directed edges whose reverse is not among them, chained into cycles. The
/// largest loop by area comes first. Empty if the edges do not form cycles.
std::vector<Loop> boundaryLoops(const PolyMesh& mesh, const std::vector<Loop>& records) {
  auto key = [](VertexId a, VertexId b) { return (std::uint64_t{a.value} << 32) | b.value; };
  std::unordered_set<std::uint64_t> edges;
  for (const Loop& r : records)
    for (std::size_t i = 0; i < r.size(); ++i) edges.insert(key(r[i], r[(i + 1) % r.size()]));
  std::vector<std::pair<VertexId, VertexId>> boundary;
  std::unordered_multimap<std::uint32_t, std::size_t> outgoing;
  for (const Loop& r : records)
    for (std::size_t i = 0; i < r.size(); ++i) {
      const VertexId a = r[i], b = r[(i + 1) % r.size()];
      if (!edges.contains(key(b, a))) {
        outgoing.emplace(a.value, boundary.size());
        boundary.emplace_back(a, b);
      }
    }
  std::vector<bool> used(boundary.size(), false);
  std::vector<Loop> loops;
  for (std::size_t start = 0; start < boundary.size(); ++start) {
    if (used[start]) continue;
    Loop loop;
    std::size_t e = start;
    while (true) {
      used[e] = true;
      loop.push_back(boundary[e].first);
      if (boundary[e].second == boundary[start].first) break;
      const auto [begin, end] = outgoing.equal_range(boundary[e].second.value);
      const auto next = std::find_if(begin, end, [&](const auto& kv) { return !used[kv.second]; });
      if (next == end) return {};
      e = next->second;
    }
    if (loop.size() < 3) return {};
    loops.push_back(std::move(loop));
  }
  if (loops.empty()) return {};
  std::size_t outer = 0;
  for (std::size_t k = 1; k < loops.size(); ++k)
    if (loopArea(mesh, loops[k]) > loopArea(mesh, loops[outer])) outer = k;
  std::rotate(loops.begin(), loops.begin() + static_cast<std::ptrdiff_t>(outer),
              loops.begin() + static_cast<std::ptrdiff_t>(outer) + 1);
  return loops;
}

/// The loop run backwards from the same first vertex (v0, v(n-1), ..., v1), as the writer does.
Loop reversedLoop(std::span<const VertexId> loop) {
  Loop out(loop.begin(), loop.end());
  std::reverse(out.begin() + 1, out.end());
  return out;
}

/// Plans the faces exactly as writeVtu wrote them, from its field data. Empty if the field data
/// does not match the cells (then the reader falls back to matching).
std::optional<FacePlan> planFromFields(const PolyMesh& mesh, const CellFaces& cells,
                                       const PolydgFields& fields) {
  const std::size_t numFaces = fields.origin.size();
  const std::size_t numRecords = cells.recordEnd.size();
  if (fields.group.size() != numRecords) return std::nullopt;
  if (fields.hasReversed && fields.reversed.size() != numRecords) return std::nullopt;
  FacePlan plan;
  for (std::int64_t o : fields.origin) {
    if (o < 0 || o > static_cast<std::int64_t>(FaceOrigin::Imported)) return std::nullopt;
    plan.origins.push_back(static_cast<FaceOrigin>(o));
  }

  // Per face: its users, and the records (in the face's orientation) of the first user.
  std::vector<int> users(numFaces, 0);
  std::vector<int> flagOfFirst(numFaces, -1);
  std::vector<std::size_t> lastCell(numFaces, std::numeric_limits<std::size_t>::max());
  std::vector<int> currentFlag(numFaces, 0);
  std::vector<std::vector<Loop>> records(numFaces);
  plan.uses.resize(cells.numCells());
  for (std::size_t c = 0; c < cells.numCells(); ++c) {
    for (std::size_t r = cells.cellBegin(c); r < cells.cellEnd[c]; ++r) {
      const std::int64_t g = fields.group[r];
      if (g < 0 || static_cast<std::size_t>(g) >= numFaces) return std::nullopt;
      const auto f = static_cast<std::size_t>(g);
      if (lastCell[f] != c) {
        lastCell[f] = c;
        if (++users[f] > 2) return std::nullopt;
        const int flag = fields.hasReversed ? static_cast<int>(fields.reversed[r]) : users[f] - 1;
        if (flag != 0 && flag != 1) return std::nullopt;
        if (users[f] == 1)
          flagOfFirst[f] = flag;
        else if (fields.hasReversed && flag == flagOfFirst[f])
          return std::nullopt;
        currentFlag[f] = flag;
        plan.uses[c].push_back({FaceId(f), flag == 1});
      } else if (fields.hasReversed && fields.reversed[r] != currentFlag[f]) {
        return std::nullopt;
      }
      if (users[f] == 1) {
        const auto rec = cells.record(r);
        records[f].push_back(currentFlag[f] ? reversedLoop(rec) : Loop(rec.begin(), rec.end()));
      }
    }
  }
  plan.loops.resize(numFaces);
  for (std::size_t f = 0; f < numFaces; ++f) {
    if (users[f] == 0) return std::nullopt;
    if (records[f].size() == 1) {
      plan.loops[f] = {records[f][0]};
    } else {
      plan.loops[f] = boundaryLoops(mesh, records[f]);
      if (plan.loops[f].empty()) return std::nullopt;
    }
  }
  return plan;
}

std::optional<PolydgFields> readPolydgFields(pugi::xml_node grid, const FileLayout& layout) {
  const pugi::xml_node fieldData = grid.child("FieldData");
  const pugi::xml_node group = findArray(fieldData, kFaceGroupArray);
  const pugi::xml_node reversed = findArray(fieldData, kFaceReversedArray);
  const pugi::xml_node origin = findArray(fieldData, kFaceOriginArray);
  if (!group || !origin) return std::nullopt;
  PolydgFields fields;
  fields.group = readArray<std::int64_t>(group, layout);
  fields.origin = readArray<std::int64_t>(origin, layout);
  if (reversed) {
    fields.reversed = readArray<std::int64_t>(reversed, layout);
    fields.hasReversed = true;
  }
  if (const pugi::xml_node element = findArray(fieldData, kElementArray))
    fields.element = readArray<std::int64_t>(element, layout);
  if (const pugi::xml_node pointVertex = findArray(fieldData, kPointVertexArray))
    fields.pointVertex = readArray<std::int64_t>(pointVertex, layout);
  return fields;
}

/// The file's FieldData arrays for the caller, as readVtu documents: text, numbers, no restore
/// arrays.
VtuFieldData readFieldData(pugi::xml_node grid, const FileLayout& layout) {
  VtuFieldData out;
  for (pugi::xml_node array : grid.child("FieldData").children()) {
    const std::string_view tag = array.name();
    if (tag != "DataArray" && tag != "Array") continue;
    const std::string name = array.attribute("Name").value();
    if (name.empty() || isReservedArrayName(name)) continue;
    const std::string_view type = array.attribute("type").value();
    if (type == "String") {
      std::string text = vtk_format::readBytes(array, layout);
      if (!text.empty() && text.back() == '\0') text.pop_back();
      out.strings.insert_or_assign(name, std::move(text));
    } else if ((type == "UInt8" || type == "UChar") && name.size() > kVtuTextSuffix.size() &&
               name.ends_with(kVtuTextSuffix)) {
      out.strings.insert_or_assign(name.substr(0, name.size() - kVtuTextSuffix.size()),
                                   vtk_format::readBytes(array, layout));
    } else if (vtk_format::isNumericType(type)) {
      out.numbers.insert_or_assign(name, readArray<double>(array, layout));
    }
  }
  return out;
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FormatError("cannot open: " + errnoText(errno));
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw FormatError("cannot open: it is a directory");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw FormatError("cannot read: " + errnoText(errno));
  return std::move(bytes).str();
}

/// readVtu without the file name in its errors; `fieldData` as readVtu's, filled as soon as the
/// layout is known.
PolyMesh readVtuContents(const std::string& path, VtuFieldData* fieldData) {
  const std::string bytes = readWholeFile(path);
  const vtk_format::FileParts parts = vtk_format::splitAppendedData(bytes);

  pugi::xml_document doc;
  const std::string_view text = parts.xml();
  const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size());
  const pugi::xml_node root = doc.child("VTKFile");
  if (!parsed && !root)
    throw FormatError(std::string("not a VTK UnstructuredGrid file (XML error: ") +
                      parsed.description() + " at byte " + std::to_string(parsed.offset) + ")");
  if (!parsed)
    throw FormatError(std::string("truncated or malformed XML (") + parsed.description() +
                      " at byte " + std::to_string(parsed.offset) + ")");
  const pugi::xml_node grid = root.child("UnstructuredGrid");
  if (std::string_view(root.attribute("type").value()) != "UnstructuredGrid" || !grid)
    throw FormatError("not a VTK UnstructuredGrid file");
  const vtk_format::FileLayout layout = vtk_format::readLayout(root, parts.appended);
  if (fieldData) *fieldData = readFieldData(grid, layout);

  std::vector<Vec3> points;
  CellFaces cells;
  std::size_t pieces = 0;
  for (pugi::xml_node piece : grid.children("Piece")) {
    readPiece(piece, layout, points, cells);
    ++pieces;
  }
  if (pieces == 0) throw FormatError("UnstructuredGrid has no Piece");

  const std::optional<PolydgFields> fields =
      pieces == 1 ? readPolydgFields(grid, layout) : std::nullopt;
  // With polydg's field data, copies of a vertex become that vertex again. Without it (or if it
  // does not fit the cells), every point is a vertex and faces are matched: matching on the
  // restored vertices would glue the two sides of a cut together.
  PolyMesh mesh;
  std::optional<FacePlan> plan;
  if (fields) {
    if (const auto vertexOf = pointVertices(*fields, points.size())) {
      for (std::size_t p = 0; p < points.size() && (*vertexOf)[p] == p; ++p)
        mesh.addVertex(points[p]);
      CellFaces restored = cells;
      for (VertexId& v : restored.vertices) v = VertexId((*vertexOf)[v.index()]);
      plan = planFromFields(mesh, restored, *fields);
    }
  }
  if (!plan) {
    mesh = PolyMesh();
    for (const Vec3& p : points) mesh.addVertex(p);
    buildByMatching(mesh, cells);
    return mesh;
  }
  for (std::size_t f = 0; f < plan->loops.size(); ++f)
    mesh.addFace(std::move(plan->loops[f]), plan->origins[f]);
  // Elements in their original order when the file says which cell is which element.
  std::vector<std::size_t> cellOfElement(plan->uses.size());
  std::iota(cellOfElement.begin(), cellOfElement.end(), 0);
  if (fields->element.size() == plan->uses.size()) {
    std::vector<std::size_t> inverse(plan->uses.size(), plan->uses.size());
    bool permutation = true;
    for (std::size_t c = 0; c < fields->element.size() && permutation; ++c) {
      const std::int64_t e = fields->element[c];
      permutation = e >= 0 && static_cast<std::size_t>(e) < inverse.size() &&
                    inverse[static_cast<std::size_t>(e)] == inverse.size();
      if (permutation) inverse[static_cast<std::size_t>(e)] = c;
    }
    if (permutation) cellOfElement = std::move(inverse);
  }
  for (std::size_t c : cellOfElement) mesh.addElementFromFaces(plan->uses[c]);
  return mesh;
}

}  // namespace

PolyMesh readVtu(const std::string& path, VtuFieldData* fieldData) {
  try {
    VtuFieldData read;
    PolyMesh mesh = readVtuContents(path, fieldData ? &read : nullptr);
    if (fieldData) *fieldData = std::move(read);
    return mesh;
  } catch (const FormatError& e) {
    throw std::runtime_error(path + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(path + ": array sizes in the file are too large for memory");
  }
}

}  // namespace polydg
