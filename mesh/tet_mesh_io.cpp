// readTetMesh (polydg/mesh/tet_mesh.h): VTU files of VTK_TETRA cells, TetGen .node/.ele pairs
// and Gmsh MSH 4.1 ASCII files into a checked TetMesh.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <pugixml.hpp>

#include "mesh/surface_text_reading.h"
#include "mesh/tet_mesh_check.h"
#include "mesh/vtk_cell_types.h"
#include "mesh/vtk_format.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/util/error.h"

namespace polydg {

namespace {

using Tet = std::array<std::uint32_t, 4>;

/// The bytes of the file at `path`; InputError "PATH: cannot open: reason" if it cannot be read.
std::string readFile(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw InputError(path + ": cannot open: it is a directory; give a tet mesh file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open: " + (errno != 0 ? std::strerror(errno) : "I/O error") +
                     "; check the path");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read: I/O error; check the file");
  return std::move(bytes).str();
}

/// The mesh of a reader's points and tets (corners index `points`, already in range): keeps the
/// points that some tet uses, in file order, orients the tets and checks the mesh, naming tets
/// and vertices as `naming` does with `pointNumbers[p]` the file's number of point p.
TetMesh finishTetMesh(const std::vector<Vec3>& points, std::vector<Tet> tets,
                      const std::vector<std::int64_t>& pointNumbers, TetNaming naming) {
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> vertexOf(points.size(), kUnused);
  for (const Tet& t : tets)
    for (std::uint32_t p : t) vertexOf[p] = 0;
  TetMesh mesh;
  naming.vertexNumbers.clear();
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (vertexOf[p] == kUnused) continue;
    vertexOf[p] = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.push_back(points[p]);
    naming.vertexNumbers.push_back(pointNumbers[p]);
  }
  for (Tet& t : tets)
    for (std::uint32_t& p : t) p = vertexOf[p];
  mesh.tets = std::move(tets);
  orientTets(mesh);
  checkTetMesh(mesh, naming);
  return mesh;
}

/// Room for `count` items of at least `bytesEach` bytes in a text of `size` bytes, so that a
/// header's absurd count fails on the text instead of allocating.
std::size_t plausible(std::int64_t count, std::size_t size, std::size_t bytesEach) {
  return std::min(static_cast<std::size_t>(std::max<std::int64_t>(count, 0)), size / bytesEach);
}

// ============================================================================================
// Line-based text (TetGen, Gmsh)
// ============================================================================================

/// A text file's lines as words, for the line-based formats: blank lines (and, with
/// `hashComments`, everything after a '#') are skipped; problems are "FILE:LINE: what".
class TextLines {
 public:
  TextLines(std::string path, bool hashComments)
      : path_(std::move(path)),
        text_(readFile(path_)),
        lines_(text_, 0, 1),
        hashComments_(hashComments) {}
  TextLines(const TextLines&) = delete;  // lines_ views text_
  TextLines& operator=(const TextLines&) = delete;

  /// Moves to the next line that has words; false at the end of the file.
  bool next() {
    std::string_view line;
    while (lines_.next(line)) {
      surface_text::splitWords(hashComments_ ? surface_text::uncommented(line) : line, words_);
      if (!words_.empty()) return true;
    }
    words_.clear();
    return false;
  }
  /// next(), or fails saying the file ends before `expected`.
  void require(const std::string& expected) {
    if (!next())
      throw InputError(path_ + ":" + std::to_string(lines_.number()) + ": the file ends before " +
                       expected + "; it is truncated or a count in it is wrong");
  }
  /// Fails unless there is no further line with words.
  void requireEnd(const std::string& after) {
    if (next()) fail("a line after " + after + "; fix the count in the header or remove it");
  }

  const std::vector<std::string_view>& words() const { return words_; }
  const std::string& path() const { return path_; }
  std::size_t textSize() const { return text_.size(); }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_ + ":" + std::to_string(lines_.number()) + ": " + what);
  }
  /// Word i as an integer in [low, high] if the line has it, else `otherwise`.
  std::int64_t optionalInteger(std::size_t i, const std::string& what, std::int64_t low,
                               std::int64_t high, std::int64_t otherwise) const {
    return i < words_.size() ? integer(i, what, low, high) : otherwise;
  }
  /// Fails unless the line has `n` words, `what` describing what they are.
  void expectWords(std::size_t n, const std::string& what) const { expectWords(n, n, what); }
  /// Fails unless the line has `least` to `most` words.
  void expectWords(std::size_t least, std::size_t most, const std::string& what) const {
    if (words_.size() < least || words_.size() > most)
      fail("expected " + std::to_string(most) + " numbers (" + what + "), found " +
           std::to_string(words_.size()) + "; fix the line or the header's counts");
  }
  /// Word i as an integer in [low, high]; `what` names it.
  std::int64_t integer(std::size_t i, const std::string& what, std::int64_t low = 0,
                       std::int64_t high = std::numeric_limits<std::int64_t>::max()) const {
    const std::string_view word = words_[i];
    const std::optional<long long> value =
        isIntegerNumber(word) ? surface_text::integerValue(word) : std::nullopt;
    if (!value) fail(what + " " + surface_text::quoted(word) + " is not an integer; fix it");
    if (*value < low || *value > high)
      fail(what + " " + surface_text::quoted(word) + " is not in the range " + std::to_string(low) +
           " to " + std::to_string(high) + "; fix it");
    return *value;
  }
  /// Fails unless word i is the integer `expected`, the next index of a numbering that must run
  /// on without gaps; `what` names the index.
  void expectIndex(std::size_t i, std::int64_t expected, const std::string& what) const {
    const std::int64_t index = integer(i, what, std::numeric_limits<std::int64_t>::min());
    if (index != expected)
      fail(what + " is " + std::to_string(index) + " where " + std::to_string(expected) +
           " comes next (indices run on from the first without gaps); renumber the file");
  }
  /// Word i as a finite double; `what` names it.
  double real(std::size_t i, const std::string& what) const {
    const std::string_view word = words_[i];
    if (!isDecimalNumber(word))
      fail(what + " " + surface_text::quoted(word) + " is not a number; fix it");
    const double value = surface_text::realValue<double>(word);
    if (!std::isfinite(value))
      fail(what + " " + surface_text::quoted(word) + " is beyond the range of double; fix it");
    return value;
  }

 private:
  std::string path_;
  std::string text_;
  surface_text::LineReader lines_;
  bool hashComments_;
  std::vector<std::string_view> words_;
};

constexpr std::int64_t kMaxPoints = std::numeric_limits<std::uint32_t>::max() - 1;

// ============================================================================================
// TetGen
// ============================================================================================

/// FILE.node's points; `base` becomes the first index (0 or 1). As in TetGen, the header's
/// fields after the count may be left out (dimension 3, no attributes, no markers).
std::vector<Vec3> readTetgenNodes(const std::string& path, std::int64_t& base) {
  TextLines in(path, /*hashComments=*/true);
  in.require("the header '<#points> 3 <#attributes> <0|1 boundary markers>'");
  in.expectWords(1, 4, "<#points> 3 <#attributes> <0|1 boundary markers>");
  const std::int64_t count = in.integer(0, "the number of points", 0, kMaxPoints);
  in.optionalInteger(1, "the dimension", 3, 3, 3);
  const std::int64_t attributes = in.optionalInteger(2, "the number of attributes", 0, 1000, 0);
  const std::int64_t markers = in.optionalInteger(3, "the number of boundary markers", 0, 1, 0);
  const std::size_t words = static_cast<std::size_t>(4 + attributes + markers);
  std::vector<Vec3> points;
  points.reserve(plausible(count, in.textSize(), 8));
  for (std::int64_t i = 0; i < count; ++i) {
    in.require("node line " + std::to_string(i + 1) + " of the " + std::to_string(count) +
               " the header announces");
    in.expectWords(words, "<index> x y z, " + std::to_string(attributes) + " attributes and " +
                              std::to_string(markers) + " markers");
    if (i == 0) base = in.integer(0, "the first point's index (TetGen numbers from 0 or 1)", 0, 1);
    in.expectIndex(0, base + i, "the point index");
    const std::string node = "node " + std::to_string(base + i);
    points.emplace_back(in.real(1, node + ": x"), in.real(2, node + ": y"),
                        in.real(3, node + ": z"));
    for (std::size_t k = 4; k < words; ++k) in.real(k, node + ": an attribute or marker");
  }
  in.requireEnd("the " + std::to_string(count) + " nodes the header announces");
  return points;
}

/// A TetGen FILE.ele and its FILE.node. The .ele header's fields after the count may be left
/// out too (4 nodes, no attribute).
TetMesh readTetgen(const std::string& elePath) {
  const std::string nodePath = std::filesystem::path(elePath).replace_extension(".node").string();
  std::int64_t base = 0;
  const std::vector<Vec3> points = readTetgenNodes(nodePath, base);
  const auto numPoints = static_cast<std::int64_t>(points.size());

  TextLines in(elePath, /*hashComments=*/true);
  in.require("the header '<#tets> <4|10 nodes per tet> <0|1 region attribute>'");
  in.expectWords(1, 3, "<#tets> <4|10 nodes per tet> <0|1 region attribute>");
  const std::int64_t count = in.integer(0, "the number of tets");
  const std::int64_t nodes = in.optionalInteger(1, "the number of nodes per tet", 4, 10, 4);
  if (nodes != 4 && nodes != 10)
    in.fail("tets must have 4 or 10 nodes, not " + std::to_string(nodes) +
            "; fix the header or the file");
  const std::int64_t attributes = in.optionalInteger(2, "the number of region attributes", 0, 1, 0);
  const std::size_t words = static_cast<std::size_t>(1 + nodes + attributes);
  const std::string range = "the nodes of " + nodePath + " are " + std::to_string(base) + " to " +
                            std::to_string(base + numPoints - 1);
  std::vector<Tet> tets;
  tets.reserve(plausible(count, in.textSize(), 8));
  TetNaming naming{elePath, "tet", {}, "node", {}};
  for (std::int64_t t = 0; t < count; ++t) {
    in.require("tet " + std::to_string(base + t) + " (the header announces " +
               std::to_string(count) + ")");
    in.expectWords(words, "<index>, " + std::to_string(nodes) + " nodes and " +
                              std::to_string(attributes) + " attributes");
    const std::string name = "tet " + std::to_string(base + t);
    in.expectIndex(0, base + t, "the tet index");
    Tet corners{};
    for (std::size_t k = 1; k <= static_cast<std::size_t>(nodes); ++k) {
      const std::int64_t v =
          in.integer(k, "a node of " + name, std::numeric_limits<std::int64_t>::min());
      if (v < base || v >= base + numPoints)
        in.fail(name + " refers to node " + std::to_string(v) + ", but " + range +
                "; fix the index or the .node file");
      if (k <= 4) corners[k - 1] = static_cast<std::uint32_t>(v - base);
    }
    if (attributes > 0) in.real(words - 1, name + "'s region attribute");
    tets.push_back(corners);
    naming.tetNumbers.push_back(base + t);
  }
  in.requireEnd("the " + std::to_string(count) + " tets the header announces");
  std::vector<std::int64_t> numbers(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) numbers[p] = base + static_cast<std::int64_t>(p);
  return finishTetMesh(points, std::move(tets), numbers, std::move(naming));
}

// ============================================================================================
// Gmsh MSH 4.1
// ============================================================================================

constexpr const char* kToMsh41 =
    "convert it with 'gmsh FILE -save -format msh41 -o OUT.msh' (ASCII unless -bin is given)";

/// Reads the line that closes a section, `marker` ("$EndNodes"), which must follow `after`.
void expectEnd(TextLines& in, const std::string& marker, const std::string& after) {
  in.require("'" + marker + "'");
  if (in.words()[0] != marker)
    in.fail("expected '" + marker + "' after " + after + ", found " +
            surface_text::quoted(in.words()[0]) +
            "; a count in the section is wrong or the file is damaged: write it again");
}

/// Skips to the line "$End<name>" of the section `name` ("$Comments" ...).
void skipSection(TextLines& in, std::string_view name) {
  const std::string end = "$End" + std::string(name.substr(1));
  for (in.require("'" + end + "'"); in.words()[0] != end;) in.require("'" + end + "'");
}

void readMeshFormat(TextLines& in) {
  in.require("the line 'version file-type data-size' of $MeshFormat");
  in.expectWords(3, "version file-type data-size");
  const std::string_view version = in.words()[0];
  if (version != "4.1")
    in.fail("MSH version " + surface_text::quoted(version) +
            "; polydg reads MSH 4.1 ASCII only: " + kToMsh41);
  if (in.words()[1] != "0")
    in.fail("a binary MSH file (file-type " + surface_text::quoted(in.words()[1]) +
            "); polydg reads MSH 4.1 ASCII only: " + kToMsh41);
  expectEnd(in, "$EndMeshFormat", "the format line");
}

/// The points of $Nodes in file order, their tags, and each tag's point.
struct GmshNodes {
  std::vector<Vec3> points;
  std::vector<std::int64_t> tags;
  std::unordered_map<std::int64_t, std::uint32_t> pointOf;
};

GmshNodes readNodes(TextLines& in) {
  in.require("the $Nodes header");
  in.expectWords(4, "numEntityBlocks numNodes minNodeTag maxNodeTag");
  const std::int64_t blocks = in.integer(0, "the number of entity blocks");
  const std::int64_t count = in.integer(1, "the number of nodes", 0, kMaxPoints);
  GmshNodes nodes;
  nodes.points.reserve(plausible(count, in.textSize(), 8));
  for (std::int64_t b = 0; b < blocks; ++b) {
    in.require("node block " + std::to_string(b + 1) + " of " + std::to_string(blocks));
    in.expectWords(4, "entityDim entityTag parametric numNodesInBlock");
    const std::int64_t dim = in.integer(0, "the entity dimension", 0, 3);
    const std::int64_t parametric = in.integer(2, "the parametric flag", 0, 1);
    const std::int64_t size = in.integer(3, "the number of nodes in the block", 0,
                                         count - static_cast<std::int64_t>(nodes.tags.size()));
    const std::size_t first = nodes.tags.size();
    for (std::int64_t i = 0; i < size; ++i) {
      in.require("the tags of node block " + std::to_string(b + 1));
      in.expectWords(1, "nodeTag");
      const std::int64_t tag = in.integer(0, "node tag", 1);
      if (!nodes.pointOf.emplace(tag, static_cast<std::uint32_t>(nodes.tags.size())).second)
        in.fail("node tag " + std::to_string(tag) + " appears twice; give each node its own tag");
      nodes.tags.push_back(tag);
    }
    const std::size_t words = 3 + static_cast<std::size_t>(parametric * dim);
    for (std::int64_t i = 0; i < size; ++i) {
      const std::string node =
          "node " + std::to_string(nodes.tags[first + static_cast<std::size_t>(i)]);
      in.require("the coordinates of " + node);
      in.expectWords(words, "x y z" + std::string(parametric ? " and parametric coordinates" : ""));
      nodes.points.emplace_back(in.real(0, node + ": x"), in.real(1, node + ": y"),
                                in.real(2, node + ": z"));
    }
  }
  if (nodes.tags.size() != static_cast<std::size_t>(count))
    in.fail("$Nodes announces " + std::to_string(count) + " nodes but its blocks hold " +
            std::to_string(nodes.tags.size()) + "; fix the count");
  expectEnd(in, "$EndNodes", "the nodes");
  return nodes;
}

/// The tets of $Elements, with their tags; lower-dimensional elements are skipped.
void readElements(TextLines& in, const GmshNodes& nodes, std::vector<Tet>& tets,
                  std::vector<std::int64_t>& tags) {
  in.require("the $Elements header");
  in.expectWords(4, "numEntityBlocks numElements minElementTag maxElementTag");
  const std::int64_t blocks = in.integer(0, "the number of entity blocks");
  const std::int64_t count = in.integer(1, "the number of elements");
  std::int64_t seen = 0;
  for (std::int64_t b = 0; b < blocks; ++b) {
    in.require("element block " + std::to_string(b + 1) + " of " + std::to_string(blocks));
    in.expectWords(4, "entityDim entityTag elementType numElementsInBlock");
    const std::int64_t dim = in.integer(0, "the entity dimension", 0, 3);
    const std::int64_t type = in.integer(2, "the element type", 1);
    const std::int64_t size = in.integer(3, "the number of elements in the block", 0, count - seen);
    seen += size;
    // Tets by their type, whatever entity they belong to; other elements of 3D entities are
    // refused, those of points, curves and surfaces skipped (they are not part of a tet mesh).
    const std::size_t words = type == 4 ? 5 : type == 11 ? 11 : 0;
    for (std::int64_t i = 0; i < size; ++i) {
      in.require("element " + std::to_string(i + 1) + " of block " + std::to_string(b + 1));
      if (words == 0 && dim < 3) continue;
      const std::string element = "element " + std::string(in.words()[0]);
      if (words == 0)
        in.fail(element + " has type " + std::to_string(type) +
                ", but a tet mesh holds only tets (type 4, or 11 with 10 nodes); mesh the "
                "volume with tetrahedra only");
      in.expectWords(words, "elementTag and " + std::to_string(words - 1) + " node tags");
      const std::int64_t tag = in.integer(0, "element tag", 1);
      Tet corners{};
      for (std::size_t k = 1; k < words; ++k) {
        const std::int64_t node =
            in.integer(k, "a node tag of " + element, std::numeric_limits<std::int64_t>::min());
        const auto found = nodes.pointOf.find(node);
        if (found == nodes.pointOf.end())
          in.fail(element + " refers to node " + std::to_string(node) +
                  ", which $Nodes does not define; fix the tag or add the node");
        if (k <= 4) corners[k - 1] = found->second;
      }
      tets.push_back(corners);
      tags.push_back(tag);
    }
  }
  if (seen != count)
    in.fail("$Elements announces " + std::to_string(count) + " elements but its blocks hold " +
            std::to_string(seen) + "; fix the count");
  expectEnd(in, "$EndElements", "the elements");
}

TetMesh readGmsh(const std::string& path) {
  TextLines in(path, /*hashComments=*/false);
  in.require("'$MeshFormat'");
  if (in.words()[0] != "$MeshFormat")
    in.fail("not a Gmsh MSH file (it does not start with $MeshFormat); give a .msh file");
  readMeshFormat(in);
  std::optional<GmshNodes> nodes;
  std::vector<Tet> tets;
  TetNaming naming{path, "element", {}, "node", {}};
  bool elements = false;
  while (in.next()) {
    const std::string_view section = in.words()[0];
    if (section == "$Nodes" && !nodes) {
      nodes = readNodes(in);
    } else if (section == "$Elements" && nodes && !elements) {
      readElements(in, *nodes, tets, naming.tetNumbers);
      elements = true;
    } else if (section == "$Nodes" || section == "$Elements") {
      in.fail("a second " + std::string(section) + " section, or $Elements before $Nodes; " +
              "write the file again with Gmsh");
    } else if (section.starts_with('$') && !section.starts_with("$End")) {
      skipSection(in, section);
    } else {
      in.fail("expected a section such as $Nodes, found " + surface_text::quoted(section) +
              "; the file is damaged: write it again");
    }
  }
  if (!elements || tets.empty())
    throw InputError(path + ": the file holds no tetrahedra (elements of type 4 or 11); mesh " +
                     "the volume ('gmsh -3') and save it as MSH 4.1");
  return finishTetMesh(nodes->points, std::move(tets), nodes->tags, std::move(naming));
}

// ============================================================================================
// VTU
// ============================================================================================

/// One Piece's points and tets, appended to `points`, `tets` and `naming.tetNumbers` (cells
/// are numbered across pieces, as ParaView shows them). Throws FormatError for a damaged file,
/// InputError for a cell polydg refuses.
void readVtuPiece(pugi::xml_node piece, const vtk_format::FileLayout& layout,
                  std::vector<Vec3>& points, std::vector<Tet>& tets, TetNaming& naming) {
  using vtk_format::FormatError;
  const std::uint64_t numPoints = vtk_format::readCount(piece, "NumberOfPoints");
  const std::uint64_t numCells = vtk_format::readCount(piece, "NumberOfCells");
  const std::size_t pointBase = points.size();
  const std::size_t cellBase = naming.tetNumbers.size();
  if (numPoints > 0) {
    const pugi::xml_node array = piece.child("Points").child("DataArray");
    if (!array) throw FormatError("a Piece has no Points array");
    const std::vector<double> xyz = vtk_format::readArray<double>(array, layout);
    if (array.attribute("NumberOfComponents").as_int(1) != 3 || xyz.size() != 3 * numPoints)
      throw FormatError("the Points array does not hold 3 coordinates for each of " +
                        std::to_string(numPoints) + " points");
    for (std::size_t i = 0; i < numPoints; ++i)
      points.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  }
  if (numCells == 0) return;
  auto cellArray = [&](const char* name) {
    const pugi::xml_node a = vtk_format::findArray(piece.child("Cells"), name);
    if (!a) throw FormatError(std::string("Cells has no '") + name + "' array");
    return vtk_format::readArray<std::int64_t>(a, layout);
  };
  const std::vector<std::int64_t> types = cellArray("types");
  const std::vector<std::int64_t> offsets = cellArray("offsets");
  const std::vector<std::int64_t> connectivity = cellArray("connectivity");
  if (types.size() != numCells || offsets.size() != numCells)
    throw FormatError("the Cells arrays 'types' and 'offsets' need " + std::to_string(numCells) +
                      " values each");
  std::int64_t begin = 0;
  for (std::size_t c = 0; c < numCells; ++c) {
    const std::string cell = naming.file + ": cell " + std::to_string(cellBase + c);
    if (types[c] != vtk_format::kVtkTetra)
      throw InputError(cell + " has VTK type " + std::to_string(types[c]) +
                       ", but a tet mesh holds only VTK_TETRA (10) cells; export the tets only");
    if (offsets[c] != begin + 4 || offsets[c] > static_cast<std::int64_t>(connectivity.size()))
      throw InputError(cell +
                       " has an offset into 'connectivity' that does not give it 4 points; fix the "
                       "'offsets' array or write the file again");
    Tet corners{};
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int64_t p = connectivity[static_cast<std::size_t>(begin) + k];
      if (p < 0 || static_cast<std::uint64_t>(p) >= numPoints)
        throw InputError(cell + " refers to point " + std::to_string(p) + ", but its Piece has " +
                         std::to_string(numPoints) + " points; fix the connectivity");
      corners[k] = static_cast<std::uint32_t>(pointBase + static_cast<std::size_t>(p));
    }
    tets.push_back(corners);
    naming.tetNumbers.push_back(static_cast<std::int64_t>(cellBase + c));
    begin = offsets[c];
  }
}

TetMesh readVtuTets(const std::string& path) {
  const std::string bytes = readFile(path);
  std::vector<Vec3> points;
  std::vector<Tet> tets;
  TetNaming naming{path, "cell", {}, "point", {}};
  try {
    const vtk_format::FileParts parts = vtk_format::splitAppendedData(bytes);
    pugi::xml_document doc;
    const std::string_view text = parts.xml();
    const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size());
    if (!parsed)
      throw vtk_format::FormatError(std::string("not a valid VTK XML file (") +
                                    parsed.description() + " at byte " +
                                    std::to_string(parsed.offset) + ")");
    const pugi::xml_node root = doc.child("VTKFile");
    const pugi::xml_node grid = root.child("UnstructuredGrid");
    if (std::string_view(root.attribute("type").value()) != "UnstructuredGrid" || !grid)
      throw vtk_format::FormatError("not a VTK UnstructuredGrid file");
    const vtk_format::FileLayout layout = vtk_format::readLayout(root, parts.appended);
    for (pugi::xml_node piece : grid.children("Piece"))
      readVtuPiece(piece, layout, points, tets, naming);
  } catch (const vtk_format::FormatError& e) {
    throw InputError(path + ": " + e.what() + "; write the file again (VTK, ParaView, meshio)");
  }
  if (points.size() > static_cast<std::size_t>(kMaxPoints))
    throw InputError(path + ": more points than polydg's 32-bit indices hold; split the mesh");
  if (tets.empty())
    throw InputError(path + ": the file holds no cells; give a mesh of VTK_TETRA cells");
  std::vector<std::int64_t> numbers(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) numbers[p] = static_cast<std::int64_t>(p);
  return finishTetMesh(points, std::move(tets), numbers, std::move(naming));
}

}  // namespace

namespace {

std::string lowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

}  // namespace

bool isTetMeshFile(const std::string& path) {
  const std::string extension = lowerExtension(path);
  return extension == ".ele" || extension == ".msh";
}

TetMesh readTetMesh(const std::string& path) {
  const std::string extension = lowerExtension(path);
  try {
    if (extension == ".vtu") return readVtuTets(path);
    if (extension == ".ele") return readTetgen(path);
    if (extension == ".msh") return readGmsh(path);
  } catch (const std::bad_alloc&) {
    throw InputError(path + ": the counts in the file are too large for memory; check them");
  }
  throw InputError(path + ": unknown tet mesh extension " +
                   surface_text::quoted(extension.empty() ? "(none)" : extension) +
                   "; polydg reads .vtu (VTK_TETRA cells), .ele (TetGen, with its .node) and .msh "
                   "(Gmsh MSH 4.1 ASCII)");
}

}  // namespace polydg
