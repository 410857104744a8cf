// Checks of surface file text before CGAL parses it: warnings for lines that are skipped, errors
// for lines that would be misread or whose loss would change the geometry.
#include "mesh/surface_text_check.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/surface_text_reading.h"

namespace polydg {

// The line and word readers, number parsing and message wording of surface_text_reading.h.
using namespace surface_text;

void ReadWarnings::add(std::size_t line, const std::string& what) {
  ++count_;
  if (kept_.size() < kMaxReadWarnings)
    kept_.push_back(path_ + ":" + std::to_string(line) + ": " + what);
}

std::vector<std::string> ReadWarnings::lines() const {
  std::vector<std::string> out = kept_;
  if (count_ > kept_.size())
    out.push_back("... and " + std::to_string(count_ - kept_.size()) + " more");
  return out;
}

void failAtLine(const std::string& path, std::size_t line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

}  // namespace

bool isDecimalNumber(std::string_view t) {
  std::size_t i = 0;
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  std::size_t digits = 0;
  for (; i < t.size() && isDigit(t[i]); ++i) ++digits;
  if (i < t.size() && t[i] == '.')
    for (++i; i < t.size() && isDigit(t[i]); ++i) ++digits;
  if (digits == 0) return false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    std::size_t exponent = 0;
    for (; i < t.size() && isDigit(t[i]); ++i) ++exponent;
    if (exponent == 0) return false;
  }
  return i == t.size();
}

bool isIntegerNumber(std::string_view t) {
  std::size_t i = t.starts_with('+') || t.starts_with('-') ? 1 : 0;
  if (i == t.size()) return false;
  for (; i < t.size(); ++i)
    if (!isDigit(t[i])) return false;
  return true;
}

// --- OFF --------------------------------------------------------------------------------------

OffHeader parseOffHeader(std::string_view text) {
  OffHeader header;
  LineReader lines(text, 0, 1);
  std::string_view line;
  std::vector<std::string_view> w;
  // The keyword: the first word of the first line that is not blank or a comment.
  while (lines.next(line)) {
    splitWords(uncommented(line), w);
    if (!w.empty()) break;
  }
  if (w.empty()) return header;
  header.keyword = w[0];
  // The counts: the rest of the keyword's line, or else the next line that has words.
  w.erase(w.begin());
  while (w.empty() && lines.next(line)) splitWords(uncommented(line), w);
  for (std::size_t k = 0; k < w.size() && k < 3; ++k) header.counts.emplace_back(w[k]);
  if (!header.counts.empty()) {
    const std::string_view last = w[header.counts.size() - 1];
    header.dataOffset = static_cast<std::size_t>(last.data() + last.size() - text.data());
  }
  header.dataLine = lines.number();
  return header;
}

void checkOffText(const std::string& path, std::string_view text, const OffHeader& header,
                  ReadWarnings& warnings, OffRecords* values) {
  if (header.counts.size() < 3)
    failAtLine(path, header.dataLine,
               "the header has " + std::to_string(header.counts.size()) +
                   " of the vertex, face and edge counts; write all three on one line (the edge "
                   "count may be 0)");
  for (const std::string& c : header.counts)
    if (!isIntegerNumber(c) || c.starts_with('-') || !integerValue(c))
      failAtLine(path, header.dataLine,
                 "header count " + quoted(c) + " is not a count; correct it");
  const auto count = [&](std::size_t k) {
    return static_cast<std::uint64_t>(integerValue(header.counts.at(k)).value_or(0));
  };
  const std::uint64_t vertices = count(0), faces = count(1);
  // "4OFF" (after the optional ST, C and N): homogeneous coordinates x y z w.
  const bool homogeneous = header.keyword.find('4') != std::string::npos;
  const std::size_t coordinates = homogeneous ? 4 : 3;
  LineReader lines(text, header.dataOffset, header.dataLine);
  std::string_view line;
  std::vector<std::string_view> w;
  std::uint64_t records = 0, extra = 0;
  std::size_t firstExtraLine = 0;
  OffRecords unused;
  OffRecords& out = values ? *values : unused;
  out.plain = values != nullptr && header.keyword == "OFF";
  if (out.plain) {
    // Room for the counts the header declares, but no more than the text can hold (a vertex
    // line has at least 6 characters, a triangle's 8): a wrong header reserves nothing huge.
    const std::size_t rest = text.size() - std::min(text.size(), header.dataOffset);
    out.vertices.reserve(std::min<std::uint64_t>(vertices, rest / 6));
    out.faces.reserve(std::min<std::uint64_t>(faces, rest / 8));
  }
  while (lines.next(line)) {
    if (out.plain && line.find('#') != std::string_view::npos) out.plain = false;
    splitWords(uncommented(line), w);
    if (w.empty()) continue;
    const std::size_t number = lines.number();
    if (number == header.dataLine) out.plain = false;
    if (records < vertices) {
      std::array<double, 4> xyzw{};
      for (std::size_t k = 0; k < std::min(w.size(), coordinates); ++k)
        if (const std::string problem = coordinateProblem(w[k], &xyzw[k]); !problem.empty())
          failAtLine(path, number, problem + "; correct it");
      if (w.size() < coordinates)
        failAtLine(path, number,
                   std::string("a vertex needs ") + (homogeneous ? "x y z w" : "x y z") +
                       " but this line has " + numbers(w.size()) +
                       "; complete it (a vertex left out would renumber every later one)");
      for (std::size_t k = coordinates; k < w.size(); ++k)
        if (!isDecimalNumber(w[k])) {
          warnings.add(number,
                       quoted(w[k]) + " after the vertex's coordinates is not a number; ignored");
          break;
        }
      if (out.plain && w.size() == 3)
        out.vertices.push_back({xyzw[0], xyzw[1], xyzw[2]});
      else
        out.plain = false;
    } else if (records < vertices + faces) {
      const std::optional<long long> size =
          isIntegerNumber(w[0]) ? integerValue(w[0]) : std::nullopt;
      if (!size || *size < 0)
        failAtLine(path, number,
                   "face size " + quoted(w[0]) + " is not a vertex count; correct the face");
      const auto corners = static_cast<std::uint64_t>(*size);
      if (w.size() - 1 < corners)
        failAtLine(path, number,
                   "a face of " + std::to_string(corners) + " vertices lists only " +
                       std::to_string(w.size() - 1) + " indices; complete it");
      // A plain file's face takes the indices as they are checked.
      if (!(corners >= 3 && w.size() == corners + 1)) out.plain = false;
      std::vector<std::size_t>* face = out.plain ? &out.faces.emplace_back(corners) : nullptr;
      for (std::size_t k = 1; k <= corners; ++k) {
        if (!isIntegerNumber(w[k]))
          failAtLine(path, number,
                     "face index " + quoted(w[k]) + " is not an integer; correct the face");
        const std::optional<long long> index = integerValue(w[k]);
        if (!index || *index < 0 || static_cast<std::uint64_t>(*index) >= vertices)
          failAtLine(path, number,
                     "face index " + std::string(w[k]) + " names no vertex (OFF counts from 0, " +
                         std::to_string(vertices) + " vertices); correct the face");
        if (face) (*face)[k - 1] = static_cast<std::size_t>(*index);
      }
      if (corners < 3)
        warnings.add(number, corners == 0   ? "face without vertices; skipped"
                             : corners == 1 ? "face of one vertex (a point); skipped"
                                            : "face of two vertices (a line); skipped");
      for (std::size_t k = corners + 1; k < w.size(); ++k)
        if (!isDecimalNumber(w[k])) {
          warnings.add(number, quoted(w[k]) + " after the face's indices is not a number; ignored");
          break;
        }
    } else {
      out.plain = false;
      if (extra++ == 0) firstExtraLine = number;
    }
    ++records;
    if (!out.plain && !out.vertices.empty()) out = OffRecords{false, {}, {}};
  }
  if (records < vertices + faces)
    failAtLine(path, lines.number(),
               "the file ends after " +
                   (records < vertices ? std::to_string(records) + " of its " +
                                             std::to_string(vertices) + " vertices"
                                       : std::to_string(records - vertices) + " of its " +
                                             std::to_string(faces) + " faces") +
                   "; the file is truncated or its header's counts are wrong");
  if (extra > 0)
    warnings.add(firstExtraLine, std::to_string(extra) + (extra == 1 ? " line" : " lines") +
                                     " after the last of the " + std::to_string(faces) +
                                     " faces the header declares; ignored");
}

// --- PLY --------------------------------------------------------------------------------------

PlyHeader parsePlyHeader(std::string_view text) {
  PlyHeader header;
  LineReader lines(text, 0, 1);
  std::string_view line;
  std::vector<std::string_view> w;
  const auto word = [&](std::size_t k) { return k < w.size() ? std::string(w[k]) : std::string(); };
  while (lines.next(line)) {
    splitWords(line, w);
    const std::string keyword = word(0);
    if (lines.number() == 2) {
      if (keyword != "format") {
        header.problem = "the header's second line is not its format";
        return header;
      }
      header.format = word(1);
    } else if (keyword == "element") {
      header.elements.push_back({word(1), word(2), {}});
      if (!isIntegerNumber(header.elements.back().count) ||
          header.elements.back().count.starts_with('-')) {
        header.problem = "element '" + word(1) + "' has no count";
        return header;
      }
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        header.problem = "a property before any element";
        return header;
      }
      PlyProperty property;
      std::size_t k = 1;
      property.type = word(k++);
      if (property.type == "list") {
        property.sizeType = word(k++);
        property.type = word(k++);
      }
      property.name = word(k);
      header.elements.back().properties.push_back(property);
    } else if (keyword == "end_header") {
      header.dataOffset = lines.position();
      header.dataLine = lines.number() + 1;
      return header;
    }
  }
  header.problem = "no end_header";
  return header;
}

namespace {

/// The range of a PLY integer type; nothing for a real type.
std::optional<std::pair<long long, long long>> integerRange(const std::string& type) {
  if (type == "char" || type == "int8") return std::pair(-128LL, 127LL);
  if (type == "uchar" || type == "uint8") return std::pair(0LL, 255LL);
  if (type == "short" || type == "int16") return std::pair(-32768LL, 32767LL);
  if (type == "ushort" || type == "uint16") return std::pair(0LL, 65535LL);
  if (type == "int" || type == "int32") return std::pair(-2147483648LL, 2147483647LL);
  if (type == "uint" || type == "uint32") return std::pair(0LL, 4294967295LL);
  return std::nullopt;
}

/// Why `token` is not a value of PLY type `type`, or "". An integer value goes to `integer`.
std::string plyValueProblem(std::string_view token, const std::string& type, long long& integer) {
  if (const auto range = integerRange(type)) {
    if (!isIntegerNumber(token)) return quoted(token) + " is not an integer";
    const std::optional<long long> value = integerValue(token);
    if (!value || *value < range->first || *value > range->second)
      return quoted(token) + " is beyond the range of " + type;
    integer = *value;
    return "";
  }
  if (!isDecimalNumber(token)) return quoted(token) + " is not a number";
  const bool finite = type == "float" || type == "float32"
                          ? std::isfinite(realValue<float>(token))
                          : std::isfinite(realValue<double>(token));
  if (!finite) return quoted(token) + " is beyond the range of " + type;
  return "";
}

}  // namespace

void checkAsciiPlyText(const std::string& path, std::string_view text, const PlyHeader& header,
                       ReadWarnings& warnings) {
  std::uint64_t vertices = 0;
  for (const PlyElement& e : header.elements)
    if (e.name == "vertex")
      vertices = static_cast<std::uint64_t>(integerValue(e.count).value_or(0));
  // The face list CGAL reads: vertex_indices, else vertex_index.
  std::string indexList = "vertex_index";
  for (const PlyElement& e : header.elements)
    for (const PlyProperty& p : e.properties)
      if (e.name == "face" && p.name == "vertex_indices") indexList = p.name;

  LineReader lines(text, header.dataOffset, header.dataLine);
  std::string_view line;
  std::vector<std::string_view> w;
  const auto nextRecord = [&] {
    while (lines.next(line)) {
      splitWords(line, w);
      if (!w.empty()) return true;
    }
    return false;
  };
  for (const PlyElement& e : header.elements) {
    const auto count = static_cast<std::uint64_t>(integerValue(e.count).value_or(0));
    for (std::uint64_t item = 0; item < count; ++item) {
      if (!nextRecord())
        failAtLine(path, lines.number(),
                   "the file ends after " + std::to_string(item) + " of its " +
                       std::to_string(count) + " '" + e.name +
                       "' elements; the file is truncated or its header's counts are wrong");
      const std::size_t number = lines.number();
      std::size_t t = 0;  // the next word of the line
      long long integer = 0;
      const auto take = [&](const PlyProperty& p, const std::string& type) {
        if (t == w.size())
          failAtLine(path, number,
                     "the line ends before the '" + p.name + "' of its '" + e.name +
                         "' element; complete it (one element per line)");
        if (const std::string problem = plyValueProblem(w[t], type, integer); !problem.empty())
          failAtLine(path, number,
                     "'" + e.name + "' property '" + p.name + "': " + problem + "; correct it");
        ++t;
      };
      for (const PlyProperty& p : e.properties) {
        if (p.sizeType.empty()) {
          take(p, p.type);
          continue;
        }
        take(p, p.sizeType);
        if (integer < 0)
          failAtLine(path, number,
                     "'" + e.name + "' list '" + p.name + "' has a negative length; correct it");
        const auto size = static_cast<std::uint64_t>(integer);
        const bool indices = e.name == "face" && p.name == indexList;
        for (std::uint64_t k = 0; k < size; ++k) {
          integer = 0;
          take(p, p.type);
          if (indices && (integer < 0 || static_cast<std::uint64_t>(integer) >= vertices))
            failAtLine(path, number,
                       "face index " + std::string(w[t - 1]) +
                           " names no vertex (PLY counts from "
                           "0, " +
                           std::to_string(vertices) + " vertices); correct the face");
        }
        if (indices && size < 3)
          warnings.add(number, size == 0   ? "face without vertices; skipped"
                               : size == 1 ? "face of one vertex (a point); skipped"
                                           : "face of two vertices (a line); skipped");
      }
      if (t < w.size())
        failAtLine(path, number,
                   "the line holds " + std::to_string(w.size()) + " values but one '" + e.name +
                       "' element has " + std::to_string(t) +
                       "; put one element per line (CGAL would read the rest as the next "
                       "element)");
    }
  }
  std::uint64_t extra = 0;
  std::size_t firstExtraLine = 0;
  while (nextRecord())
    if (extra++ == 0) firstExtraLine = lines.number();
  if (extra > 0)
    warnings.add(firstExtraLine, std::to_string(extra) + (extra == 1 ? " line" : " lines") +
                                     " after the last element the header declares; ignored");
}

// --- STL --------------------------------------------------------------------------------------

void checkAsciiStlText(const std::string& path, std::string_view text, ReadWarnings& warnings,
                       StlRecords* values) {
  WordReader words(text);
  std::string_view word;
  bool inFacet = false;
  std::size_t facetLine = 0, corners = 0;
  const auto isKeyword = [](std::string_view s) {
    return s == "solid" || s == "endsolid" || s == "facet" || s == "outer" || s == "vertex" ||
           s == "endloop" || s == "endfacet";
  };
  StlRecords unused;
  StlRecords& out = values ? *values : unused;
  out.plain = values != nullptr;
  const std::size_t warned = warnings.count();
  // CGAL's parser: a "solid" inside a solid stops it (the file then fails), and a solid's name
  // is read as words, so a keyword there would be taken as one.
  bool inSolid = false, solidClosed = false;
  // A number as strtod reads it, "nan" and "inf" included: normals are not used, and
  // exporters write NaN normals for degenerate facets.
  const auto isReal = [](std::string_view s) {
    const std::string copy(s);
    char* end = nullptr;
    std::strtod(copy.c_str(), &end);
    return !copy.empty() && *end == '\0';
  };
  while (words.next(word)) {
    const std::size_t number = words.line();
    if (word == "solid" || word == "endsolid") {
      if (inFacet)
        failAtLine(path, facetLine,
                   "facet without endfacet (the solid ends at line " + std::to_string(number) +
                       "); complete it");
      if (word == "solid" && inSolid) out.plain = false;
      inSolid = word == "solid";
      solidClosed = solidClosed || !inSolid;
      const std::vector<std::string_view> name = words.restOfLine();
      if (std::any_of(name.begin(), name.end(), isKeyword)) out.plain = false;
    } else if (word == "facet") {
      if (inFacet)
        failAtLine(path, facetLine,
                   "facet without endfacet (the next facet starts at line " +
                       std::to_string(number) + "); complete it");
      inFacet = true;
      facetLine = number;
      corners = 0;
      const std::vector<std::string_view> rest = words.restOfLine();
      bool valid = rest.size() == 4 && rest[0] == "normal";
      for (std::size_t k = 1; k < rest.size() && valid; ++k) valid = isReal(rest[k]);
      if (!valid)
        warnings.add(number,
                     "facet line is not 'facet normal nx ny nz'; its normal is ignored "
                     "(normals are not used)");
    } else if (word == "outer") {
      const std::vector<std::string_view> rest = words.restOfLine();
      if (rest.size() != 1 || rest[0] != "loop")
        warnings.add(number, "line is not 'outer loop'; ignored");
    } else if (word == "vertex") {
      if (!inFacet)
        failAtLine(path, number,
                   "vertex outside a facet (CGAL would skip it); put it inside "
                   "'facet normal ... outer loop ... endloop endfacet'");
      std::array<double, 3> corner{};
      for (std::size_t k = 0; k < 3; ++k) {
        std::string_view coordinate;
        if (!words.next(coordinate) || isKeyword(coordinate))
          failAtLine(path, number,
                     "a vertex needs x y z but this one has " + numbers(k) + "; complete it");
        if (const std::string problem = coordinateProblem(coordinate, &corner[k]); !problem.empty())
          failAtLine(path, words.line(), problem + "; correct it");
      }
      if (out.plain) out.corners.push_back(corner);
      if (++corners > 3)
        failAtLine(path, number,
                   "a fourth vertex in the facet of line " + std::to_string(facetLine) +
                       "; STL facets are triangles: split it into two facets");
    } else if (word == "endloop") {
      // Nothing to check: CGAL reads vertices up to endfacet.
    } else if (word == "endfacet") {
      if (!inFacet) {
        warnings.add(number, "endfacet without a facet; ignored");
      } else if (corners != 3) {
        failAtLine(path, facetLine,
                   "facet of " + std::to_string(corners) +
                       (corners == 1 ? " vertex" : " vertices") +
                       "; an STL facet is a triangle: complete or remove it");
      }
      inFacet = false;
    } else {
      warnings.add(number, "unexpected " + quoted(word) + "; ignored up to the end of the line");
      words.restOfLine();
    }
  }
  if (inFacet)
    failAtLine(path, words.line(),
               "the file ends inside the facet of line " + std::to_string(facetLine) +
                   "; the file is truncated");
  if (inSolid || !solidClosed || warnings.count() != warned) out.plain = false;
  if (!out.plain) out.corners.clear();
}

}  // namespace polydg
