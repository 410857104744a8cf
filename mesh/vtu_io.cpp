#include "polydg/mesh/vtu_io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <numeric>
#include <optional>
#include <ostream>
#include <span>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include <tbb/parallel_for.h>
#include <zlib.h>
#include <boost/container/small_vector.hpp>
#include <pugixml.hpp>

#include "polydg/mesh/face_triangulation.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/xml_escape.h"

namespace polydg {

namespace {

constexpr std::int64_t kVtkPolyhedron = 42;
// The field data arrays with which readVtu restores writeVtu's faces exactly (see vtu_io.h).
constexpr std::string_view kFaceGroupArray = "polydg_face_group";
constexpr std::string_view kFaceReversedArray = "polydg_face_reversed";
/// For each cell in file order, the polydg element it is. Cells are written in increasing
/// order of their point count: meshio 5 groups polyhedra into blocks by point count in order
/// of first appearance but splits cell data by point count in increasing order, so only that
/// order keeps cell data with its cells.
constexpr std::string_view kElementArray = "polydg_element";
constexpr std::string_view kFaceOriginArray = "polydg_face_origin";
/// For each VTU point, the mesh vertex it is a copy of; written only when some vertex has
/// several points (see incidencePoints).
constexpr std::string_view kPointVertexArray = "polydg_point_vertex";

// ============================================================================================
// Base64
// ============================================================================================

constexpr char kBase64Alphabet[] =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Streams bytes out as base64 text; finish() writes the last, padded group.
class Base64Writer {
 public:
  explicit Base64Writer(std::ostream& os) : os_(os) {}

  void write(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      group_[count_++] = bytes[i];
      if (count_ == 3) emit();
    }
  }

  void finish() {
    if (count_ > 0) emit();
  }

 private:
  void emit() {
    const std::uint32_t bits = (std::uint32_t{group_[0]} << 16) |
                               (count_ > 1 ? std::uint32_t{group_[1]} << 8 : 0) |
                               (count_ > 2 ? std::uint32_t{group_[2]} : 0);
    char out[4] = {kBase64Alphabet[(bits >> 18) & 63], kBase64Alphabet[(bits >> 12) & 63],
                   count_ > 1 ? kBase64Alphabet[(bits >> 6) & 63] : '=',
                   count_ > 2 ? kBase64Alphabet[bits & 63] : '='};
    os_.write(out, 4);
    count_ = 0;
  }

  std::ostream& os_;
  unsigned char group_[3] = {0, 0, 0};
  int count_ = 0;
};

int base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

bool isXmlSpace(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

/// A problem with the file's contents; readVtu prefixes the file name.
class VtuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads consecutive bytes from a region of the file, either raw or base64 text decoded one
/// group of four characters at a time (so separately encoded pieces decode seamlessly).
class ByteReader {
 public:
  ByteReader(std::string_view data, bool base64) : data_(data), base64_(base64) {}

  /// Appends the next `n` bytes to `out`; returns false if the data ends first.
  bool read(std::size_t n, std::string& out) {
    if (!base64_) {
      if (n > data_.size() - pos_) return false;
      out.append(data_.substr(pos_, n));
      pos_ += n;
      return true;
    }
    while (pending_.size() - pendingPos_ < n) {
      if (!decodeGroup()) return false;
    }
    out.append(pending_, pendingPos_, n);
    pendingPos_ += n;
    if (pendingPos_ == pending_.size()) {
      pending_.clear();
      pendingPos_ = 0;
    }
    return true;
  }

  /// An upper bound on the bytes left, to reject absurd sizes before allocating.
  std::size_t maxRemaining() const {
    const std::size_t left = data_.size() - pos_;
    return base64_ ? left / 4 * 3 + 3 + (pending_.size() - pendingPos_) : left;
  }

 private:
  /// Decodes the next group into pending_; false at the end of the text.
  bool decodeGroup() {
    int values[4];
    int count = 0;
    int padding = 0;
    while (count < 4) {
      while (pos_ < data_.size() && isXmlSpace(data_[pos_])) ++pos_;
      if (pos_ == data_.size()) {
        if (count == 0) return false;
        throw VtuError("base64 data ends inside a group of four characters");
      }
      const char c = data_[pos_++];
      if (c == '=' && count >= 2) {
        ++padding;
        values[count++] = 0;
      } else {
        const int v = base64Value(c);
        if (v < 0 || padding > 0)
          throw VtuError(std::string("invalid character '") + c + "' in base64 data");
        values[count++] = v;
      }
    }
    const std::uint32_t bits = (std::uint32_t(values[0]) << 18) | (std::uint32_t(values[1]) << 12) |
                               (std::uint32_t(values[2]) << 6) | std::uint32_t(values[3]);
    pending_.push_back(static_cast<char>((bits >> 16) & 0xff));
    if (padding < 2) pending_.push_back(static_cast<char>((bits >> 8) & 0xff));
    if (padding < 1) pending_.push_back(static_cast<char>(bits & 0xff));
    return true;
  }

  std::string_view data_;
  bool base64_;
  std::size_t pos_ = 0;
  std::string pending_;
  std::size_t pendingPos_ = 0;
};

// ============================================================================================
// Writing
// ============================================================================================

/// The cell arrays of the file, with the polydg field data that goes with them. Point ids are
/// VTU points (see pointVertex), not mesh vertices.
struct CellStreams {
  std::vector<std::int64_t> connectivity, offsets, types, faces, faceOffsets;
  std::vector<std::int64_t> faceGroup, faceReversed, faceOrigin;
  std::vector<std::int64_t> element;  ///< the element written as each cell, in file order
  /// The mesh vertex of each VTU point: points 0 .. numVertices-1 are the vertices themselves,
  /// later points are further copies of a vertex (one per extra group of its elements).
  std::vector<std::int64_t> pointVertex;
  /// Element e's corners (distinct vertices) are incidences cornerBegin[e] .. cornerBegin[e+1]:
  /// vertex cornerVertex[i], written as point cornerPoint[i].
  std::vector<std::size_t> cornerBegin;
  std::vector<VertexId> cornerVertex;
  std::vector<std::uint32_t> cornerPoint;
};

/// The records (simple polygons) that stand for each face in the file, in the face's own
/// orientation: the face's one loop, or the triangles of a face with holes.
class FaceRecords {
 public:
  explicit FaceRecords(const PolyMesh& mesh) : mesh_(mesh), triangles_(mesh.numFaces()) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t f = r.begin(); f != r.end(); ++f)
                          if (mesh.face(FaceId(f)).numLoops() > 1)
                            triangles_[FaceId(f)] = triangulateFace(mesh, FaceId(f));
                      });
  }
  std::size_t count(FaceId f) const {
    return mesh_.face(f).numLoops() == 1 ? 1 : triangles_[f].size();
  }
  std::span<const VertexId> record(FaceId f, std::size_t k) const {
    const Face& face = mesh_.face(f);
    if (face.numLoops() == 1) return {face.vertices.data(), face.vertices.size()};
    return {triangles_[f][k].data(), 3};
  }

 private:
  const PolyMesh& mesh_;
  FaceData<std::vector<std::array<VertexId, 3>>> triangles_;
};

/// Union-find over integers, with path halving.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::uint32_t> parent_;
};

/// Each element's distinct vertices in order of first use by its records; element e's are
/// vertices[begin[e] .. begin[e+1]). Entry i of that range is the incidence begin[e] + i.
struct Incidences {
  std::vector<std::size_t> begin;
  std::vector<VertexId> vertices;

  std::span<const VertexId> of(ElementId e) const {
    return {vertices.data() + begin[e.index()], begin[e.index() + 1] - begin[e.index()]};
  }
  /// The incidence of vertex v in element e (v must be one of e's vertices).
  std::uint32_t find(ElementId e, VertexId v) const {
    const auto vs = of(e);
    return static_cast<std::uint32_t>(begin[e.index()] +
                                      (std::find(vs.begin(), vs.end(), v) - vs.begin()));
  }
};

Incidences elementIncidences(const PolyMesh& mesh, const FaceRecords& records) {
  const std::size_t ne = mesh.numElements();
  std::vector<boost::container::small_vector<VertexId, 16>> perElement(ne);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne, 512),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e) {
                        auto& vs = perElement[e];
                        for (const FaceUse& use : mesh.element(ElementId(e)).faces)
                          for (std::size_t k = 0; k < records.count(use.face); ++k)
                            for (VertexId v : records.record(use.face, k))
                              if (std::find(vs.begin(), vs.end(), v) == vs.end()) vs.push_back(v);
                      }
                    });
  Incidences inc;
  inc.begin.resize(ne + 1, 0);
  for (std::size_t e = 0; e < ne; ++e) inc.begin[e + 1] = inc.begin[e] + perElement[e].size();
  inc.vertices.resize(inc.begin[ne]);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t e) {
    std::copy(perElement[e].begin(), perElement[e].end(), inc.vertices.begin() + inc.begin[e]);
  });
  return inc;
}

/// The VTU point of every incidence. Per vertex, its elements are grouped by connectivity
/// through the interior faces that contain the vertex, and each group gets its own point: the
/// first group (in element order) the vertex's own id, further groups new points after all
/// vertices (`pointVertex` receives their vertices). So elements coupled across interior faces
/// share points, while the two sides of a cut, or pieces touching only at a vertex or an edge,
/// are separate regions of the file.
std::vector<std::uint32_t> incidencePoints(const PolyMesh& mesh, const Incidences& inc,
                                           std::vector<std::int64_t>& pointVertex) {
  DisjointSets groups(inc.vertices.size());
  for (const Face& face : mesh.faces()) {
    if (!face.front.valid() || !face.back.valid()) continue;
    for (VertexId v : face.vertices) groups.unite(inc.find(face.front, v), inc.find(face.back, v));
  }
  const std::size_t nv = mesh.numVertices();
  pointVertex.resize(nv);
  std::iota(pointVertex.begin(), pointVertex.end(), std::int64_t{0});
  std::vector<std::uint32_t> rootPoint(inc.vertices.size(), Id<VertexTag>::kInvalid);
  std::vector<bool> vertexTaken(nv, false);
  std::vector<std::uint32_t> point(inc.vertices.size());
  for (std::size_t i = 0; i < inc.vertices.size(); ++i) {
    const std::uint32_t root = groups.find(static_cast<std::uint32_t>(i));
    if (rootPoint[root] == Id<VertexTag>::kInvalid) {
      const VertexId v = inc.vertices[i];
      if (!vertexTaken[v.index()]) {
        vertexTaken[v.index()] = true;
        rootPoint[root] = v.value;
      } else {
        rootPoint[root] = static_cast<std::uint32_t>(pointVertex.size());
        pointVertex.push_back(v.value);
      }
    }
    point[i] = rootPoint[root];
  }
  return point;
}

CellStreams buildCellStreams(const PolyMesh& mesh) {
  const std::size_t ne = mesh.numElements();
  const FaceRecords records(mesh);
  const Incidences inc = elementIncidences(mesh, records);
  CellStreams s;
  const std::vector<std::uint32_t> point = incidencePoints(mesh, inc, s.pointVertex);
  s.cornerBegin = inc.begin;
  s.cornerVertex = inc.vertices;
  s.cornerPoint = point;

  // Cells in increasing order of their point count (stable), see kElementArray.
  std::vector<std::size_t> order(ne);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return inc.begin[a + 1] - inc.begin[a] < inc.begin[b + 1] - inc.begin[b];
  });
  // Sizes per cell, then running ends, then the streams filled in parallel.
  std::vector<std::size_t> recordEnd(ne + 1, 0), faceEnd(ne + 1, 0);
  for (std::size_t c = 0; c < ne; ++c) {
    std::size_t recordsOfCell = 0, stream = 1;
    for (const FaceUse& use : mesh.element(ElementId(order[c])).faces)
      for (std::size_t k = 0; k < records.count(use.face); ++k) {
        ++recordsOfCell;
        stream += 1 + records.record(use.face, k).size();
      }
    recordEnd[c + 1] = recordEnd[c] + recordsOfCell;
    faceEnd[c + 1] = faceEnd[c] + stream;
  }
  s.element.assign(order.begin(), order.end());
  s.types.assign(ne, kVtkPolyhedron);
  s.offsets.resize(ne);
  s.faceOffsets.resize(ne);
  s.connectivity.resize(inc.vertices.size());
  s.faces.resize(faceEnd[ne]);
  s.faceGroup.resize(recordEnd[ne]);
  s.faceReversed.resize(recordEnd[ne]);
  std::vector<std::size_t> connectivityEnd(ne + 1, 0);
  for (std::size_t c = 0; c < ne; ++c)
    connectivityEnd[c + 1] = connectivityEnd[c] + inc.begin[order[c] + 1] - inc.begin[order[c]];
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, ne, 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c) {
          const ElementId e(order[c]);
          const std::size_t first = inc.begin[e.index()];
          for (std::size_t i = first; i < inc.begin[e.index() + 1]; ++i)
            s.connectivity[connectivityEnd[c] + i - first] = point[i];
          s.offsets[c] = static_cast<std::int64_t>(connectivityEnd[c + 1]);
          std::size_t at = faceEnd[c], rec = recordEnd[c];
          s.faces[at++] = static_cast<std::int64_t>(recordEnd[c + 1] - recordEnd[c]);
          for (const FaceUse& use : mesh.element(e).faces)
            for (std::size_t k = 0; k < records.count(use.face); ++k) {
              const auto record = records.record(use.face, k);
              const std::size_t n = record.size();
              s.faces[at++] = static_cast<std::int64_t>(n);
              // Backwards keeps the first vertex first: v0, v(n-1), ..., v1.
              for (std::size_t i = 0; i < n; ++i)
                s.faces[at++] = point[inc.find(e, use.reversed ? record[(n - i) % n] : record[i])];
              s.faceGroup[rec] = use.face.value;
              s.faceReversed[rec++] = use.reversed ? 1 : 0;
            }
          s.faceOffsets[c] = static_cast<std::int64_t>(faceEnd[c + 1]);
        }
      });
  for (const Face& face : mesh.faces())
    s.faceOrigin.push_back(static_cast<std::int64_t>(face.origin));
  return s;
}

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

/// The type an array is stored as: doubles as Float64; integers (all non-negative here) in the
/// smallest of UInt8, Int32 and Int64 that holds them (VTK and meshio convert on reading).
enum class StoredType { Float64, UInt8, Int32, Int64 };

std::string_view vtkTypeName(StoredType t) {
  switch (t) {
    case StoredType::Float64: return "Float64";
    case StoredType::UInt8: return "UInt8";
    case StoredType::Int32: return "Int32";
    case StoredType::Int64: return "Int64";
  }
  return "Int64";
}

std::size_t storedSize(StoredType t) {
  switch (t) {
    case StoredType::UInt8: return 1;
    case StoredType::Int32: return 4;
    default: return 8;
  }
}

/// One <DataArray> to write: its values (doubles or integers) and how to store them.
struct ArrayOut {
  std::string_view indent, name;
  int components = 1;
  bool withTuples = false;  ///< field data needs NumberOfTuples
  std::span<const double> doubles;
  std::span<const std::int64_t> integers;
  StoredType stored = StoredType::Float64;

  std::size_t size() const {
    return stored == StoredType::Float64 ? doubles.size() : integers.size();
  }
  std::size_t bytes() const { return size() * storedSize(stored); }
};

ArrayOut floatArray(std::string_view indent, std::string_view name, int components,
                    std::span<const double> values) {
  return {indent, name, components, false, values, {}, StoredType::Float64};
}

ArrayOut intArray(std::string_view indent, std::string_view name,
                  std::span<const std::int64_t> values, bool withTuples = false) {
  const std::int64_t largest = values.empty() ? 0 : *std::max_element(values.begin(), values.end());
  const StoredType t = largest < 256                                         ? StoredType::UInt8
                       : largest <= std::numeric_limits<std::int32_t>::max() ? StoredType::Int32
                                                                             : StoredType::Int64;
  return {indent, name, 1, withTuples, {}, values, t};
}

/// Appends values [begin, end) of `a`, as stored little-endian, to `out`.
void storeValues(const ArrayOut& a, std::size_t begin, std::size_t end, std::vector<char>& out) {
  const std::size_t at = out.size();
  const std::size_t width = storedSize(a.stored);
  out.resize(at + (end - begin) * width);
  char* p = out.data() + at;
  auto put = [&](auto value) {
    auto bytes = std::bit_cast<std::array<char, sizeof value>>(value);
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes.begin(), bytes.end());
    std::memcpy(p, bytes.data(), bytes.size());
    p += bytes.size();
  };
  for (std::size_t i = begin; i < end; ++i) {
    switch (a.stored) {
      case StoredType::Float64: put(a.doubles[i]); break;
      case StoredType::UInt8: put(static_cast<std::uint8_t>(a.integers[i])); break;
      case StoredType::Int32: put(static_cast<std::int32_t>(a.integers[i])); break;
      case StoredType::Int64: put(a.integers[i]); break;
    }
  }
}

/// Writes the UInt64 byte count and the values of `a` as raw bytes, or through `base64`.
template <class Sink>
void writeBinary(const ArrayOut& a, Sink&& sink) {
  constexpr std::size_t kChunk = 1 << 16;
  std::vector<char> buffer;
  auto count = std::bit_cast<std::array<char, 8>>(std::uint64_t{a.bytes()});
  if constexpr (std::endian::native == std::endian::big) std::reverse(count.begin(), count.end());
  sink(count.data(), count.size());
  for (std::size_t begin = 0; begin < a.size(); begin += kChunk) {
    buffer.clear();
    storeValues(a, begin, std::min(a.size(), begin + kChunk), buffer);
    sink(buffer.data(), buffer.size());
  }
}

/// Writes one <DataArray>; in appended mode only the tag, with `offset` into the appended data.
void writeDataArray(std::ostream& os, const ArrayOut& a, VtuEncoding encoding, std::size_t offset) {
  os << a.indent << "<DataArray type=\"" << vtkTypeName(a.stored) << "\" Name=\""
     << xmlEscape(a.name) << '"';
  // Like VTK, only for several components: meshio 5 turns any array that has the attribute
  // into a 2D one, which its polyhedron reader cannot take for 'faces'.
  if (a.components != 1) os << " NumberOfComponents=\"" << a.components << '"';
  if (a.withTuples) os << " NumberOfTuples=\"" << a.size() << '"';
  if (encoding == VtuEncoding::Appended) {
    os << " format=\"appended\" offset=\"" << offset << "\"/>\n";
    return;
  }
  os << " format=\"" << (encoding == VtuEncoding::Ascii ? "ascii" : "binary") << "\">\n"
     << a.indent << "  ";
  if (encoding == VtuEncoding::Ascii) {
    char buffer[64];
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (i > 0 && i % 12 == 0)
        os << '\n' << a.indent << "  ";
      else if (i > 0)
        os << ' ';
      const auto result = a.stored == StoredType::Float64
                              ? std::to_chars(buffer, buffer + sizeof buffer, a.doubles[i])
                              : std::to_chars(buffer, buffer + sizeof buffer, a.integers[i]);
      os.write(buffer, result.ptr - buffer);
    }
  } else {
    Base64Writer out(os);
    writeBinary(a, [&](const char* data, std::size_t n) { out.write(data, n); });
    out.finish();
  }
  os << '\n' << a.indent << "</DataArray>\n";
}

/// The point and cell values the file holds, in file order.
struct FileValues {
  std::vector<double> points;                     ///< 3 per VTU point
  std::vector<std::vector<double>> pointArrays;   ///< pointData, copied to every VTU point
  std::vector<std::vector<double>> cornerArrays;  ///< cornerData, the mean per VTU point
  std::vector<double> volume;                     ///< per cell
  std::vector<std::vector<double>> cellArrays;    ///< cellData, in cell order
};

/// The rows of `values` (`components` values per row) in the order `rows` lists them: an
/// array per mesh entity becomes one per file entity (VTU point or cell).
std::vector<double> gatherRows(const std::vector<double>& values, int components,
                               const std::vector<std::int64_t>& rows) {
  const auto k = static_cast<std::size_t>(components);
  std::vector<double> out(rows.size() * k);
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t i = 0; i < k; ++i)
      out[r * k + i] = values[static_cast<std::size_t>(rows[r]) * k + i];
  return out;
}

/// The mean of `a`'s corner values over the corners written as each VTU point.
std::vector<double> cornerMeans(const CellStreams& s, const CornerArray& a) {
  const auto k = static_cast<std::size_t>(a.components);
  const std::size_t ne = s.cornerBegin.size() - 1;
  std::vector<double> corner(s.cornerVertex.size() * k);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e)
                        for (std::size_t i = s.cornerBegin[e]; i < s.cornerBegin[e + 1]; ++i)
                          a.value(ElementId(e), s.cornerVertex[i], corner.data() + i * k);
                    });
  std::vector<double> mean(s.pointVertex.size() * k, 0.0);
  std::vector<std::uint32_t> count(s.pointVertex.size(), 0);
  for (std::size_t i = 0; i < s.cornerPoint.size(); ++i) {
    const std::size_t p = s.cornerPoint[i];
    ++count[p];
    for (std::size_t c = 0; c < k; ++c) mean[p * k + c] += corner[i * k + c];
  }
  for (std::size_t p = 0; p < count.size(); ++p)
    for (std::size_t c = 0; c < k; ++c)
      if (count[p] > 0) mean[p * k + c] /= count[p];  // a vertex of no element keeps 0
  return mean;
}

FileValues fileValues(const PolyMesh& mesh, const CellStreams& s,
                      const std::vector<CellArray>& cellData,
                      const std::vector<PointArray>& pointData,
                      const std::vector<CornerArray>& cornerData) {
  FileValues v;
  const std::size_t np = s.pointVertex.size(), ne = s.element.size();
  v.points.resize(3 * np);
  v.volume.resize(ne);
  tbb::parallel_for(std::size_t(0), np, [&](std::size_t p) {
    const Vec3& x = mesh.position(VertexId(static_cast<std::size_t>(s.pointVertex[p])));
    for (int i = 0; i < 3; ++i) v.points[3 * p + i] = x[i];
  });
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, ne, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c)
          v.volume[c] = signedVolume(mesh, ElementId(static_cast<std::size_t>(s.element[c])));
      });
  for (const PointArray& a : pointData)
    v.pointArrays.push_back(gatherRows(a.values, a.components, s.pointVertex));
  for (const CornerArray& a : cornerData) v.cornerArrays.push_back(cornerMeans(s, a));
  for (const CellArray& a : cellData)
    v.cellArrays.push_back(gatherRows(a.values, a.components, s.element));
  return v;
}

void writeContents(std::ostream& os, const PolyMesh& mesh, const CellStreams& s,
                   const FileValues& values, const std::vector<CellArray>& cellData,
                   const std::vector<PointArray>& pointData,
                   const std::vector<CornerArray>& cornerData, VtuEncoding enc) {
  const std::string_view field = "      ", inner = "        ";
  std::vector<ArrayOut> fieldArrays{intArray(field, kFaceGroupArray, s.faceGroup, true),
                                    intArray(field, kFaceReversedArray, s.faceReversed, true),
                                    intArray(field, kFaceOriginArray, s.faceOrigin, true),
                                    intArray(field, kElementArray, s.element, true)};
  if (s.pointVertex.size() != mesh.numVertices())
    fieldArrays.push_back(intArray(field, kPointVertexArray, s.pointVertex, true));
  std::vector<ArrayOut> pointArrays, cellArrays;
  for (std::size_t i = 0; i < pointData.size(); ++i)
    pointArrays.push_back(
        floatArray(inner, pointData[i].name, pointData[i].components, values.pointArrays[i]));
  for (std::size_t i = 0; i < cornerData.size(); ++i)
    pointArrays.push_back(
        floatArray(inner, cornerData[i].name, cornerData[i].components, values.cornerArrays[i]));
  cellArrays.push_back(floatArray(inner, "volume", 1, values.volume));
  for (std::size_t i = 0; i < cellData.size(); ++i)
    cellArrays.push_back(
        floatArray(inner, cellData[i].name, cellData[i].components, values.cellArrays[i]));
  const ArrayOut points = floatArray(inner, "Points", 3, values.points);
  const std::vector<ArrayOut> cells{
      intArray(inner, "connectivity", s.connectivity), intArray(inner, "offsets", s.offsets),
      intArray(inner, "types", s.types), intArray(inner, "faces", s.faces),
      intArray(inner, "faceoffsets", s.faceOffsets)};

  std::size_t offset = 0;
  std::vector<const ArrayOut*> appended;
  auto put = [&](const ArrayOut& a) {
    writeDataArray(os, a, enc, offset);
    offset += 8 + a.bytes();
    appended.push_back(&a);
  };
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\""
        " header_type=\"UInt64\">\n"
     << "  <UnstructuredGrid>\n"
     << "    <FieldData>\n";
  for (const ArrayOut& a : fieldArrays) put(a);
  os << "    </FieldData>\n"
     << "    <Piece NumberOfPoints=\"" << s.pointVertex.size() << "\" NumberOfCells=\""
     << mesh.numElements() << "\">\n";
  os << "      <PointData>\n";
  for (const ArrayOut& a : pointArrays) put(a);
  os << "      </PointData>\n      <CellData>\n";
  for (const ArrayOut& a : cellArrays) put(a);
  os << "      </CellData>\n      <Points>\n";
  put(points);
  os << "      </Points>\n      <Cells>\n";
  for (const ArrayOut& a : cells) put(a);
  os << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
  if (enc == VtuEncoding::Appended) {
    // Raw bytes after '_'; the newline before the closing tag is where meshio 5 ends the data.
    os << "  <AppendedData encoding=\"raw\">\n   _";
    for (const ArrayOut* a : appended)
      writeBinary(*a, [&](const char* data, std::size_t n) {
        os.write(data, static_cast<std::streamsize>(n));
      });
    os << "\n  </AppendedData>\n";
  }
  os << "</VTKFile>\n";
}

std::string errnoText(int error) { return error != 0 ? std::strerror(error) : "I/O error"; }

// ============================================================================================
// Reading: arrays
// ============================================================================================

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

Scalar parseScalar(std::string_view type, std::string_view array) {
  static const std::pair<std::string_view, Scalar> kTypes[] = {
      {"Int8", Scalar::Int8},       {"UInt8", Scalar::UInt8},   {"Int16", Scalar::Int16},
      {"UInt16", Scalar::UInt16},   {"Int32", Scalar::Int32},   {"UInt32", Scalar::UInt32},
      {"Int64", Scalar::Int64},     {"UInt64", Scalar::UInt64}, {"Float32", Scalar::Float32},
      {"Float64", Scalar::Float64}, {"Char", Scalar::Int8},     {"UChar", Scalar::UInt8},
      {"Short", Scalar::Int16},     {"UShort", Scalar::UInt16}, {"Int", Scalar::Int32},
      {"UInt", Scalar::UInt32},     {"Long", Scalar::Int64},    {"ULong", Scalar::UInt64},
      {"Float", Scalar::Float32},   {"Double", Scalar::Float64}};
  for (const auto& [name, scalar] : kTypes)
    if (name == type) return scalar;
  throw VtuError("array '" + std::string(array) + "' has unknown type '" + std::string(type) + "'");
}

std::size_t scalarSize(Scalar s) {
  switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8: return 1;
    case Scalar::Int16:
    case Scalar::UInt16: return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32: return 4;
    case Scalar::Int64:
    case Scalar::UInt64:
    case Scalar::Float64: return 8;
  }
  return 1;
}

bool isFloat(Scalar s) { return s == Scalar::Float32 || s == Scalar::Float64; }

/// Converts one value to the requested kind: any value to double; integers (or floats holding
/// integers) to int64.
template <class Out, class In>
Out convertValue(In v, std::string_view array) {
  if constexpr (std::is_same_v<Out, double>) {
    return static_cast<double>(v);
  } else if constexpr (std::is_floating_point_v<In>) {
    if (!(v == std::floor(v) && std::abs(v) < 9.0e18))
      throw VtuError("array '" + std::string(array) +
                     "' holds a non-integer value where ids are expected");
    return static_cast<std::int64_t>(v);
  } else if constexpr (std::is_same_v<In, std::uint64_t>) {
    if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      throw VtuError("array '" + std::string(array) + "' holds a value too large for an id");
    return static_cast<std::int64_t>(v);
  } else {
    return static_cast<std::int64_t>(v);
  }
}

template <class T>
T loadScalar(const char* p, bool swap) {
  std::array<char, sizeof(T)> bytes;
  std::memcpy(bytes.data(), p, sizeof(T));
  if (swap) std::reverse(bytes.begin(), bytes.end());
  return std::bit_cast<T>(bytes);
}

template <class Out, class In>
void appendConverted(const std::string& bytes, bool swap, std::string_view array,
                     std::vector<Out>& out) {
  const std::size_t n = bytes.size() / sizeof(In);
  out.reserve(out.size() + n);
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(convertValue<Out>(loadScalar<In>(bytes.data() + i * sizeof(In), swap), array));
}

template <class Out>
void convertBytes(const std::string& bytes, Scalar s, bool swap, std::string_view array,
                  std::vector<Out>& out) {
  switch (s) {
    case Scalar::Int8: return appendConverted<Out, std::int8_t>(bytes, swap, array, out);
    case Scalar::UInt8: return appendConverted<Out, std::uint8_t>(bytes, swap, array, out);
    case Scalar::Int16: return appendConverted<Out, std::int16_t>(bytes, swap, array, out);
    case Scalar::UInt16: return appendConverted<Out, std::uint16_t>(bytes, swap, array, out);
    case Scalar::Int32: return appendConverted<Out, std::int32_t>(bytes, swap, array, out);
    case Scalar::UInt32: return appendConverted<Out, std::uint32_t>(bytes, swap, array, out);
    case Scalar::Int64: return appendConverted<Out, std::int64_t>(bytes, swap, array, out);
    case Scalar::UInt64: return appendConverted<Out, std::uint64_t>(bytes, swap, array, out);
    case Scalar::Float32: return appendConverted<Out, float>(bytes, swap, array, out);
    case Scalar::Float64: return appendConverted<Out, double>(bytes, swap, array, out);
  }
}

/// The parts of the file that every array read needs.
struct FileLayout {
  bool swapBytes = false;      ///< the file's byte order differs from this machine's
  std::size_t headerSize = 4;  ///< UInt32 or UInt64 headers
  bool compressed = false;     ///< vtkZLibDataCompressor
  std::string_view appended;   ///< the bytes after AppendedData's '_'
  bool appendedBase64 = true;
};

std::string arrayName(pugi::xml_node array) {
  const char* name = array.attribute("Name").value();
  return *name ? name : array.parent().name();
}

std::uint64_t readHeaderWord(ByteReader& in, const FileLayout& layout, const std::string& what) {
  std::string bytes;
  if (!in.read(layout.headerSize, bytes)) throw VtuError("truncated " + what);
  return layout.headerSize == 4 ? loadScalar<std::uint32_t>(bytes.data(), layout.swapBytes)
                                : loadScalar<std::uint64_t>(bytes.data(), layout.swapBytes);
}

/// The raw bytes of one binary array: a header, then the data, possibly in zlib blocks.
std::string readBinaryBytes(ByteReader& in, const FileLayout& layout, const std::string& what) {
  std::string data;
  if (!layout.compressed) {
    const std::uint64_t size = readHeaderWord(in, layout, what);
    if (size > in.maxRemaining() || !in.read(size, data)) throw VtuError("truncated " + what);
    return data;
  }
  const std::uint64_t blocks = readHeaderWord(in, layout, what);
  const std::uint64_t blockSize = readHeaderWord(in, layout, what);
  const std::uint64_t lastSize = readHeaderWord(in, layout, what);
  if (blocks > in.maxRemaining() / layout.headerSize) throw VtuError("truncated " + what);
  std::vector<std::uint64_t> compressedSizes(blocks);
  std::uint64_t totalCompressed = 0;
  for (auto& c : compressedSizes) {
    c = readHeaderWord(in, layout, what);
    totalCompressed += c;
  }
  if (totalCompressed > in.maxRemaining()) throw VtuError("truncated " + what);
  std::string block;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const std::uint64_t expected = (b + 1 == blocks && lastSize != 0) ? lastSize : blockSize;
    block.clear();
    if (!in.read(compressedSizes[b], block)) throw VtuError("truncated " + what);
    // zlib cannot expand data by more than about 1032:1; larger claims are corrupt headers.
    if (expected > 1100 * compressedSizes[b] + 1024)
      throw VtuError("corrupt compression header in " + what);
    const std::size_t at = data.size();
    data.resize(at + expected);
    uLongf produced = static_cast<uLongf>(expected);
    const int status =
        uncompress(reinterpret_cast<Bytef*>(data.data() + at), &produced,
                   reinterpret_cast<const Bytef*>(block.data()), static_cast<uLong>(block.size()));
    if (status != Z_OK || produced != expected)
      throw VtuError("cannot decompress " + what +
                     " (zlib: " + (status == Z_OK ? "wrong block size" : zError(status)) + ")");
  }
  return data;
}

/// Reads a DataArray's values as `Out` (double or int64), whatever its stored type and format.
template <class Out>
std::vector<Out> readArray(pugi::xml_node array, const FileLayout& layout) {
  const std::string name = arrayName(array);
  const Scalar scalar = parseScalar(array.attribute("type").value(), name);
  const std::string_view format = array.attribute("format").value();
  std::vector<Out> out;
  if (format == "ascii" || format.empty()) {
    const std::string_view text = array.child_value();
    std::size_t pos = 0;
    while (true) {
      while (pos < text.size() && isXmlSpace(text[pos])) ++pos;
      if (pos == text.size()) break;
      std::size_t end = pos;
      while (end < text.size() && !isXmlSpace(text[end])) ++end;
      const char* first = text.data() + pos;
      const char* last = text.data() + end;
      std::from_chars_result result{};
      if (isFloat(scalar)) {
        double v = 0.0;
        result = std::from_chars(first, last, v);
        if (result.ec == std::errc()) out.push_back(convertValue<Out>(v, name));
      } else if (scalar == Scalar::UInt64) {
        std::uint64_t v = 0;
        result = std::from_chars(first, last, v);
        if (result.ec == std::errc()) out.push_back(convertValue<Out>(v, name));
      } else {
        std::int64_t v = 0;
        result = std::from_chars(first, last, v);
        if (result.ec == std::errc()) out.push_back(convertValue<Out>(v, name));
      }
      if (result.ec != std::errc() || result.ptr != last)
        throw VtuError("array '" + name + "' has an invalid number '" +
                       std::string(first, std::min<std::size_t>(last - first, 32)) + "'");
      pos = end;
    }
    return out;
  }
  std::string bytes;
  if (format == "binary") {
    ByteReader in(array.child_value(), /*base64=*/true);
    bytes = readBinaryBytes(in, layout, "data in array '" + name + "'");
  } else if (format == "appended") {
    const pugi::xml_attribute offsetAttr = array.attribute("offset");
    const unsigned long long offset = offsetAttr.as_ullong(~0ull);
    if (!offsetAttr || offset == ~0ull)
      throw VtuError("array '" + name + "' has no valid offset into the appended data");
    if (offset > layout.appended.size())
      throw VtuError("truncated appended data (array '" + name + "')");
    ByteReader in(layout.appended.substr(offset), layout.appendedBase64);
    bytes = readBinaryBytes(in, layout, "appended data (array '" + name + "')");
  } else {
    throw VtuError("array '" + name + "' has unknown format '" + std::string(format) + "'");
  }
  if (bytes.size() % scalarSize(scalar) != 0)
    throw VtuError("array '" + name + "' has a byte count that is not a multiple of its type size");
  convertBytes(bytes, scalar, layout.swapBytes, name, out);
  return out;
}

pugi::xml_node findArray(pugi::xml_node parent, std::string_view name) {
  for (pugi::xml_node a : parent.children("DataArray"))
    if (name == a.attribute("Name").value()) return a;
  return {};
}

std::uint64_t readCount(pugi::xml_node node, const char* attribute) {
  const pugi::xml_attribute a = node.attribute(attribute);
  std::uint64_t value = 0;
  const std::string_view text = a.value();
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (!a || result.ec != std::errc() || result.ptr != text.data() + text.size())
    throw VtuError(std::string(node.name()) + " has no valid " + attribute);
  return value;
}

// ============================================================================================
// Reading: cells to face records
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

/// Outward faces of the 3D linear cells in VTK's point numbering (vtkTetra::GetFaceArray etc.).
struct LinearCellType {
  std::int64_t type;
  std::size_t points;
  std::vector<std::vector<int>> faces;
};

const LinearCellType* linearCellType(std::int64_t type) {
  static const std::vector<LinearCellType> kTypes = [] {
    const std::vector<std::vector<int>> hex = {{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                               {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}};
    // A voxel numbers its points x fastest, then y, then z; as a hexahedron: 0 1 3 2 4 5 7 6.
    const int voxelToHex[8] = {0, 1, 3, 2, 4, 5, 7, 6};
    std::vector<std::vector<int>> voxel = hex;
    for (auto& face : voxel)
      for (int& p : face) p = voxelToHex[p];
    return std::vector<LinearCellType>{
        {10, 4, {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}}},
        {11, 8, voxel},
        {12, 8, hex},
        {13, 6, {{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}}},
        {14, 5, {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}},
        {15,
         10,
         {{0, 4, 3, 2, 1},
          {5, 6, 7, 8, 9},
          {0, 1, 6, 5},
          {1, 2, 7, 6},
          {2, 3, 8, 7},
          {3, 4, 9, 8},
          {4, 0, 5, 9}}},
        {16,
         12,
         {{0, 5, 4, 3, 2, 1},
          {6, 7, 8, 9, 10, 11},
          {0, 1, 7, 6},
          {1, 2, 8, 7},
          {2, 3, 9, 8},
          {3, 4, 10, 9},
          {4, 5, 11, 10},
          {5, 0, 6, 11}}}};
  }();
  for (const auto& t : kTypes)
    if (t.type == type) return &t;
  return nullptr;
}

/// Reads one Piece: appends its points to `points` and its cells' faces to `cells`.
void readPiece(pugi::xml_node piece, const FileLayout& layout, std::vector<Vec3>& points,
               CellFaces& cells) {
  const std::uint64_t numPoints = readCount(piece, "NumberOfPoints");
  const std::uint64_t numCells = readCount(piece, "NumberOfCells");
  const std::size_t pointBase = points.size();
  const std::size_t cellBase = cells.numCells();

  if (numPoints > 0) {
    const pugi::xml_node array = piece.child("Points").child("DataArray");
    if (!array) throw VtuError("Piece has no Points array");
    if (array.attribute("NumberOfComponents").as_int(1) != 3)
      throw VtuError("Points array does not have 3 components");
    const std::vector<double> xyz = readArray<double>(array, layout);
    if (xyz.size() != 3 * numPoints)
      throw VtuError("Points array has " + std::to_string(xyz.size()) + " values, expected " +
                     std::to_string(3 * numPoints));
    for (std::size_t i = 0; i < numPoints; ++i)
      points.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  }
  if (numCells == 0) return;

  const pugi::xml_node cellsNode = piece.child("Cells");
  auto required = [&](const char* name) {
    const pugi::xml_node a = findArray(cellsNode, name);
    if (!a) throw VtuError(std::string("Cells has no '") + name + "' array");
    std::vector<std::int64_t> values = readArray<std::int64_t>(a, layout);
    return values;
  };
  const std::vector<std::int64_t> types = required("types");
  const std::vector<std::int64_t> offsets = required("offsets");
  const std::vector<std::int64_t> connectivity = required("connectivity");
  if (types.size() != numCells || offsets.size() != numCells)
    throw VtuError("Cells arrays 'types' and 'offsets' need " + std::to_string(numCells) +
                   " values");
  std::vector<std::int64_t> faces, faceOffsets;
  if (std::find(types.begin(), types.end(), kVtkPolyhedron) != types.end()) {
    faces = required("faces");
    faceOffsets = required("faceoffsets");
    if (faceOffsets.size() != numCells)
      throw VtuError("Cells array 'faceoffsets' needs " + std::to_string(numCells) + " values");
  }

  auto cellError = [&](std::size_t c, const std::string& problem) {
    return VtuError("cell " + std::to_string(cellBase + c) + " " + problem);
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
    } else if (const LinearCellType* linear = linearCellType(type)) {
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
// Reading: faces from records
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

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw VtuError("cannot open: " + errnoText(errno));
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw VtuError("cannot open: it is a directory");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw VtuError("cannot read: " + errnoText(errno));
  return std::move(bytes).str();
}

PolyMesh readVtuContents(const std::string& path) {
  const std::string bytes = readWholeFile(path);

  // Appended data may be raw binary, which is not XML: parse the text before it, closed off.
  FileLayout layout;
  std::string xmlText;
  const std::size_t appendedTag = bytes.find("<AppendedData");
  if (appendedTag != std::string::npos) {
    const std::size_t tagEnd = bytes.find('>', appendedTag);
    if (tagEnd == std::string::npos) throw VtuError("truncated AppendedData element");
    std::size_t underscore = tagEnd + 1;
    while (underscore < bytes.size() && isXmlSpace(bytes[underscore])) ++underscore;
    if (underscore == bytes.size() || bytes[underscore] != '_')
      throw VtuError("AppendedData does not start with '_'");
    const std::size_t begin = underscore + 1;
    const std::size_t close = bytes.rfind("</AppendedData>");
    const std::size_t end = close != std::string::npos && close >= begin ? close : bytes.size();
    layout.appended = std::string_view(bytes).substr(begin, end - begin);
    xmlText = bytes.substr(0, tagEnd + 1) + "</AppendedData></VTKFile>";
  }

  pugi::xml_document doc;
  const std::string& text = appendedTag != std::string::npos ? xmlText : bytes;
  const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size());
  const pugi::xml_node root = doc.child("VTKFile");
  if (!parsed && !root)
    throw VtuError(std::string("not a VTK UnstructuredGrid file (XML error: ") +
                   parsed.description() + " at byte " + std::to_string(parsed.offset) + ")");
  if (!parsed)
    throw VtuError(std::string("truncated or malformed XML (") + parsed.description() +
                   " at byte " + std::to_string(parsed.offset) + ")");
  const pugi::xml_node grid = root.child("UnstructuredGrid");
  if (std::string_view(root.attribute("type").value()) != "UnstructuredGrid" || !grid)
    throw VtuError("not a VTK UnstructuredGrid file");

  const std::string_view byteOrder = root.attribute("byte_order").as_string("LittleEndian");
  if (byteOrder != "LittleEndian" && byteOrder != "BigEndian")
    throw VtuError("unknown byte_order '" + std::string(byteOrder) + "'");
  layout.swapBytes = (byteOrder == "BigEndian") != (std::endian::native == std::endian::big);
  const std::string_view headerType = root.attribute("header_type").as_string("UInt32");
  if (headerType != "UInt32" && headerType != "UInt64")
    throw VtuError("unknown header_type '" + std::string(headerType) + "'");
  layout.headerSize = headerType == "UInt64" ? 8 : 4;
  const std::string_view compressor = root.attribute("compressor").value();
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    throw VtuError("compressor " + std::string(compressor) +
                   " is not supported (only vtkZLibDataCompressor)");
  layout.compressed = !compressor.empty();
  if (const pugi::xml_node appended = root.child("AppendedData")) {
    const std::string_view encoding = appended.attribute("encoding").as_string("raw");
    if (encoding != "raw" && encoding != "base64")
      throw VtuError("unknown AppendedData encoding '" + std::string(encoding) + "'");
    layout.appendedBase64 = encoding == "base64";
  }

  std::vector<Vec3> points;
  CellFaces cells;
  std::size_t pieces = 0;
  for (pugi::xml_node piece : grid.children("Piece")) {
    readPiece(piece, layout, points, cells);
    ++pieces;
  }
  if (pieces == 0) throw VtuError("UnstructuredGrid has no Piece");

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

// ============================================================================================
// Public functions
// ============================================================================================

void writeVtu(const PolyMesh& mesh, const std::string& path, const VtuWriteOptions& options,
              const std::vector<CellArray>& cellData, const std::vector<PointArray>& pointData,
              const std::vector<CornerArray>& cornerData) {
  std::unordered_set<std::string> cellNames{"volume"}, pointNames;
  checkArrays(cellData, mesh.numElements(), "cell", cellNames);
  checkArrays(pointData, mesh.numVertices(), "point", pointNames);
  for (const CornerArray& a : cornerData) {
    checkName(a.name, a.components, "point", pointNames);
    if (!a.value)
      throw std::invalid_argument("writeVtu: corner array '" + a.name + "' has no value function");
  }
  // Everything that can fail for reasons other than I/O happens before the file is opened.
  const CellStreams streams = buildCellStreams(mesh);
  const FileValues values = fileValues(mesh, streams, cellData, pointData, cornerData);

  const std::string tmp = path + ".tmp";
  auto fail = [&](int error) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path + ": " + errnoText(error));
  };
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) fail(errno);
    errno = 0;
    try {
      writeContents(os, mesh, streams, values, cellData, pointData, cornerData, options.encoding);
    } catch (...) {
      os.close();
      std::remove(tmp.c_str());
      throw;
    }
    os.flush();
    if (!os) fail(errno);
    os.close();
    if (os.fail()) fail(errno);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail(errno);
}

PolyMesh readVtu(const std::string& path) {
  try {
    return readVtuContents(path);
  } catch (const VtuError& e) {
    throw std::runtime_error(path + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(path + ": array sizes in the file are too large for memory");
  }
}

namespace vtu_detail {

std::string base64Encode(std::string_view bytes) {
  std::ostringstream os;
  Base64Writer out(os);
  out.write(bytes.data(), bytes.size());
  out.finish();
  return os.str();
}

std::string base64Decode(std::string_view text) {
  ByteReader in(text, /*base64=*/true);
  std::string out;
  try {
    while (in.read(1, out)) {
    }
  } catch (const VtuError& e) {
    throw std::runtime_error(e.what());
  }
  return out;
}

}  // namespace vtu_detail

}  // namespace polydg
