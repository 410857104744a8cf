// Line-by-line checks of the text of OBJ, OFF, ASCII PLY and ASCII STL surface files, run before
// CGAL parses them (readSurface, polydg/mesh/surface_io.h): a line that can be skipped without
// changing the geometry becomes a warning, a line that would change the geometry if skipped or
// misread is an error (std::runtime_error "FILE:LINE: what is wrong; what to do"). The rule, per
// format, is documented with readSurface.
#pragma once

#include <array>
#include <cstddef>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "polydg/mesh/surface_io.h"

namespace polydg {

/// Warnings about the lines of one file, each "FILE:LINE: what; what was done": the first
/// kMaxReadWarnings are kept, the rest only counted.
class ReadWarnings {
 public:
  explicit ReadWarnings(std::string path) : path_(std::move(path)) {}
  /// Adds the warning `what` about line `line` (1-based).
  void add(std::size_t line, const std::string& what);
  /// The kept warnings in the order added, then "... and N more" if N were left out.
  std::vector<std::string> lines() const;
  /// Warnings added, kept or not.
  std::size_t count() const { return count_; }

 private:
  std::string path_;
  std::vector<std::string> kept_;
  std::size_t count_ = 0;
};

/// Throws std::runtime_error(path + ":" + line + ": " + what); `what` says what is wrong and,
/// after a semicolon, what to do.
[[noreturn]] void failAtLine(const std::string& path, std::size_t line, const std::string& what);

/// True if `token` is a whole decimal number as C++ streams (CGAL's readers) and strtod read it:
/// [+-] digits [. [digits]] or [+-] . digits, then optionally [eE] [+-] digits. Not "inf", "nan",
/// hexadecimal, or a number followed by anything ("3.1+e2", "1,5", "2x").
bool isDecimalNumber(std::string_view token);

/// True if `token` is [+-] digits.
bool isIntegerNumber(std::string_view token);

/// What checkObjText found in an OBJ file, and its vertices and faces.
struct ObjText {
  /// The `v` lines' x y z (correctly rounded, as CGAL's stream reader rounds them), in order:
  /// one per `v` line.
  std::vector<std::array<double, 3>> positions;
  /// The `f` lines of three or more corners: their vertex indices from 0, a relative (negative)
  /// index resolved against the vertices before its line, as CGAL's OBJ reader resolves it.
  std::vector<std::vector<std::size_t>> polygons;
  std::size_t points = 0;           ///< `p` indices and faces of one corner
  std::size_t lines = 0;            ///< `l` segments and faces of two corners
  std::set<std::string> materials;  ///< used by faces, points and lines ("" before any usemtl)
  /// Not empty: polydg must not read this file itself (homogeneous coordinates, which CGAL's
  /// reader ignored too; a line continuation; NUL bytes): assimp does, and the warnings do not
  /// apply.
  std::string assimpReason;
};

/// Checks the OBJ `text` of the file at `path` line by line (comments cut at '#'; tabs, CRs and
/// other control white space are spaces) and returns its vertices and faces. Warnings go to
/// `warnings`; errors throw (failAtLine). The rule is the OBJ part of readSurface's table.
ObjText checkObjText(const std::string& path, std::string_view text, ReadWarnings& warnings);

/// The header of an ASCII OFF file: "[ST][C][N][4][n]OFF" (or anything else, for the caller to
/// refuse), then the vertex, face and edge counts on one line; '#' starts a comment.
struct OffHeader {
  std::string keyword;              ///< "" if the file has no token at all
  std::vector<std::string> counts;  ///< up to three tokens of the line that follows the keyword
  std::size_t dataOffset = 0;       ///< where the vertex records start: just after the counts
  std::size_t dataLine = 0;         ///< the line (1-based) holding dataOffset
};
OffHeader parseOffHeader(std::string_view text);

/// The records of a plain OFF file, read while checkOffText checks them.
struct OffRecords {
  /// The file is plain: keyword "OFF", no comment in its records, no record on the counts'
  /// line, each vertex record exactly x y z, each face record exactly its size (3 or more)
  /// and that many indices, nothing after the last face. Then the values below are what
  /// CGAL's reader would make of it (numbers rounded correctly, as streams read them), and
  /// nothing else is.
  bool plain = true;
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::vector<std::size_t>> faces;
};

/// Checks the counts and records of an ASCII OFF file whose header keyword is one of CGAL's
/// forms: three counts on one line (a missing edge count is an error: CGAL and assimp would both
/// read it from the first vertex line), then vertex records, the comment-free, non-blank lines
/// after the counts (the rest of the counts line is one, if not blank, as CGAL reads it). If
/// `values` is given, also reads the records of a plain file into it (see OffRecords).
void checkOffText(const std::string& path, std::string_view text, const OffHeader& header,
                  ReadWarnings& warnings, OffRecords* values = nullptr);

/// One property of a PLY element as its header declares it.
struct PlyProperty {
  std::string name, type, sizeType;  ///< sizeType: the count type of a list, else ""
};

struct PlyElement {
  std::string name, count;  ///< count as written
  std::vector<PlyProperty> properties;
};

/// A PLY header, up to and including its end_header line.
struct PlyHeader {
  std::string format;  ///< "ascii", "binary_little_endian", "binary_big_endian" or other
  std::vector<PlyElement> elements;
  /// Not empty if the header is malformed (no format line second, a property before any
  /// element, no end_header); the other fields are then incomplete.
  std::string problem;
  std::size_t dataOffset = 0;  ///< the first byte after the end_header line
  std::size_t dataLine = 0;    ///< the line number (1-based) of dataOffset
};
PlyHeader parsePlyHeader(std::string_view text);

/// Checks the data lines of an ASCII PLY file, one element per line as the format requires
/// (CGAL reads values as a stream, so a line with a value too many or too few shifts every later
/// element). `header` must be free of problems.
void checkAsciiPlyText(const std::string& path, std::string_view text, const PlyHeader& header,
                       ReadWarnings& warnings);

/// The facets of a plain ASCII STL file, read while checkAsciiStlText checks them.
struct StlRecords {
  /// The file is plain: each solid opened by "solid" and closed by "endsolid" (one after the
  /// other, at least one), their names without a keyword of the format, and nothing the check
  /// warns about. Then `corners` (three per facet, in order, correctly rounded as CGAL's
  /// stream reads them) are the points CGAL's ASCII parser reads, before it merges equal ones.
  bool plain = true;
  std::vector<std::array<double, 3>> corners;
};

/// Checks an ASCII STL file ("solid" ... "endsolid"), token by token as CGAL reads it. If
/// `values` is given, also reads the facets of a plain file into it (see StlRecords).
void checkAsciiStlText(const std::string& path, std::string_view text, ReadWarnings& warnings,
                       StlRecords* values = nullptr);

}  // namespace polydg
