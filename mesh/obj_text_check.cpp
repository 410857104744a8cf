// The OBJ check of mesh/surface_text_check.h: each line of an OBJ file checked, and its vertices
// and faces read as CGAL's OBJ reader (CGAL/IO/OBJ.h) reads them.
#include <algorithm>
#include <array>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/surface_text_check.h"
#include "mesh/surface_text_reading.h"

namespace polydg {

namespace {

// The line and word readers, number parsing and message wording of surface_text_reading.h.
using namespace surface_text;

/// Keywords that need no word here: groups, materials, display and rendering attributes, and
/// the `p` and `l` primitives (counted, skipped by design).
bool isQuietObjKeyword(std::string_view k) {
  static const std::set<std::string_view> kQuiet = {
      "g",      "o",      "s",          "mg",        "usemtl",   "mtllib",
      "usemap", "maplib", "bevel",      "lod",       "c_interp", "d_interp",
      "ctech",  "stech",  "shadow_obj", "trace_obj", "p",        "l"};
  return kQuiet.contains(k);
}

/// Free-form curves and surfaces: valid OBJ that neither CGAL nor assimp turns into triangles.
bool isFreeFormObjKeyword(std::string_view k) {
  static const std::set<std::string_view> kFreeForm = {
      "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
      "scrv",   "sp",  "end",  "con",  "bsp",  "bzp",   "cdc",  "cdp",  "res"};
  return kFreeForm.contains(k);
}

/// The first word of an OBJ line (comments cut, control white space as spaces).
std::string_view firstObjWord(std::string_view line) {
  line = uncommented(line);
  std::size_t begin = 0;
  while (begin < line.size() && isSpace(line[begin])) ++begin;
  std::size_t end = begin;
  while (end < line.size() && !isSpace(line[end])) ++end;
  return line.substr(begin, end - begin);
}

/// The number of `v` lines: face indices may refer forward (CGAL and assimp both allow it), so
/// a positive index is checked against this count.
std::size_t countObjVertices(std::string_view text) {
  LineReader lines(text, 0, 1);
  std::string_view line;
  std::size_t vertices = 0;
  while (lines.next(line))
    if (firstObjWord(line) == "v") ++vertices;
  return vertices;
}

using Words = std::vector<std::string_view>;

/// The checks of an OBJ file's lines by keyword, and what they share: the result, the
/// warnings and the material in use.
class ObjLineChecks {
 public:
  ObjLineChecks(const std::string& path, ObjText& out, ReadWarnings& warnings,
                long long allVertices)
      : path_(path), out_(out), warnings_(warnings), allVertices_(allVertices) {
    out_.positions.reserve(static_cast<std::size_t>(allVertices));
  }

  /// A `v` line: x y z, then perhaps a weight w or a colour r g b.
  void vertex(std::size_t number, const Words& w) {
    const std::size_t n = w.size() - 1;
    std::array<double, 3> xyz{};
    for (std::size_t k = 1; k <= std::min<std::size_t>(n, 3); ++k)
      if (const std::string problem = coordinateProblem(w[k], &xyz[k - 1]); !problem.empty())
        failAtLine(path_, number, problem + "; correct it");
    if (n < 3)
      failAtLine(path_, number,
                 "a vertex needs x y z but this line has " + numbers(n) +
                     "; complete it (a vertex left out would renumber every later one)");
    // After x y z: a weight w (homogeneous coordinates) or a colour r g b.
    bool allNumbers = true;
    std::string_view notNumber;
    for (std::size_t k = 4; k <= n && allNumbers; ++k)
      if (!isDecimalNumber(w[k])) {
        allNumbers = false;
        notNumber = w[k];
      }
    if (!allNumbers) {
      warnings_.add(number,
                    quoted(notNumber) + " after the vertex's x y z is not a number; ignored");
    } else if (n == 4 && realValue<double>(w[4]) != 1.0) {
      if (out_.assimpReason.empty())
        out_.assimpReason = "line " + std::to_string(number) + ": homogeneous vertex (w != 1)";
    } else if (n != 3 && n != 4 && n != 6) {
      warnings_.add(number, numbers(n - 3) +
                                " after the vertex's x y z (neither a weight w nor a colour r g "
                                "b); ignored");
    }
    out_.positions.push_back(xyz);
  }

  /// An `f` line: a point or a line if it has fewer than three corners, else a face whose
  /// corners are checked one by one.
  void face(std::size_t number, const Words& w) {
    const std::size_t corners = w.size() - 1;
    if (corners == 0) {
      warnings_.add(number, "face without vertex indices; skipped");
    } else if (corners < 3) {
      useMaterial();
      (corners == 1 ? out_.points : out_.lines) += 1;
      warnings_.add(number, corners == 1 ? "face of one corner (a point); skipped"
                                         : "face of two corners (a line); skipped");
    } else {
      useMaterial();
      std::vector<std::size_t>& polygon = out_.polygons.emplace_back();
      polygon.reserve(corners);
      bool attributeWarned = false;
      for (std::size_t k = 1; k < w.size(); ++k)
        polygon.push_back(faceCorner(number, w[k], attributeWarned));
    }
  }

  /// `p`, `l`, attribute and `usemtl` lines, and every other keyword (`line`: the line with
  /// its comment cut and its white space as spaces).
  void other(std::size_t number, const Words& w, const std::string& line) {
    const std::string_view keyword = w[0];
    if (keyword == "p") {
      out_.points += w.size() - 1;
      useMaterial();
    } else if (keyword == "l") {
      out_.lines += w.size() > 2 ? w.size() - 2 : 0;
      useMaterial();
    } else if (keyword == "vt" || keyword == "vn" || keyword == "vp") {
      // Attributes: checked only so that a broken line is not passed over in silence.
      const std::size_t n = w.size() - 1;
      bool valid = keyword == "vn" ? n == 3 : n >= 1 && n <= 3;
      for (std::size_t k = 1; k < w.size() && valid; ++k) valid = isDecimalNumber(w[k]);
      if (!valid)
        warnings_.add(number, "malformed '" + std::string(keyword) + "' line (" +
                                  (keyword == "vn" ? "3 numbers" : "1 to 3 numbers") +
                                  " expected); ignored");
    } else if (keyword == "usemtl") {
      const std::size_t start = line.find("usemtl") + 6;
      material_ = line.substr(std::min(line.size(), line.find_first_not_of(' ', start)));
      materialCounted_ = false;
    } else if (isFreeFormObjKeyword(keyword)) {
      warnings_.add(number,
                    "free-form geometry (" + quoted(keyword) + ") is not supported; line skipped");
    } else if (!isQuietObjKeyword(keyword)) {
      warnings_.add(number, "unknown keyword " + quoted(keyword) + "; line skipped");
    }
  }

 private:
  /// Counts the material in use, once until the next usemtl.
  void useMaterial() {
    if (!materialCounted_) out_.materials.insert(material_);
    materialCounted_ = true;
  }

  /// A corner of a face (v, v/vt, v//vn or v/vt/vn): its vertex index must name a vertex; a
  /// malformed texture or normal reference is warned about once per face. Returns the vertex
  /// from 0: i - 1 for an index i from 1, the vertices before this line plus i for an index i
  /// counted back from -1 (CGAL's OBJ reader does the same).
  std::size_t faceCorner(std::size_t number, std::string_view corner, bool& attributeWarned) {
    const std::string_view vertex = corner.substr(0, corner.find('/'));
    if (!isIntegerNumber(vertex))
      failAtLine(path_, number,
                 (vertex.empty() ? "face corner " + quoted(corner) + " has no vertex index"
                                 : "face index " + quoted(vertex) + " is not an integer") +
                     "; correct the face");
    const std::optional<long long> index = integerValue(vertex);
    const auto before = static_cast<long long>(out_.positions.size());
    if (index && *index == 0)
      failAtLine(path_, number,
                 "face index 0 names no vertex (OBJ counts vertices from 1, and from -1 "
                 "backwards); correct the face");
    if (vertex.starts_with('-') && (!index || *index < -before))
      failAtLine(path_, number,
                 "face index " + std::string(vertex) + " counts back past the first vertex (" +
                     std::to_string(before) + " precede this line); correct the face");
    if (!vertex.starts_with('-') && (!index || *index > allVertices_))
      failAtLine(path_, number,
                 "face index " + std::string(vertex) + " is beyond the " +
                     std::to_string(allVertices_) +
                     " vertices of the file; correct the face or add the missing vertices");
    // Texture and normal references play no part in the geometry.
    std::size_t parts = 1;
    bool malformed = false;
    for (std::size_t slash = corner.find('/'); slash != std::string_view::npos;
         slash = corner.find('/', slash + 1)) {
      ++parts;
      const std::size_t next = corner.find('/', slash + 1);
      const std::string_view part = corner.substr(slash + 1, next - slash - 1);
      if (!part.empty() && !isIntegerNumber(part)) malformed = true;
    }
    if ((malformed || parts > 3) && !attributeWarned) {
      attributeWarned = true;
      warnings_.add(number, "texture/normal reference in face corner " + quoted(corner) +
                                " is not an integer; ignored (only vertex indices are used)");
    }
    return static_cast<std::size_t>(*index > 0 ? *index - 1 : before + *index);
  }

  const std::string& path_;
  ObjText& out_;
  ReadWarnings& warnings_;
  const long long allVertices_;
  std::string material_;          // the default material until the first usemtl
  bool materialCounted_ = false;  // `material_` is in out_.materials already
};

}  // namespace

ObjText checkObjText(const std::string& path, std::string_view text, ReadWarnings& warnings) {
  ObjText out;
  if (text.find('\0') != std::string_view::npos) {
    out.assimpReason = "the file is not text (NUL bytes)";
    return out;
  }
  // A UTF-8 byte order mark is no part of the first line (it would make "v" a word of its own).
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  ObjLineChecks checks(path, out, warnings, static_cast<long long>(countObjVertices(text)));
  LineReader lines(text, 0, 1);
  std::string_view raw;
  std::string line;  // one buffer for every line
  Words w;           // and one for its words
  while (lines.next(raw)) {
    const std::size_t number = lines.number();
    line.assign(raw.substr(0, std::min(raw.size(), raw.find('#'))));
    for (char& c : line)
      if (isSpace(c)) c = ' ';
    while (!line.empty() && line.back() == ' ') line.pop_back();
    if (!line.empty() && line.back() == '\\') {
      out.assimpReason = "line " + std::to_string(number) + ": line continuation";
      return out;
    }
    splitWords(line, w);
    if (w.empty()) continue;
    if (w[0] == "v")
      checks.vertex(number, w);
    else if (w[0] == "f")
      checks.face(number, w);
    else
      checks.other(number, w, line);
  }
  return out;
}

}  // namespace polydg
