// Tests of mesh/surface_text_check.h, through readSurface as a user meets it: each kind of
// malformed line of an OBJ, OFF, ASCII PLY or ASCII STL file is either a warning naming its file
// and line (the file still reads, with the geometry of its well-formed lines) or a one-line error
// "FILE:LINE: what is wrong; what to do"; blank lines, comments, CR LF line ends and attributes
// are neither. Every file is a tetrahedron with legs 2, 3 and 4 (volume 4) with one line changed.
#include "mesh/surface_text_check.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "polydg/mesh/surface_io.h"
#include "tests/support/assimp_models.h"
#include "tests/support/exact_figures.h"
#include "tests/support/packages.h"
#include "tests/support/temp_dir.h"

namespace polydg {
namespace {

using polydg::testing::kExactRelTol;  // the tetrahedron's coordinates are integers
using polydg::testing::relativeError;
using polydg::testing::TempDir;

using Lines = std::vector<std::string>;

const Lines kObj = {"v 0 0 0", "v 2 0 0", "v 0 3 0", "v 0 0 4",
                    "f 1 3 2", "f 1 2 4", "f 1 4 3", "f 2 3 4"};
const Lines kOff = {"OFF",   "4 4 0",   "0 0 0",   "2 0 0",   "0 3 0",
                    "0 0 4", "3 0 2 1", "3 0 1 3", "3 0 3 2", "3 1 2 3"};
const Lines kPly = {"ply",
                    "format ascii 1.0",
                    "element vertex 4",
                    "property double x",
                    "property double y",
                    "property double z",
                    "element face 4",
                    "property list uchar int vertex_indices",
                    "end_header",
                    "0 0 0",  // line 10
                    "2 0 0",
                    "0 3 0",
                    "0 0 4",
                    "3 0 2 1",  // line 14
                    "3 0 1 3",
                    "3 0 3 2",
                    "3 1 2 3"};

/// Facet k of the STL tetrahedron starts at line 2 + 7 k: facet, outer loop, three vertices,
/// endloop, endfacet.
Lines stlTetra() {
  const char* corners[4] = {"0 0 0", "2 0 0", "0 3 0", "0 0 4"};
  const int facets[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  Lines lines = {"solid tetra"};
  for (const auto& f : facets) {
    lines.push_back("facet normal 0 0 0");
    lines.push_back("  outer loop");
    for (int k : f) lines.push_back(std::string("    vertex ") + corners[k]);
    lines.push_back("  endloop");
    lines.push_back("endfacet");
  }
  lines.push_back("endsolid tetra");
  return lines;
}
const Lines kStl = stlTetra();

/// `lines` with line `number` (1-based) replaced by `text`.
Lines replaced(Lines lines, std::size_t number, const std::string& text) {
  lines.at(number - 1) = text;
  return lines;
}

/// `lines` with `text` inserted to become line `number`.
Lines inserted(Lines lines, std::size_t number, const std::string& text) {
  lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(number - 1), text);
  return lines;
}

/// The lines joined, each ended by `end`.
std::string joined(const Lines& lines, const std::string& end = "\n") {
  std::string text;
  for (const std::string& line : lines) text += line + end;
  return text;
}

struct LineCase {
  std::string file;  ///< its extension chooses the format
  std::string text;
  std::size_t line;    ///< the line the warning or error names
  std::string phrase;  ///< a part of its message
};

/// Reads `text` as `file`: the tetrahedron must come out whole, read by CGAL. Returns the
/// warnings and sets `path`.
std::vector<std::string> tetraWarnings(const TempDir& dir, const std::string& file,
                                       const std::string& text, std::string& path) {
  path = dir.write(file, text);
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.reader, "cgal");
  EXPECT_EQ(s.triangles.size(), 4u);
  EXPECT_LT(relativeError(enclosedVolume(s), 4.0), kExactRelTol) << enclosedVolume(s);
  return info.warnings;
}

/// Each case reads the whole tetrahedron with exactly one warning, on its line.
void expectOneWarningEach(const std::string& dirName, const std::vector<LineCase>& cases) {
  const TempDir dir(dirName);
  for (const LineCase& c : cases) {
    SCOPED_TRACE(c.file);
    std::string path;
    const std::vector<std::string> warnings = tetraWarnings(dir, c.file, c.text, path);
    ASSERT_EQ(warnings.size(), 1u) << (warnings.empty() ? "none" : warnings.back());
    const std::string& w = warnings[0];
    EXPECT_EQ(w.rfind(path + ":" + std::to_string(c.line) + ": ", 0), 0u) << w;
    EXPECT_NE(w.find(c.phrase), std::string::npos) << w;
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  }
}

/// Each case fails to read with one line "PATH:LINE: ...; ...".
void expectErrorEach(const std::string& dirName, const std::vector<LineCase>& cases) {
  const TempDir dir(dirName);
  for (const LineCase& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string path = dir.write(c.file, c.text);
    std::string message;
    try {
      readSurface(path);
      ADD_FAILURE() << "read without an error";
      continue;
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    EXPECT_EQ(message.rfind(path + ":" + std::to_string(c.line) + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(c.phrase), std::string::npos) << message;
    EXPECT_NE(message.find("; ", path.size()), std::string::npos) << "no advice: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// --- numbers ----------------------------------------------------------------------------------

TEST(SurfaceTextNumbers, DecimalsAreWholeNumbersAsStreamsReadThem) {
  for (const char* yes : {"0", "-0", "+1", "1.", ".5", "-.5", "1e5", "1E+05", "2.e-1", "007"})
    EXPECT_TRUE(isDecimalNumber(yes)) << yes;
  for (const char* no : {"", "+", ".", "e5", "1e", "1e+", "3.1+e2", "1,5", "2x", "0x1p3", "inf",
                         "nan", "--1", "1..2", "1 2"})
    EXPECT_FALSE(isDecimalNumber(no)) << no;
  for (const char* yes : {"0", "-12", "+3", "0007"}) EXPECT_TRUE(isIntegerNumber(yes)) << yes;
  for (const char* no : {"", "-", "1.0", "1e2", "x", "1/2", " 1"})
    EXPECT_FALSE(isIntegerNumber(no)) << no;
}

// --- OBJ --------------------------------------------------------------------------------------

TEST(ObjLines, NeitherWarningNorErrorForWellFormedVariants) {
  // CR LF line ends, comments (whole lines and after data), tabs, indentation, blank lines,
  // groups, materials, attributes, colours, a weight of 1, points and lines, negative indices,
  // a forward reference and no final line end.
  const std::string text =
      "# a tetrahedron\r\nmtllib t.mtl\r\no tetra\r\n\r\ng side\r\ns 1\r\n"
      "v 0 0 0 1 0 0\r\n\tv 2 0 0 # x leg\r\nv 0 3 0 1\r\nvt 0 0\r\nvn 0 0 -1\r\n"
      "usemtl red\r\nf 1/1/1 -1/1/1 -2/1/1\r\nf 1//1 2//1 4//1\r\nf 1 4 3 # forward\r\n"
      "v 0 0 4\r\np 1 2\r\nl 1 2 3\r\nf 2 3 4";
  const TempDir dir("obj_clean");
  std::string path;
  const std::vector<std::string> warnings = tetraWarnings(dir, "clean.obj", text, path);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  // A UTF-8 byte order mark before the first vertex.
  EXPECT_TRUE(tetraWarnings(dir, "bom.obj", "\xEF\xBB\xBF" + joined(kObj), path).empty());
}

TEST(ObjLines, SkippableLinesWarnAndNameTheirLine) {
  const std::string tetra = joined(kObj);
  expectOneWarningEach(
      "obj_warnings",
      {
          {"empty_f.obj", joined(inserted(kObj, 5, "f")), 5, "face without vertex indices"},
          {"empty_f_crlf.obj", joined(inserted(kObj, 5, "f  "), "\r\n"), 5,
           "face without vertex indices"},
          {"point_face.obj", tetra + "f 3\n", 9, "face of one corner (a point); skipped"},
          {"line_face.obj", tetra + "f 1 2\n", 9, "face of two corners (a line); skipped"},
          {"unknown.obj", "bogus 1 2\n" + tetra, 1, "unknown keyword 'bogus'; line skipped"},
          {"free_form.obj", tetra + "curv 0 1 1 2\n", 9, "free-form geometry ('curv')"},
          {"v_text.obj", joined(replaced(kObj, 2, "v 2 0 0 junk")), 2,
           "'junk' after the vertex's x y z is not a number; ignored"},
          {"v_five.obj", joined(replaced(kObj, 2, "v 2 0 0 1 5")), 2,
           "2 numbers after the vertex's x y z"},
          {"f_attribute.obj", joined(replaced(inserted(kObj, 5, "vt 0 0"), 6, "f 1/1/x 3/1 2")), 6,
           "texture/normal reference in face corner '1/1/x' is not an integer; ignored"},
          {"vn_short.obj", joined(inserted(kObj, 5, "vn 0 1")), 5, "malformed 'vn' line"},
      });
}

TEST(ObjLines, LinesThatChangeTheGeometryAreErrors) {
  expectErrorEach(
      "obj_errors",
      {
          {"v_two.obj", joined(replaced(kObj, 2, "v 2 0")), 2,
           "a vertex needs x y z but this line has 2 numbers"},
          {"v_none.obj", joined(replaced(kObj, 3, "v")), 3,
           "a vertex needs x y z but this line has 0 numbers"},
          {"v_abc.obj", joined(replaced(kObj, 2, "v 2 abc 0")), 2,
           "coordinate 'abc' is not a number"},
          {"v_suffix.obj", joined(replaced(kObj, 4, "v 0 0 3.1+e2")), 4,
           "coordinate '3.1+e2' is not a number"},
          {"v_nan.obj", joined(replaced(kObj, 1, "v nan 0 0")), 1,
           "coordinate 'nan' is not a number"},
          {"v_huge.obj", joined(replaced(kObj, 2, "v 2e999 0 0")), 2,
           "coordinate '2e999' is beyond the range of double"},
          {"f_zero.obj", joined(replaced(kObj, 6, "f 0 2 4")), 6, "face index 0 names no vertex"},
          {"f_beyond.obj", joined(replaced(kObj, 6, "f 1 2 5")), 6,
           "face index 5 is beyond the 4 vertices of the file"},
          {"f_back.obj", joined(replaced(kObj, 5, "f -1 -3 -5")), 5,
           "face index -5 counts back past the first vertex (4 precede this line)"},
          {"f_letter.obj", joined(replaced(kObj, 7, "f 1 x 3")), 7,
           "face index 'x' is not an integer"},
          {"f_real.obj", joined(replaced(kObj, 7, "f 1 4.0 3")), 7,
           "face index '4.0' is not an integer"},
          {"f_slash_first.obj", joined(replaced(kObj, 8, "f /2 3 4")), 8,
           "face corner '/2' has no vertex index"},
          // The first malformed line in file order, even if it is found only at the end.
          {"f_order.obj", joined(replaced(replaced(kObj, 5, "f 1 3 9"), 6, "f 0 2 4")), 5,
           "face index 9 is beyond"},
      });
}

TEST(ObjLines, WarningsAreCappedWithACountOfTheRest) {
  Lines lines = kObj;
  for (std::size_t k = 0; k < kMaxReadWarnings + 5; ++k) lines.push_back("bogus");
  const TempDir dir("obj_cap");
  std::string path;
  const std::vector<std::string> warnings = tetraWarnings(dir, "many.obj", joined(lines), path);
  ASSERT_EQ(warnings.size(), kMaxReadWarnings + 1);
  EXPECT_EQ(warnings.front(), path + ":9: unknown keyword 'bogus'; line skipped");
  EXPECT_EQ(warnings[kMaxReadWarnings - 1], path + ":" + std::to_string(8 + kMaxReadWarnings) +
                                                ": unknown keyword 'bogus'; line skipped");
  EXPECT_EQ(warnings.back(), "... and 5 more");
}

TEST(ObjLines, AssimpCorpusEmptyFaceIsAWarning) {
  // assimp's own malformed2.obj: an `f` line without indices at line 23, read as the five other
  // faces (as before), now with a word about the sixth.
  const std::string path = (corpus::kAssimpModels / "invalid" / "malformed2.obj").string();
  ASSERT_TRUE(packages::assimpTestModels());
  ASSERT_TRUE(std::filesystem::exists(path))
      << path << " is missing: Debian's assimp-testmodels provides it (scripts/setup.sh installs "
      << "every package the tests need)";
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.polygons, 5u);
  EXPECT_EQ(s.triangles.size(), 10u);
  ASSERT_EQ(info.warnings.size(), 1u);
  EXPECT_EQ(info.warnings[0], path + ":23: face without vertex indices; skipped");
}

// --- OFF --------------------------------------------------------------------------------------

TEST(OffLines, NeitherWarningNorErrorForWellFormedVariants) {
  // Comments, CR LF, blank lines, the counts on the keyword's line, vertex and face colours.
  const std::string text =
      "COFF 4 4 0 # counts\r\n\r\n# vertices\r\n0 0 0 255 0 0 255\r\n2 0 0 0 255 0 255\r\n"
      "0 3 0 0 0 255 255\r\n  0 0 4 9 9 9 255 # last\r\n3 0 2 1\r\n3 0 1 3 0.5 0.5 0.5\r\n"
      "3 0 3 2\r\n3 1 2 3\r\n";
  const TempDir dir("off_clean");
  std::string path;
  const std::vector<std::string> warnings = tetraWarnings(dir, "clean.off", text, path);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

TEST(OffLines, SkippableLinesWarnAndNameTheirLine) {
  const Lines fiveFaces = replaced(kOff, 2, "4 5 0");
  expectOneWarningEach("off_warnings",
                       {
                           {"empty_face.off", joined(inserted(fiveFaces, 11, "0")), 11,
                            "face without vertices; skipped"},
                           {"line_face.off", joined(inserted(fiveFaces, 11, "2 0 1")), 11,
                            "face of two vertices (a line); skipped"},
                           {"vertex_text.off", joined(replaced(kOff, 4, "2 0 0 junk")), 4,
                            "'junk' after the vertex's coordinates is not a number; ignored"},
                           {"face_text.off", joined(replaced(kOff, 7, "3 0 2 1 red")), 7,
                            "'red' after the face's indices is not a number; ignored"},
                           {"extra.off", joined(kOff) + "9 9 9\nmore\n", 11,
                            "2 lines after the last of the 4 faces the header declares; ignored"},
                       });
}

TEST(OffLines, LinesThatChangeTheGeometryAreErrors) {
  expectErrorEach(
      "off_errors",
      {
          {"vertex_two.off", joined(replaced(kOff, 4, "2 0")), 4,
           "a vertex needs x y z but this line has 2 numbers"},
          {"vertex_abc.off", joined(replaced(kOff, 5, "0 abc 0")), 5,
           "coordinate 'abc' is not a number"},
          {"vertex_suffix.off", joined(replaced(kOff, 5, "0 3 0x")), 5,
           "coordinate '0x' is not a number"},
          {"face_beyond.off", joined(replaced(kOff, 8, "3 0 1 4")), 8,
           "face index 4 names no vertex (OFF counts from 0, 4 vertices)"},
          {"face_negative.off", joined(replaced(kOff, 8, "3 0 -1 3")), 8,
           "face index -1 names no vertex"},
          {"face_short.off", joined(replaced(kOff, 9, "3 0 3")), 9,
           "a face of 3 vertices lists only 2 indices"},
          {"face_real.off", joined(replaced(kOff, 9, "3 0 3 2.0")), 9,
           "face index '2.0' is not an integer"},
          {"face_size.off", joined(replaced(kOff, 10, "x 1 2 3")), 10,
           "face size 'x' is not a vertex count"},
          {"truncated.off", joined(Lines(kOff.begin(), kOff.end() - 1)), 9,
           "the file ends after 3 of its 4 faces"},
          // Without an edge count, CGAL and assimp both took the "1" of "1.5" for it and read
          // the first vertex as (0.5, 0, 0).
          {"no_edge_count.off", joined(replaced(replaced(kOff, 2, "4 4"), 3, "1.5 0 0")), 2,
           "the header has 2 of the vertex, face and edge counts"},
          {"count_text.off", joined(replaced(kOff, 2, "4 four 0")), 2,
           "header count 'four' is not a count"},
      });
}

// --- PLY --------------------------------------------------------------------------------------

TEST(PlyLines, NeitherWarningNorErrorForWellFormedVariants) {
  const TempDir dir("ply_clean");
  std::string path;
  // CR LF line ends and blank lines between elements.
  const std::vector<std::string> warnings =
      tetraWarnings(dir, "clean.ply", joined(inserted(kPly, 14, ""), "\r\n"), path);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

TEST(PlyLines, SkippableLinesWarnAndNameTheirLine) {
  const Lines fiveFaces = replaced(kPly, 7, "element face 5");
  expectOneWarningEach("ply_warnings",
                       {
                           {"line_face.ply", joined(inserted(fiveFaces, 14, "2 0 1")), 14,
                            "face of two vertices (a line); skipped"},
                           {"empty_face.ply", joined(inserted(fiveFaces, 18, "0")), 18,
                            "face without vertices; skipped"},
                           {"extra.ply", joined(kPly) + "1 2 3\n", 18,
                            "1 line after the last element the header declares; ignored"},
                       });
}

TEST(PlyLines, LinesThatChangeTheGeometryAreErrors) {
  expectErrorEach(
      "ply_errors",
      {
          {"vertex_two.ply", joined(replaced(kPly, 11, "2 0")), 11,
           "the line ends before the 'z' of its 'vertex' element"},
          {"vertex_abc.ply", joined(replaced(kPly, 12, "0 abc 0")), 12,
           "'vertex' property 'y': 'abc' is not a number"},
          {"vertex_four.ply", joined(replaced(kPly, 12, "0 3 0 1")), 12,
           "the line holds 4 values but one 'vertex' element has 3"},
          {"face_beyond.ply", joined(replaced(kPly, 15, "3 0 1 4")), 15,
           "face index 4 names no vertex (PLY counts from 0, 4 vertices)"},
          {"face_count.ply", joined(replaced(kPly, 16, "300 0 3 2")), 16,
           "'300' is beyond the range of uchar"},
          {"face_real.ply", joined(replaced(kPly, 16, "3 0 3 2.5")), 16, "'2.5' is not an integer"},
          {"truncated.ply", joined(Lines(kPly.begin(), kPly.end() - 1)), 16,
           "the file ends after 3 of its 4 'face' elements"},
      });
}

// --- STL --------------------------------------------------------------------------------------

TEST(StlLines, NeitherWarningNorErrorForWellFormedVariants) {
  // Zero, non-unit and NaN normals (normals are not used), CR LF line ends, tabs, blank lines and
  // a solid name of several words.
  Lines lines = replaced(kStl, 1, "solid my\ttetra model");
  lines = replaced(lines, 9, "facet normal 0 -5 0");
  lines = replaced(lines, 16, "facet normal nan nan nan");
  lines = inserted(lines, 10, "");
  const TempDir dir("stl_clean");
  std::string path;
  const std::vector<std::string> warnings =
      tetraWarnings(dir, "clean.stl", joined(lines, "\r\n"), path);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

TEST(StlLines, SkippableLinesWarnAndNameTheirLine) {
  expectOneWarningEach(
      "stl_warnings",
      {
          {"normal_text.stl", joined(replaced(kStl, 9, "facet normal a b c")), 9,
           "facet line is not 'facet normal nx ny nz'"},
          {"no_normal.stl", joined(replaced(kStl, 9, "facet")), 9,
           "facet line is not 'facet normal nx ny nz'"},
          {"outer.stl", joined(replaced(kStl, 3, "outer lop")), 3, "line is not 'outer loop'"},
          {"color.stl", joined(inserted(kStl, 8, "color 1 0 0")), 8,
           "unexpected 'color'; ignored up to the end of the line"},
          {"vertex_text.stl", joined(replaced(kStl, 4, "vertex 0 0 0 junk")), 4,
           "unexpected 'junk'"},
      });
}

TEST(StlLines, LinesThatChangeTheGeometryAreErrors) {
  expectErrorEach(
      "stl_errors",
      {
          {"vertex_two.stl", joined(replaced(kStl, 5, "vertex 0 3")), 5,
           "a vertex needs x y z but this one has 2 numbers"},
          {"vertex_abc.stl", joined(replaced(kStl, 5, "vertex 0 abc 0")), 5,
           "coordinate 'abc' is not a number"},
          {"four_vertices.stl", joined(inserted(kStl, 7, "vertex 1 1 0")), 7,
           "a fourth vertex in the facet of line 2; STL facets are triangles"},
          {"two_vertices.stl", joined(replaced(kStl, 13, "")), 9,
           "facet of 2 vertices; an STL facet is a triangle"},
          {"outside.stl", joined(inserted(kStl, 9, "vertex 1 1 1")), 9, "vertex outside a facet"},
          {"no_endfacet.stl", joined(replaced(kStl, 8, "")), 2,
           "facet without endfacet (the next facet starts at line 9)"},
          {"no_last_endfacet.stl", joined(replaced(kStl, 29, "")), 23,
           "facet without endfacet (the solid ends at line 30)"},
          {"truncated.stl", joined(Lines(kStl.begin(), kStl.begin() + 27)), 27,
           "the file ends inside the facet of line 23"},
      });
}

}  // namespace
}  // namespace polydg
