// writeVtu (polydg/mesh/vtu_io.h): a PolyMesh as VTK polyhedra, with polydg's restore arrays;
// writeTetVtu (polydg/mesh/tet_mesh.h): a TetMesh as VTK_TETRA cells, through the same document.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "mesh/per_element.h"
#include "mesh/point_groups.h"
#include "mesh/vtk_cell_types.h"
#include "mesh/vtk_format.h"
#include "mesh/vtu_cell_streams.h"
#include "mesh/vtu_layout.h"
#include "mesh/vtu_restore_arrays.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/mesh/vtu_io.h"

namespace polydg {

namespace {

using vtk_format::ArrayOut;
using vtk_format::floatArray;
using vtk_format::generatedFloatArray;
using vtk_format::generatedIntArray;
using vtk_format::intArray;

/// An array's name (non-empty, unused so far among `names`, then recorded) and component count
/// (1 or 3).
void checkName(const std::string& name, int components, const char* kind,
               std::unordered_set<std::string>& names) {
  if (name.empty())
    throw std::invalid_argument(std::string("writeVtu: a ") + kind + " array has no name");
  if (!names.insert(name).second)
    throw std::invalid_argument(std::string("writeVtu: ") + kind + " array name '" + name +
                                "' is used twice");
  if (components != 1 && components != 3)
    throw std::invalid_argument("writeVtu: array '" + name + "' has " + std::to_string(components) +
                                " components; use 1 or 3");
}

template <class Tag>
void checkArrays(const std::vector<VtuArray<Tag>>& arrays, std::size_t count, const char* kind,
                 std::unordered_set<std::string>& names) {
  for (const auto& a : arrays) {
    checkName(a.name, a.components, kind, names);
    if (a.values.size() != count * static_cast<std::size_t>(a.components))
      throw std::invalid_argument("writeVtu: array '" + a.name + "' has " +
                                  std::to_string(a.values.size()) + " values, expected " +
                                  std::to_string(count * a.components));
  }
}

/// `name` with control characters shown as '?', for messages.
std::string printable(std::string_view name) {
  std::string out(name);
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return out;
}

/// The rules of VtuFieldData (names, finite numbers) and distinct array names in the file.
void checkFieldData(const VtuFieldData& fieldData) {
  std::unordered_set<std::string> fileNames;
  auto checkName = [&](const std::string& name, const std::string& fileName, const char* kind) {
    if (name.empty())
      throw std::invalid_argument(std::string("writeVtu: a field data ") + kind + " has no name");
    for (char c : name)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        char code[8];
        std::snprintf(code, sizeof code, "0x%02x", static_cast<unsigned>(c));
        throw std::invalid_argument("writeVtu: field data name '" + printable(name) +
                                    "' holds the control character " + code +
                                    ", which an XML attribute cannot keep");
      }
    if (isReservedArrayName(name))
      throw std::invalid_argument("writeVtu: field data name '" + name +
                                  "' is reserved for polydg's restore arrays (names starting "
                                  "with polydg_face_, polydg_element or polydg_point_)");
    if (!fileNames.insert(fileName).second)
      throw std::invalid_argument("writeVtu: field data text '" + name + "' is stored as '" +
                                  fileName + "', the name of a number array");
  };
  for (const auto& [name, values] : fieldData.numbers) {
    checkName(name, name, "number array");
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        throw std::invalid_argument("writeVtu: field data array '" + printable(name) + "' holds " +
                                    (std::isnan(values[i]) ? "NaN" : "an infinity") + " at index " +
                                    std::to_string(i) + "; only finite numbers can be written");
  }
  for (const auto& [name, text] : fieldData.strings)
    checkName(name, name + std::string(kVtuTextSuffix), "text");
}

/// The point and cell values the file holds, in file order. Not copied: `points` may view its
/// own `pointCopies`.
struct FileValues {
  FileValues() = default;
  FileValues(const FileValues&) = delete;
  FileValues& operator=(const FileValues&) = delete;
  FileValues(FileValues&&) = default;

  /// 3 per VTU point: the mesh's positions themselves where the points are the vertices (a
  /// mesh fresh from slicing; 42 MB not copied for the bunny at 200 cells), else `pointCopies`.
  std::span<const double> points;
  std::vector<double> pointCopies;
  std::vector<std::vector<double>> pointArrays;   ///< pointData, copied to every VTU point
  std::vector<std::vector<double>> cornerArrays;  ///< cornerData, the mean per VTU point
  /// Per element (not per cell: the file's volume array is made from them as it is written),
  /// the caller's or `computedVolumes`.
  std::span<const double> volumes;
  std::vector<double> computedVolumes;
  std::vector<std::vector<double>> cellArrays;  ///< cellData, in cell order
};

/// The rows of `values` (`components` values per row) in the order `rows` lists them: an
/// array per mesh entity becomes one per file entity (VTU point or cell).
template <class Tag>
std::vector<double> gatherRows(const std::vector<double>& values, int components,
                               std::span<const Id<Tag>> rows) {
  const auto k = static_cast<std::size_t>(components);
  std::vector<double> out(rows.size() * k);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t i = 0; i < k; ++i) out[r * k + i] = values[rows[r].index() * k + i];
  return out;
}

/// The mean of `a`'s corner values over the corners written as each VTU point.
std::vector<double> cornerMeans(const CellStreams& s, const CornerArray& a) {
  const auto k = static_cast<std::size_t>(a.components);
  const ElementCorners& corners = s.corners();
  const PointGroups& points = s.points();
  std::vector<double> corner(corners.size() * k);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, corners.numElements(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e) {
                        std::size_t i = corners.first(ElementId(e));
                        corners.forEach(ElementId(e), [&](VertexId v) {
                          a.value(ElementId(e), v, corner.data() + k * i++);
                        });
                      }
                    });
  std::vector<double> mean(points.numPoints() * k, 0.0);
  std::vector<std::uint32_t> count(points.numPoints(), 0);
  corners.forEachIn(0, static_cast<std::uint32_t>(corners.size()),
                    [&](std::uint32_t i, VertexId v) {
                      const std::size_t p = points.point(i, v);
                      ++count[p];
                      for (std::size_t c = 0; c < k; ++c) mean[p * k + c] += corner[i * k + c];
                    });
  for (std::size_t p = 0; p < count.size(); ++p)
    for (std::size_t c = 0; c < k; ++c)
      if (count[p] > 0) mean[p * k + c] /= count[p];  // a vertex of no element keeps 0
  return mean;
}

FileValues fileValues(const PolyMesh& mesh, const CellStreams& s, std::span<const double> volumes,
                      const std::vector<CellArray>& cellData,
                      const std::vector<PointArray>& pointData,
                      const std::vector<CornerArray>& cornerData) {
  FileValues v;
  const std::span<const VertexId> pointVertex = s.points().pointVertex;
  const std::span<const ElementId> cells = s.elements();
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "positions are packed coordinates");
  if (s.points().pointsAreVertices() && !pointVertex.empty()) {
    v.points = {mesh.position(VertexId(std::size_t(0))).data(), 3 * pointVertex.size()};
  } else {
    v.pointCopies.resize(3 * pointVertex.size());
    tbb::parallel_for(std::size_t(0), pointVertex.size(), [&](std::size_t p) {
      const Vec3& x = mesh.position(pointVertex[p]);
      for (int i = 0; i < 3; ++i) v.pointCopies[3 * p + i] = x[i];
    });
    v.points = v.pointCopies;
  }
  if (volumes.empty()) v.computedVolumes = signedVolumes(mesh);
  v.volumes = volumes.empty() ? std::span<const double>(v.computedVolumes) : volumes;
  for (const PointArray& a : pointData)
    v.pointArrays.push_back(gatherRows(a.values, a.components, pointVertex));
  for (const CornerArray& a : cornerData) v.cornerArrays.push_back(cornerMeans(s, a));
  for (const CellArray& a : cellData)
    v.cellArrays.push_back(gatherRows(a.values, a.components, cells));
  return v;
}

constexpr std::string_view kFieldIndent = "      ", kArrayIndent = "        ";

/// The caller's field data as arrays: numbers, then texts as their bytes (0 .. 255, which
/// intArray stores as UInt8). The arrays view this object's own storage, so it is never copied.
class CallerArrays {
 public:
  explicit CallerArrays(const VtuFieldData& fieldData) {
    // Every name and byte string first: the arrays view them, so the vectors must not grow after.
    for (const auto& [name, text] : fieldData.strings) {
      textNames_.push_back(name + std::string(kVtuTextSuffix));
      textBytes_.emplace_back(reinterpret_cast<const unsigned char*>(text.data()),
                              reinterpret_cast<const unsigned char*>(text.data()) + text.size());
    }
    for (const auto& [name, values] : fieldData.numbers)
      arrays.push_back(floatArray(kFieldIndent, name, 1, values, true));
    for (std::size_t i = 0; i < textNames_.size(); ++i)
      arrays.push_back(intArray(kFieldIndent, textNames_[i], textBytes_[i], true));
  }
  CallerArrays(const CallerArrays&) = delete;
  CallerArrays& operator=(const CallerArrays&) = delete;

  std::vector<ArrayOut> arrays;

 private:
  std::vector<std::string> textNames_;
  std::vector<std::vector<std::int64_t>> textBytes_;
};

/// The arrays of one file, section by section in document order, and the piece's size.
struct Document {
  std::vector<ArrayOut> restore;  ///< polydg's field data (restore arrays)
  std::vector<ArrayOut> caller;   ///< the caller's field data
  std::vector<ArrayOut> pointData, cellData;
  ArrayOut points;
  std::vector<ArrayOut> cells;  ///< connectivity, offsets, types, and any face arrays
  std::size_t numPoints = 0, numCells = 0;
};

void writeDocument(std::ostream& os, const Document& d, VtuEncoding enc) {
  // The appended data: polydg's arrays in document order, then the caller's field data in
  // reverse order. meshio 7 reads raw appended data array by array, finding each <DataArray> by
  // its offset attribute while it rewrites the attributes of the arrays already read to
  // positions in a base64 text; where a rewritten offset equals the one it looks for and
  // belongs to an array earlier in the document, it reads the wrong array (hostile field data
  // placed in document order did so: tests/mesh/vtk_check.py --field-data). Read last to first
  // after all of polydg's arrays, a caller's array is preceded in the document only by arrays
  // not read yet (their offsets are all different) and by the restore arrays, whose rewritten
  // offsets (4/3 of their raw bytes and a few characters) stay below the raw size of the whole
  // mesh, where the caller's arrays begin. polydg's own arrays keep the offsets they have in a
  // file without field data.
  std::vector<const ArrayOut*> appended;
  for (const ArrayOut& a : d.restore) appended.push_back(&a);
  for (const ArrayOut& a : d.pointData) appended.push_back(&a);
  for (const ArrayOut& a : d.cellData) appended.push_back(&a);
  appended.push_back(&d.points);
  for (const ArrayOut& a : d.cells) appended.push_back(&a);
  for (auto a = d.caller.rbegin(); a != d.caller.rend(); ++a) appended.push_back(&*a);
  std::unordered_map<const ArrayOut*, std::size_t> offsets;
  std::size_t offset = 0;
  for (const ArrayOut* a : appended) {
    offsets.emplace(a, offset);
    offset += a->binaryBytes();
  }
  auto put = [&](const ArrayOut& a) { vtk_format::writeDataArray(os, a, enc, offsets.at(&a)); };

  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\""
        " header_type=\"UInt64\">\n"
     << "  <UnstructuredGrid>\n"
     << "    <FieldData>\n";
  for (const ArrayOut& a : d.restore) put(a);
  for (const ArrayOut& a : d.caller) put(a);
  os << "    </FieldData>\n"
     << "    <Piece NumberOfPoints=\"" << d.numPoints << "\" NumberOfCells=\"" << d.numCells
     << "\">\n";
  os << "      <PointData>\n";
  for (const ArrayOut& a : d.pointData) put(a);
  os << "      </PointData>\n      <CellData>\n";
  for (const ArrayOut& a : d.cellData) put(a);
  os << "      </CellData>\n      <Points>\n";
  put(d.points);
  os << "      </Points>\n      <Cells>\n";
  for (const ArrayOut& a : d.cells) put(a);
  os << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
  if (enc == VtuEncoding::Appended) {
    // Raw bytes after '_'; the newline before the closing tag is where meshio 5 ends the data.
    os << "  <AppendedData encoding=\"raw\">\n   _";
    for (const ArrayOut* a : appended) vtk_format::writeAppendedBytes(os, *a);
    os << "\n  </AppendedData>\n";
  }
  os << "</VTKFile>\n";
}

void writeContents(std::ostream& os, const PolyMesh& mesh, const CellStreams& s,
                   const FileValues& values, const std::vector<CellArray>& cellData,
                   const std::vector<PointArray>& pointData,
                   const std::vector<CornerArray>& cornerData, const VtuFieldData& fieldData,
                   VtuEncoding enc, const vtk_format::GeneratedInts& faces) {
  const CallerArrays caller(fieldData);
  Document d;
  d.restore = {generatedIntArray(kFieldIndent, kFaceGroupArray, s.faceGroup(), true),
               generatedIntArray(kFieldIndent, kFaceReversedArray, s.faceReversed(), true),
               generatedIntArray(kFieldIndent, kFaceOriginArray, s.faceOrigin(), true),
               generatedIntArray(kFieldIndent, kElementArray, s.element(), true)};
  if (!s.points().pointsAreVertices())
    d.restore.push_back(generatedIntArray(kFieldIndent, kPointVertexArray, s.pointVertex(), true));
  d.caller = caller.arrays;
  for (std::size_t i = 0; i < pointData.size(); ++i)
    d.pointData.push_back(floatArray(kArrayIndent, pointData[i].name, pointData[i].components,
                                     values.pointArrays[i]));
  for (std::size_t i = 0; i < cornerData.size(); ++i)
    d.pointData.push_back(floatArray(kArrayIndent, cornerData[i].name, cornerData[i].components,
                                     values.cornerArrays[i]));
  const std::span<const ElementId> cells = s.elements();
  d.cellData.push_back(generatedFloatArray(
      kArrayIndent, "volume", 1,
      {cells.size(),
       [volumes = values.volumes, cells](std::size_t begin, std::size_t end, double* out) {
         for (std::size_t c = begin; c < end; ++c) out[c - begin] = volumes[cells[c].index()];
       }}));
  for (std::size_t i = 0; i < cellData.size(); ++i)
    d.cellData.push_back(
        floatArray(kArrayIndent, cellData[i].name, cellData[i].components, values.cellArrays[i]));
  d.points = floatArray(kArrayIndent, "Points", 3, values.points);
  d.cells = {generatedIntArray(kArrayIndent, "connectivity", s.connectivity()),
             generatedIntArray(kArrayIndent, "offsets", s.offsets()),
             generatedIntArray(kArrayIndent, "types", s.types()),
             generatedIntArray(kArrayIndent, "faces", faces),
             generatedIntArray(kArrayIndent, "faceoffsets", s.faceOffsets())};
  d.numPoints = s.points().numPoints();
  d.numCells = mesh.numElements();
  writeDocument(os, d, enc);
}

/// The arrays' and the field data's names and sizes (writeVtu's std::invalid_argument).
void checkArraysOf(const PolyMesh& mesh, const std::vector<CellArray>& cellData,
                   const std::vector<PointArray>& pointData,
                   const std::vector<CornerArray>& cornerData, const VtuFieldData& fieldData) {
  std::unordered_set<std::string> cellNames{"volume"}, pointNames;
  checkArrays(cellData, mesh.numElements(), "cell", cellNames);
  checkArrays(pointData, mesh.numVertices(), "point", pointNames);
  for (const CornerArray& a : cornerData) {
    checkName(a.name, a.components, "point", pointNames);
    if (!a.value)
      throw std::invalid_argument("writeVtu: corner array '" + a.name + "' has no value function");
  }
  checkFieldData(fieldData);
}

/// The file of `mesh` written as `streams` lay it out, with its `faces` array (streams.faces(),
/// or the same values held).
void writeWithStreams(const PolyMesh& mesh, const CellStreams& streams,
                      const vtk_format::GeneratedInts& faces, const std::string& path,
                      const VtuWriteOptions& options, const std::vector<CellArray>& cellData,
                      const std::vector<PointArray>& pointData,
                      const std::vector<CornerArray>& cornerData, const VtuFieldData& fieldData,
                      std::span<const double> volumes) {
  const FileValues values = fileValues(mesh, streams, volumes, cellData, pointData, cornerData);
  vtk_format::writeReplacing(path, [&](std::ostream& os) {
    writeContents(os, mesh, streams, values, cellData, pointData, cornerData, fieldData,
                  options.encoding, faces);
  });
}

/// `generated`'s values made once and held as 32-bit integers (4 bytes a value), handed out by
/// a generator of the same size and largest value, so that a file written with it has the same
/// bytes. Values that do not fit are not held: generator() is then `generated` itself.
class HeldInts {
 public:
  explicit HeldInts(vtk_format::GeneratedInts generated) : generated_(std::move(generated)) {
    if (generated_.largest > std::numeric_limits<std::int32_t>::max()) return;
    values_.resize(generated_.size);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, values_.size(), vtk_format::kChunkValues),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::vector<std::int64_t> made(r.size());
                        generated_.fill(r.begin(), r.end(), made.data());
                        std::copy(made.begin(), made.end(),
                                  values_.begin() + static_cast<std::ptrdiff_t>(r.begin()));
                      });
  }
  vtk_format::GeneratedInts generator() const {
    if (values_.size() != generated_.size) return generated_;
    return {generated_.size, generated_.largest,
            [this](std::size_t begin, std::size_t end, std::int64_t* out) {
              std::copy(values_.begin() + static_cast<std::ptrdiff_t>(begin),
                        values_.begin() + static_cast<std::ptrdiff_t>(end), out);
            }};
  }

 private:
  vtk_format::GeneratedInts generated_;
  std::vector<std::int32_t> values_;
};

}  // namespace

void writeVtu(const PolyMesh& mesh, const std::string& path, const VtuWriteOptions& options,
              const std::vector<CellArray>& cellData, const std::vector<PointArray>& pointData,
              const std::vector<CornerArray>& cornerData, const VtuFieldData& fieldData,
              std::span<const double> volumes, std::span<const char> boxes) {
  checkArraysOf(mesh, cellData, pointData, cornerData, fieldData);
  requireNoneOrOnePerElement(volumes.size(), mesh, "writeVtu", "volumes");
  requireNoneOrOnePerElement(boxes.size(), mesh, "writeVtu", "box flags");
  // Everything that can fail for reasons other than I/O happens before the file is opened.
  const CellStreams streams(mesh, boxes);
  writeWithStreams(mesh, streams, streams.faces(), path, options, cellData, pointData, cornerData,
                   fieldData, volumes);
}

struct VtuLayout::Impl {
  explicit Impl(const PolyMesh& m)
      : mesh(m),
        streams(m),
        volumes(signedVolumes(m)),
        faceStream(streams.faces()),
        vertices(m.numVertices()),
        faces(m.numFaces()),
        elements(m.numElements()) {}
  const PolyMesh& mesh;
  const CellStreams streams;
  const std::vector<double> volumes;
  /// The `faces` array, made record by record with each corner's point looked up: held (4
  /// bytes a value), since making it was half of the 23 ms a frame of the bunny sliced at 40
  /// cells spent on it.
  const HeldInts faceStream;
  const std::size_t vertices, faces, elements;
};

VtuLayout::VtuLayout(const PolyMesh& mesh) : impl_(std::make_unique<Impl>(mesh)) {}
VtuLayout::~VtuLayout() = default;
const PolyMesh& VtuLayout::mesh() const { return impl_->mesh; }
bool VtuLayout::fits(const PolyMesh& mesh) const {
  return &mesh == &impl_->mesh && mesh.numVertices() == impl_->vertices &&
         mesh.numFaces() == impl_->faces && mesh.numElements() == impl_->elements;
}

void writeVtu(const VtuLayout& layout, const std::string& path, const VtuWriteOptions& options,
              const std::vector<CellArray>& cellData, const std::vector<PointArray>& pointData,
              const std::vector<CornerArray>& cornerData) {
  const VtuLayout::Impl& l = *layout.impl_;
  if (!layout.fits(l.mesh))
    throw std::logic_error("writeVtu: the mesh changed since its layout was made");
  checkArraysOf(l.mesh, cellData, pointData, cornerData, {});
  writeWithStreams(l.mesh, l.streams, l.faceStream.generator(), path, options, cellData, pointData,
                   cornerData, {}, l.volumes);
}

void writeTetVtu(const TetMesh& mesh, const std::string& path, const VtuWriteOptions& options,
                 const VtuFieldData& fieldData) {
  checkFieldData(fieldData);
  const std::size_t nv = mesh.numVertices(), nt = mesh.numTets();
  std::vector<double> points(3 * nv), volume(nt);
  for (std::size_t v = 0; v < nv; ++v)
    for (std::size_t k = 0; k < 3; ++k) points[3 * v + k] = mesh.vertices[v][static_cast<int>(k)];
  std::vector<std::int64_t> connectivity(4 * nt), offsets(nt), types(nt, vtk_format::kVtkTetra);
  for (std::size_t t = 0; t < nt; ++t) {
    for (std::size_t k = 0; k < 4; ++k) {
      if (mesh.tets[t][k] >= nv)
        throw std::invalid_argument("writeTetVtu: tet " + std::to_string(t) + " has corner " +
                                    std::to_string(mesh.tets[t][k]) + ", but the mesh has " +
                                    std::to_string(nv) + " vertices");
      connectivity[4 * t + k] = mesh.tets[t][k];
    }
    offsets[t] = static_cast<std::int64_t>(4 * (t + 1));
    volume[t] = sixVolume(mesh, t) / 6.0;
  }
  const CallerArrays caller(fieldData);
  Document d;
  d.caller = caller.arrays;
  d.cellData = {floatArray(kArrayIndent, "volume", 1, volume)};
  d.points = floatArray(kArrayIndent, "Points", 3, points);
  d.cells = {intArray(kArrayIndent, "connectivity", connectivity),
             intArray(kArrayIndent, "offsets", offsets), intArray(kArrayIndent, "types", types)};
  d.numPoints = nv;
  d.numCells = nt;
  vtk_format::writeReplacing(path,
                             [&](std::ostream& os) { writeDocument(os, d, options.encoding); });
}

}  // namespace polydg
