// Checks of surface file text before CGAL parses it: warnings for lines that are skipped, errors
// for lines that would be misread or whose loss would change the geometry.
#include "mesh/surface_text_check.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>

namespace polydg {

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

namespace {

/// Characters that separate words in every format here (CR included, so CRLF files read like LF).
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// The words of `line`, into `out` (cleared first, so that one buffer serves every line).
void splitWords(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && isSpace(line[i])) ++i;
    if (i == line.size()) return;
    const std::size_t start = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    out.push_back(line.substr(start, i - start));
  }
}

/// `line` up to its first '#'.
std::string_view uncommented(std::string_view line) {
  return line.substr(0, std::min(line.size(), line.find('#')));
}

/// `token` quoted for a message, shortened if long.
std::string quoted(std::string_view token) {
  constexpr std::size_t kLongest = 40;
  if (token.size() > kLongest) return "'" + std::string(token.substr(0, kLongest - 3)) + "...'";
  return "'" + std::string(token) + "'";
}

/// The lines of a text from `offset` on, numbered from `firstLine`; a line excludes its '\n'.
class LineReader {
 public:
  LineReader(std::string_view text, std::size_t offset, std::size_t firstLine)
      : text_(text), next_(offset), nextNumber_(firstLine), number_(firstLine) {}

  /// The next line, or false at the end of the text.
  bool next(std::string_view& line) {
    if (next_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', next_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(next_, end - next_);
    next_ = end + 1;
    number_ = nextNumber_++;
    return true;
  }
  /// The number of the line `next` returned last (the first line's before any).
  std::size_t number() const { return number_; }
  /// Where the line after the last one returned starts.
  std::size_t position() const { return next_; }

 private:
  std::string_view text_;
  std::size_t next_, nextNumber_, number_;
};

/// The words of a text one by one with their line numbers, as a stream reader takes them.
class WordReader {
 public:
  explicit WordReader(std::string_view text) : lines_(text, 0, 1) {}

  bool next(std::string_view& word) {
    while (index_ == words_.size()) {
      std::string_view line;
      if (!lines_.next(line)) return false;
      splitWords(line, words_);
      index_ = 0;
    }
    word = words_[index_++];
    return true;
  }
  /// The words after the last one returned, up to the end of its line; they are skipped.
  std::vector<std::string_view> restOfLine() {
    std::vector<std::string_view> rest(words_.begin() + static_cast<std::ptrdiff_t>(index_),
                                       words_.end());
    index_ = words_.size();
    return rest;
  }
  /// The line of the last word returned.
  std::size_t line() const { return lines_.number(); }

 private:
  LineReader lines_;
  std::vector<std::string_view> words_;
  std::size_t index_ = 0;
};

/// The value of a token isDecimalNumber accepts, correctly rounded to T; +-infinity if it is
/// beyond T's range (a value too small for T is its nearest subnormal or zero, as streams read
/// it).
template <typename T>
T realValue(std::string_view token) {
  if (token.starts_with('+')) token.remove_prefix(1);
  T value{};
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error == std::errc()) return value;
  // Out of range: from_chars does not say which way.
  const std::string text(token);
  if constexpr (std::is_same_v<T, float>)
    return std::strtof(text.c_str(), nullptr);
  else
    return std::strtod(text.c_str(), nullptr);
}

/// The value of a token isIntegerNumber accepts, or nothing if it is beyond 64 bits.
std::optional<long long> integerValue(std::string_view token) {
  if (token.starts_with('+')) token.remove_prefix(1);
  long long value = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc()) return std::nullopt;
  return value;
}

/// Why `token` is not a finite double, or "" if it is one.
std::string coordinateProblem(std::string_view token) {
  if (!isDecimalNumber(token)) return "coordinate " + quoted(token) + " is not a number";
  if (!std::isfinite(realValue<double>(token)))
    return "coordinate " + quoted(token) + " is beyond the range of double";
  return "";
}

/// "1 number", "2 numbers".
std::string numbers(std::size_t n) { return std::to_string(n) + (n == 1 ? " number" : " numbers"); }

// --- OBJ --------------------------------------------------------------------------------------

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

}  // namespace

ObjText checkObjText(const std::string& path, std::string_view text, ReadWarnings& warnings) {
  ObjText out;
  if (text.find('\0') != std::string_view::npos) {
    out.assimpReason = "the file is not text (NUL bytes)";
    return out;
  }
  // A UTF-8 byte order mark is no part of the first line (it would make "v" a word of its own).
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  out.cgalText.reserve(text.size());
  std::string material;          // the default material until the first usemtl
  bool materialCounted = false;  // `material` is in out.materials already
  const auto allVertices = static_cast<long long>(countObjVertices(text));
  LineReader lines(text, 0, 1);
  std::string_view raw;
  std::string line;                 // one buffer for every line
  std::vector<std::string_view> w;  // and one for its words
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
    if (w.empty()) {
      out.cgalText += '\n';
      continue;
    }
    const std::string_view keyword = w[0];
    const auto useMaterial = [&] {
      if (!materialCounted) out.materials.insert(material);
      materialCounted = true;
    };
    if (keyword == "v") {
      ++out.vertices;
      const std::size_t n = w.size() - 1;
      for (std::size_t k = 1; k <= std::min<std::size_t>(n, 3); ++k)
        if (const std::string problem = coordinateProblem(w[k]); !problem.empty())
          failAtLine(path, number, problem + "; correct it");
      if (n < 3)
        failAtLine(path, number,
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
        warnings.add(number,
                     quoted(notNumber) + " after the vertex's x y z is not a number; ignored");
      } else if (n == 4 && realValue<double>(w[4]) != 1.0) {
        if (out.assimpReason.empty())
          out.assimpReason = "line " + std::to_string(number) + ": homogeneous vertex (w != 1)";
      } else if (n != 3 && n != 4 && n != 6) {
        warnings.add(number, numbers(n - 3) +
                                 " after the vertex's x y z (neither a weight w nor a colour r g "
                                 "b); ignored");
      }
      out.cgalText += "v ";
      out.cgalText += w[1];
      out.cgalText += ' ';
      out.cgalText += w[2];
      out.cgalText += ' ';
      out.cgalText += w[3];
    } else if (keyword == "f") {
      const std::size_t corners = w.size() - 1;
      if (corners == 0) {
        warnings.add(number, "face without vertex indices; skipped");
      } else if (corners < 3) {
        useMaterial();
        (corners == 1 ? out.points : out.lines) += 1;
        warnings.add(number, corners == 1 ? "face of one corner (a point); skipped"
                                          : "face of two corners (a line); skipped");
      } else {
        ++out.faces;
        useMaterial();
        out.cgalText += 'f';
        bool attributeWarned = false;
        for (std::size_t k = 1; k < w.size(); ++k) {
          // A corner: v, v/vt, v//vn or v/vt/vn.
          const std::string_view corner = w[k];
          const std::string_view vertex = corner.substr(0, corner.find('/'));
          if (!isIntegerNumber(vertex))
            failAtLine(path, number,
                       (vertex.empty() ? "face corner " + quoted(corner) + " has no vertex index"
                                       : "face index " + quoted(vertex) + " is not an integer") +
                           "; correct the face");
          const std::optional<long long> index = integerValue(vertex);
          const auto before = static_cast<long long>(out.vertices);
          if (index && *index == 0)
            failAtLine(path, number,
                       "face index 0 names no vertex (OBJ counts vertices from 1, and from -1 "
                       "backwards); correct the face");
          if (vertex.starts_with('-') && (!index || *index < -before))
            failAtLine(path, number,
                       "face index " + std::string(vertex) +
                           " counts back past the first vertex (" + std::to_string(before) +
                           " precede this line); correct the face");
          if (!vertex.starts_with('-') && (!index || *index > allVertices))
            failAtLine(path, number,
                       "face index " + std::string(vertex) + " is beyond the " +
                           std::to_string(allVertices) +
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
            warnings.add(number, "texture/normal reference in face corner " + quoted(corner) +
                                     " is not an integer; ignored (only vertex indices are used)");
          }
          out.cgalText += ' ';
          out.cgalText += vertex;
        }
      }
    } else if (keyword == "p") {
      out.points += w.size() - 1;
      useMaterial();
    } else if (keyword == "l") {
      out.lines += w.size() > 2 ? w.size() - 2 : 0;
      useMaterial();
    } else if (keyword == "vt" || keyword == "vn" || keyword == "vp") {
      // Attributes: checked only so that a broken line is not passed over in silence.
      const std::size_t n = w.size() - 1;
      bool valid = keyword == "vn" ? n == 3 : n >= 1 && n <= 3;
      for (std::size_t k = 1; k < w.size() && valid; ++k) valid = isDecimalNumber(w[k]);
      if (!valid)
        warnings.add(number, "malformed '" + std::string(keyword) + "' line (" +
                                 (keyword == "vn" ? "3 numbers" : "1 to 3 numbers") +
                                 " expected); ignored");
    } else if (keyword == "usemtl") {
      const std::size_t start = line.find("usemtl") + 6;
      material = line.substr(std::min(line.size(), line.find_first_not_of(' ', start)));
      materialCounted = false;
    } else if (isFreeFormObjKeyword(keyword)) {
      warnings.add(number,
                   "free-form geometry (" + quoted(keyword) + ") is not supported; line skipped");
    } else if (!isQuietObjKeyword(keyword)) {
      warnings.add(number, "unknown keyword " + quoted(keyword) + "; line skipped");
    }
    out.cgalText += '\n';
  }
  return out;
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
                  ReadWarnings& warnings) {
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
  while (lines.next(line)) {
    splitWords(uncommented(line), w);
    if (w.empty()) continue;
    const std::size_t number = lines.number();
    if (records < vertices) {
      for (std::size_t k = 0; k < std::min(w.size(), coordinates); ++k)
        if (const std::string problem = coordinateProblem(w[k]); !problem.empty())
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
      for (std::size_t k = 1; k <= corners; ++k) {
        if (!isIntegerNumber(w[k]))
          failAtLine(path, number,
                     "face index " + quoted(w[k]) + " is not an integer; correct the face");
        const std::optional<long long> index = integerValue(w[k]);
        if (!index || *index < 0 || static_cast<std::uint64_t>(*index) >= vertices)
          failAtLine(path, number,
                     "face index " + std::string(w[k]) + " names no vertex (OFF counts from 0, " +
                         std::to_string(vertices) + " vertices); correct the face");
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
    } else if (extra++ == 0) {
      firstExtraLine = number;
    }
    ++records;
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

void checkAsciiStlText(const std::string& path, std::string_view text, ReadWarnings& warnings) {
  WordReader words(text);
  std::string_view word;
  bool inFacet = false;
  std::size_t facetLine = 0, corners = 0;
  const auto isKeyword = [](std::string_view s) {
    return s == "solid" || s == "endsolid" || s == "facet" || s == "outer" || s == "vertex" ||
           s == "endloop" || s == "endfacet";
  };
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
      words.restOfLine();  // the name
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
      for (std::size_t k = 0; k < 3; ++k) {
        std::string_view coordinate;
        if (!words.next(coordinate) || isKeyword(coordinate))
          failAtLine(path, number,
                     "a vertex needs x y z but this one has " + numbers(k) + "; complete it");
        if (const std::string problem = coordinateProblem(coordinate); !problem.empty())
          failAtLine(path, words.line(), problem + "; correct it");
      }
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
}

}  // namespace polydg
