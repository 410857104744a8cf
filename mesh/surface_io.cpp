// Reading surfaces: guard the header counts; read OBJ/OFF/PLY/STL in double precision as CGAL's
// readers read them (OBJ, plain OFF and plain ASCII STL files as their text is checked, binary
// STL directly, the others through CGAL's polygon-soup readers after checks for what they
// misread) and everything else, or what CGAL cannot read, through assimp with transforms baked in
// (the module libpolydg_assimp.so, mesh/assimp_import.h); then weld by exact position and
// triangulate polygons exactly (mesh/surface_builder.h).
#include "polydg/mesh/surface_io.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/IO/STL.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "mesh/assimp_import.h"
#include "mesh/surface_builder.h"
#include "mesh/surface_text_check.h"
#include "util/format.h"
#include "util/modules.h"

namespace polydg {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

/// The first 64 KiB of the file: enough for any real OFF or PLY header.
std::string readHead(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

// --- header guard -----------------------------------------------------------------------------

/// The unsigned decimal `token` (saturated at the largest 64-bit value); `ok` is false if
/// `token` is not a plain unsigned decimal.
std::uint64_t parseCount(const std::string& token, bool& ok) {
  ok = !token.empty();
  std::uint64_t value = 0;
  for (char c : token) {
    if (!std::isdigit(static_cast<unsigned char>(c))) {
      ok = false;
      return 0;
    }
    const std::uint64_t digit = static_cast<std::uint64_t>(c - '0');
    if (value > (std::numeric_limits<std::uint64_t>::max() - digit) / 10)
      return std::numeric_limits<std::uint64_t>::max();
    value = 10 * value + digit;
  }
  return value;
}

/// assimp's OFF and PLY readers allocate what the header declares before reading the data, so
/// one corrupt count can take all memory (assimp's own invalid/OutOfMemory.off asks for 16 GB).
/// Every declared vertex, face or PLY element takes at least one byte of the file, so a header
/// declaring more of them than the file has bytes is rejected before assimp sees it.
void checkDeclaredCounts(const std::string& path, const std::string& head,
                         std::uintmax_t fileSize) {
  const auto check = [&](const std::string& token, const std::string& what) {
    bool ok = false;
    const std::uint64_t count = parseCount(token, ok);
    if (ok && count > fileSize)
      fail(path, "header declares " + token + " " + what + " but the file has only " +
                     std::to_string(fileSize) + " bytes; the file is corrupt");
  };

  std::istringstream lines(head);
  std::string line;
  if (head.starts_with("ply")) {
    // "element NAME COUNT" lines up to end_header.
    while (std::getline(lines, line) && !line.starts_with("end_header")) {
      std::istringstream words(line);
      std::string keyword, name, count;
      if (words >> keyword >> name >> count && keyword == "element")
        check(count, "'" + name + "' elements");
    }
    return;
  }
  // OFF: a keyword ending in "OFF" (OFF, COFF, NOFF, ...), then the vertex and face counts;
  // '#' starts a comment.
  std::vector<std::string> tokens;
  while (tokens.size() < 3 && std::getline(lines, line)) {
    std::istringstream words(line.substr(0, line.find('#')));
    for (std::string word; tokens.size() < 3 && words >> word;) tokens.push_back(word);
  }
  if (tokens.size() < 3) return;
  std::string keyword = tokens[0];
  for (char& c : keyword) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (!keyword.ends_with("OFF")) return;
  check(tokens[1], "vertices");
  check(tokens[2], "faces");
}

// --- CGAL: OBJ, OFF, PLY and STL in double precision --------------------------------------------

using CgalPoint = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
using SoupPolygon = std::vector<std::size_t>;

/// What a CGAL reader returned, in polydg's terms. Face indices are checked against `points`.
struct PolygonSoup {
  std::vector<Vec3> points;
  std::vector<SoupPolygon> polygons;
  std::size_t meshes = 1;
  std::size_t inputVertices = 0;
  std::size_t ignoredPoints = 0;  ///< OBJ `p` indices and faces of one corner, removed before
                                  ///< CGAL parsed the file
  std::size_t ignoredLines = 0;   ///< OBJ `l` segments and faces of two corners, likewise
  /// An OBJ file with vertices and no `f` line of three or more corners.
  bool onlyPointsOrLines = false;
  std::vector<std::string> warnings;  ///< see SurfaceReadInfo::warnings
};

/// The point type for STL files. CGAL's ASCII STL reader merges equal points through a
/// std::map: ordered by bits, so that a NaN is kept (and reported) instead of breaking the
/// map's ordering.
struct StlPoint {
  std::array<double, 3> c{};
  double& operator[](std::size_t i) { return c[i]; }
  const double& operator[](std::size_t i) const { return c[i]; }
  bool operator<(const StlPoint& o) const {
    for (std::size_t i = 0; i < 3; ++i) {
      const auto a = std::bit_cast<std::uint64_t>(c[i]), b = std::bit_cast<std::uint64_t>(o.c[i]);
      if (a != b) return a < b;
    }
    return false;
  }
};

/// For its lifetime, std::cout, std::cerr and std::clog write into a buffer: CGAL's readers print
/// their errors and notes there in verbose mode. One capture at a time in this process.
class CapturedOutput {
 public:
  CapturedOutput()
      : lock_(mutex()),
        out_(std::cout.rdbuf(buffer_.rdbuf())),
        err_(std::cerr.rdbuf(buffer_.rdbuf())),
        log_(std::clog.rdbuf(buffer_.rdbuf())) {}
  ~CapturedOutput() {
    std::cout.rdbuf(out_);
    std::cerr.rdbuf(err_);
    std::clog.rdbuf(log_);
  }
  CapturedOutput(const CapturedOutput&) = delete;
  CapturedOutput& operator=(const CapturedOutput&) = delete;

  /// The last line that mentions an error or a warning, or "" if none did.
  std::string lastError() const {
    std::istringstream lines(buffer_.str());
    std::string line, found;
    while (std::getline(lines, line)) {
      const std::string lower = lowercase(line);
      if (lower.find("error") != std::string::npos || lower.find("warning") != std::string::npos)
        found = line;
    }
    return found;
  }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  std::ostringstream buffer_;
  std::streambuf* out_;
  std::streambuf* err_;
  std::streambuf* log_;
};

/// Why CGAL did not read a file: "" while nothing went wrong.
using Reason = std::string;

/// Runs `read` (a CGAL reader call returning bool) with output captured; returns "" on success,
/// else CGAL's last error line (or the exception it threw).
template <typename Read>
Reason runCgal(Read read) {
  CapturedOutput captured;
  try {
    if (read()) return "";
  } catch (const std::exception& e) {  // CGAL assertions, std::bad_alloc
    return oneLine(e.what());
  }
  const std::string error = captured.lastError();
  return error.empty() ? "its reader failed without a message" : oneLine(error);
}

/// Every index of every polygon names a point, and no polygon is empty.
Reason checkIndices(const std::vector<SoupPolygon>& polygons, std::size_t numPoints) {
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    if (polygons[f].empty()) return "face " + std::to_string(f) + " has no corners";
    for (std::size_t v : polygons[f])
      if (v >= numPoints)
        return "face " + std::to_string(f) + " refers to a vertex beyond the " +
               std::to_string(numPoints) + " of the file";
  }
  return "";
}

template <typename Point>
std::vector<Vec3> toVec3(const std::vector<Point>& points) {
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Point& p : points) out.emplace_back(p[0], p[1], p[2]);
  return out;
}

/// The whole file, or nothing if it cannot be read.
std::optional<std::string> readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return std::nullopt;
  // In one read of the size the file has (a character at a time took as long as checking it).
  const std::streamoff size = in.tellg();
  if (size < 0) return std::nullopt;
  std::string text(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  in.read(text.data(), size);
  if (in.gcount() != size) return std::nullopt;
  return text;
}

/// Reads an OBJ file: its vertices and faces as checkObjText reads them while it checks each
/// line (what CGAL's OBJ reader would read of a file that passes the check, parsed once instead
/// of again by CGAL's stream parser, which took three quarters of reading a 75k-triangle scan),
/// or returns why polydg must not read it (assimp then does).
std::variant<PolygonSoup, Reason> readObj(const std::string& path, ReadWarnings& warnings) {
  const std::optional<std::string> text = readText(path);
  if (!text) return Reason("cannot read the file");
  ObjText scan = checkObjText(path, *text, warnings);
  if (!scan.assimpReason.empty()) return scan.assimpReason;
  PolygonSoup soup;
  soup.meshes = std::max<std::size_t>(1, scan.materials.size());
  soup.inputVertices = scan.positions.size();
  soup.ignoredPoints = scan.points;
  soup.ignoredLines = scan.lines;
  if (scan.polygons.empty() && !scan.positions.empty()) {
    soup.onlyPointsOrLines = true;
    return soup;
  }
  soup.points = toVec3(scan.positions);
  soup.polygons = std::move(scan.polygons);
  return soup;
}

/// Why CGAL's PLY reader must not read a file with this header, or "": it asserts (crashes when
/// assertions are off) on x/y/z of integer type, silently misaligns on a property type it does
/// not know, fills a list from its declared count (a corrupt 32-bit count allocates gigabytes),
/// reads "vertices"/"faces"/"halfedge" elements its own way, and ignores the triangle strips and
/// range grids that assimp reads. `header` is parsed from the file's first 64 KiB.
Reason plyHeaderProblem(const PlyHeader& header) {
  static const std::set<std::string> kScalar = {
      "char", "int8",  "uchar", "uint8",  "short", "int16",   "ushort", "uint16",
      "int",  "int32", "uint",  "uint32", "float", "float32", "double", "float64"};
  static const std::set<std::string> kListCount = {"char",  "int8",  "uchar",  "uint8",
                                                   "short", "int16", "ushort", "uint16"};
  static const std::set<std::string> kReal = {"float", "float32", "double", "float64"};
  static const std::set<std::string> kForeign = {"vertices", "faces", "halfedge", "tristrips",
                                                 "range_grid"};
  if (header.problem == "no end_header") return "no end_header in the first 64 KiB";
  if (!header.problem.empty()) return header.problem;
  if (header.format != "ascii" && header.format != "binary_little_endian" &&
      header.format != "binary_big_endian")
    return "unknown PLY format '" + header.format + "'";
  bool haveVertex = false;
  for (const PlyElement& element : header.elements) {
    if (kForeign.contains(element.name))
      return "element '" + element.name + "' is not read the same way by CGAL";
    for (const PlyProperty& property : element.properties) {
      if (!property.sizeType.empty() && !kListCount.contains(property.sizeType))
        return "list count type '" + property.sizeType + "' (CGAL reads 8 and 16 bits only)";
      if (!kScalar.contains(property.type)) return "property type '" + property.type + "'";
    }
    if (element.name != "vertex") continue;
    haveVertex = true;
    for (const char* axis : {"x", "y", "z"}) {
      const auto it = std::find_if(element.properties.begin(), element.properties.end(),
                                   [&](const PlyProperty& p) { return p.name == axis; });
      if (it == element.properties.end()) return std::string("vertex has no ") + axis;
      if (!it->sizeType.empty() || !kReal.contains(it->type))
        return std::string("vertex ") + axis + " is of type " + it->type;
    }
  }
  if (!haveVertex) return "no vertex element";
  return "";
}

/// Why CGAL's OFF reader must not read a file with this header, or "": it allocates the vertex
/// and face counts before reading, so only the ASCII forms whose counts checkDeclaredCounts has
/// bounded are given to it ([ST][C][N][4]OFF, then the counts): not nOFF (a dimension first),
/// binary OFF (binary counts) or SKEL. Counts that are missing or malformed are an error of
/// checkOffText (CGAL and assimp would both take a missing edge count from the first vertex
/// line: "OFF\n4 4\n1.5 0 0" has 1 edge and a first vertex at x = 0.5 for both).
Reason offHeaderProblem(const OffHeader& header) {
  if (header.keyword.empty()) return "no OFF header";
  std::string keyword = header.keyword;
  for (const char* prefix : {"ST", "C", "N", "4"})
    if (keyword.starts_with(prefix)) keyword.erase(0, std::strlen(prefix));
  if (keyword != "OFF") return "header keyword '" + header.keyword + "' is not one CGAL reads here";
  if (!header.counts.empty() && header.counts[0] == "BINARY") return "binary OFF";
  return "";
}

/// The corners of the `facets` facets of a binary STL file (84 + 50 n bytes, checked by the
/// caller), three a facet, as CGAL's binary parser reads them: each corner's three little-endian
/// floats converted exactly to doubles. Written here without that parser's std::map of the
/// points it has seen (most of reading a 75k-triangle scan).
Reason readBinaryStl(const std::string& path, std::uint32_t facets, std::vector<StlPoint>& points) {
  std::ifstream in(path, std::ios::binary);
  if (!in.seekg(84)) return "cannot read the file";
  constexpr std::size_t kFacetBytes = 50, kChunk = 65536;  // facets read at a time
  std::vector<char> bytes(kFacetBytes * std::min<std::size_t>(facets, kChunk));
  points.resize(3 * std::size_t{facets});
  for (std::size_t first = 0; first < facets; first += kChunk) {
    const std::size_t count = std::min<std::size_t>(kChunk, facets - first);
    if (!in.read(bytes.data(), static_cast<std::streamsize>(count * kFacetBytes)))
      return "the file ended before its " + std::to_string(facets) + " facets";
    for (std::size_t i = 0; i < count; ++i) {
      const char* facet = bytes.data() + i * kFacetBytes + 12;  // after the normal
      const std::size_t f = first + i;
      for (std::size_t corner = 0; corner < 3; ++corner)
        for (std::size_t k = 0; k < 3; ++k) {
          const auto* b = reinterpret_cast<const unsigned char*>(facet + 12 * corner + 4 * k);
          const std::uint32_t word = b[0] | std::uint32_t{b[1]} << 8 | std::uint32_t{b[2]} << 16 |
                                     std::uint32_t{b[3]} << 24;
          points[3 * f + corner][k] = std::bit_cast<float>(word);
        }
    }
  }
  return "";
}

/// Reads an STL file, binary (readBinaryStl) or ASCII (a plain file's facets as its check read
/// them, any other through the ASCII parser of CGAL/IO/STL/STL_reader.h, CGAL 5.5), chosen as
/// assimp chooses: binary if the file has
/// exactly 84 + 50 n bytes, n being the facet count at byte 80; else ASCII if its first word is
/// "solid". CGAL's read_STL is not used: it takes "solid" followed by a tab for binary, and when
/// one parser fails it runs the other on the same output, appending the second parse to what
/// the first left. An ASCII file's text is checked first (checkAsciiStlText), unless it holds
/// NUL bytes (binary content, which CGAL then fails on).
Reason readStl(const std::string& path, const std::string& head, std::vector<StlPoint>& points,
               std::vector<SoupPolygon>& triangles, ReadWarnings& warnings) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return "cannot find its size";
  std::uint32_t facets = 0;
  if (head.size() >= 84) std::memcpy(&facets, head.data() + 80, sizeof facets);
  const bool binary = size >= 84 && size == 84 + 50 * std::uintmax_t{facets};
  const std::size_t word = head.find_first_not_of(" \t\r\n\v\f");
  if (!binary && (word == std::string::npos || head.compare(word, 5, "solid") != 0))
    return "neither binary (" + std::to_string(size) +
           " bytes, not 84 + 50 x its facet count) "
           "nor ASCII (no 'solid' first)";
  if (binary) {
    if (Reason reason = readBinaryStl(path, facets, points); !reason.empty()) return reason;
  } else {
    const std::optional<std::string> text = readText(path);
    if (!text) return "cannot read the file";
    StlRecords records;
    if (text->find('\0') == std::string::npos) {
      checkAsciiStlText(path, *text, warnings, &records);
    } else {
      records.plain = false;
    }
    if (!records.plain) {
      std::ifstream in(path, std::ios::binary);
      return runCgal(
          [&] { return CGAL::IO::internal::parse_ASCII_STL(in, points, triangles, true); });
    }
    // The facets the check read: not parsed a second time.
    points.resize(records.corners.size());
    for (std::size_t i = 0; i < records.corners.size(); ++i) points[i].c = records.corners[i];
  }
  // Read here, each facet keeps its own three corners, which readSurface welds by exact
  // position as it welds the points CGAL's parsers merged.
  triangles.resize(points.size() / 3);
  for (std::size_t f = 0; f < triangles.size(); ++f) triangles[f] = {3 * f, 3 * f + 1, 3 * f + 2};
  return "";
}

/// Reads an OBJ, OFF, PLY or STL file (`extension` in lower case) as CGAL's readers read it, or
/// returns why not.
/// Malformed lines throw; warnings go into the soup.
std::variant<PolygonSoup, Reason> readWithCgal(const std::string& path,
                                               const std::string& extension,
                                               const std::string& head) {
  if (head.empty()) return Reason("the file is empty");
  ReadWarnings warnings(path);
  PolygonSoup soup;
  Reason reason;
  bool linesChecked = false;  // faces without corners were warned about and are dropped
  if (extension == "obj") {
    auto read = readObj(path, warnings);
    if (auto* r = std::get_if<Reason>(&read)) return *r;
    soup = std::move(std::get<PolygonSoup>(read));
    if (soup.onlyPointsOrLines) return soup;
  } else if (extension == "stl") {
    std::vector<StlPoint> points;
    reason = readStl(path, head, points, soup.polygons, warnings);
    soup.points = toVec3(points);
    soup.inputVertices = 3 * soup.polygons.size();
  } else {
    const bool ply = extension == "ply";
    std::optional<PlyHeader> plyHeader;
    if (ply) {
      plyHeader = parsePlyHeader(head);
      reason = plyHeaderProblem(*plyHeader);
    } else {
      reason = offHeaderProblem(parseOffHeader(head));
    }
    if (!reason.empty()) return reason;
    linesChecked = !ply || plyHeader->format == "ascii";
    OffRecords off;
    if (linesChecked) {
      const std::optional<std::string> text = readText(path);
      if (!text) return Reason("cannot read the file");
      if (ply)
        checkAsciiPlyText(path, *text, parsePlyHeader(*text), warnings);
      else
        checkOffText(path, *text, parseOffHeader(*text), warnings, &off);
    }
    if (!ply && off.plain) {
      // A plain OFF file's records, read while checking them, are what CGAL would read: its
      // stream parser is not run a second time over the text (it took 3/4 of reading the
      // bunny).
      soup.points = toVec3(off.vertices);
      soup.polygons = std::move(off.faces);
    } else {
      std::vector<CgalPoint> points;
      reason = runCgal([&] {
        const auto verbose = CGAL::parameters::verbose(true);
        return ply ? CGAL::IO::read_PLY(path, points, soup.polygons, verbose)
                   : CGAL::IO::read_OFF(path, points, soup.polygons, verbose);
      });
      soup.points = toVec3(points);
    }
    soup.inputVertices = soup.points.size();
  }
  if (!reason.empty()) return reason;
  if (soup.points.empty()) return Reason("no vertices");
  if (linesChecked)
    std::erase_if(soup.polygons, [](const SoupPolygon& polygon) { return polygon.empty(); });
  reason = checkIndices(soup.polygons, soup.points.size());
  if (!reason.empty()) return reason;
  soup.warnings = warnings.lines();
  return soup;
}

}  // namespace

TriangleSurface readSurface(const std::string& path, SurfaceReadInfo* info) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "no such file");
  if (fs::is_directory(status)) fail(path, "is a directory; give the path of a mesh file");
  const std::string head = readHead(path);
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec) checkDeclaredCounts(path, head, size);

  SurfaceReadInfo counts;
  SurfaceBuilder builder(path, counts);
  std::size_t inputFaces = 0;  // faces with three or more corners
  std::vector<Vec3> corners;
  const auto requireFinite = [&](const Vec3& p) {
    if (!p.allFinite())
      fail(path, "a vertex has a non-finite coordinate (NaN or infinity); fix the file");
  };
  // Adds a face whose corners are in `corners` (points and lines are counted, not added).
  const auto addFace = [&] {
    if (corners.empty()) return;
    if (corners.size() == 1) {
      ++counts.ignoredPoints;
      return;
    }
    if (corners.size() == 2) {
      ++counts.ignoredLines;
      return;
    }
    ++inputFaces;
    for (const Vec3& p : corners) requireFinite(p);
    if (corners.size() == 3) {
      builder.addTriangle(corners[0], corners[1], corners[2]);
    } else {
      ++counts.polygons;
      builder.addPolygon(corners);
    }
  };

  const std::string extension = lowercase(fs::path(path).extension().string());
  Reason cgalReason;
  std::optional<PolygonSoup> soup;
  if (extension == ".obj" || extension == ".off" || extension == ".ply" || extension == ".stl") {
    auto read = readWithCgal(path, extension.substr(1), head);
    if (auto* reason = std::get_if<Reason>(&read))
      cgalReason = *reason;
    else
      soup = std::move(std::get<PolygonSoup>(read));
  }

  if (soup) {
    if (soup->onlyPointsOrLines)
      fail(path, "contains only points/lines, no triangles; polydg needs a surface mesh");
    counts.reader = "cgal";
    counts.meshes = soup->meshes;
    counts.inputVertices = soup->inputVertices;
    builder.reserve(soup->points.size(), soup->polygons.size());
    std::vector<std::uint32_t> welded(soup->points.size(), SurfaceBuilder::kNoVertex);
    for (const SoupPolygon& polygon : soup->polygons) {
      if (polygon.size() == 3) {  // nearly every face: its points welded once each
        std::array<Vec3, 3> at;
        for (int k = 0; k < 3; ++k) {
          at[k] = canonical(soup->points[polygon[k]]);
          requireFinite(at[k]);
        }
        ++inputFaces;
        builder.addTriangle({polygon[0], polygon[1], polygon[2]}, at, welded);
        continue;
      }
      corners.clear();
      for (std::size_t v : polygon) corners.push_back(canonical(soup->points[v]));
      addFace();
    }
    counts.ignoredPoints += soup->ignoredPoints;
    counts.ignoredLines += soup->ignoredLines;
    counts.warnings = std::move(soup->warnings);
  } else {
    const ImportedScene scene = importWithAssimp(path, cgalReason);
    if (!scene.error.empty()) fail(path, scene.error);
    counts.reader = "assimp";
    counts.meshes = scene.meshes.size();
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
      const ImportedMesh& mesh = scene.meshes[m];
      counts.inputVertices += mesh.vertices.size();
      std::size_t next = 0;
      for (const unsigned size : mesh.faceSizes) {
        corners.clear();
        for (unsigned k = 0; k < size; ++k) {
          const unsigned v = mesh.corners[next++];
          if (v >= mesh.vertices.size())
            fail(path, "mesh " + std::to_string(m) + " refers to vertex " + std::to_string(v) +
                           " of " + std::to_string(mesh.vertices.size()) + "; the file is corrupt");
          corners.push_back(canonical(mesh.vertices[v]));
        }
        addFace();
      }
    }
  }

  if (builder.numTriangles() == 0) {
    if (inputFaces == 0)
      fail(path, "contains only points/lines, no triangles; polydg needs a surface mesh");
    fail(path, "no face has three distinct vertices (" + std::to_string(inputFaces) +
                   " degenerate); polydg needs a surface mesh");
  }
  counts.weldedVertices = builder.numVertices();
  counts.triangles = builder.numTriangles();
  if (info != nullptr) *info = counts;
  return builder.take();
}

ImportedScene importWithAssimp(const std::string& path, const std::string& cgalReason) {
  // Loaded once; a failure is not remembered, so a later call tries again.
  static const auto import = reinterpret_cast<ImportWithAssimp>(
      loadModuleEntry(POLYDG_ASSIMP_MODULE, POLYDG_BIN_TO_LIB, kImportWithAssimp,
                      "reading " + path + " (a format CGAL does not read)", "reinstall polydg"));
  ImportedScene scene;
  import(path, cgalReason, scene);
  return scene;
}

}  // namespace polydg
