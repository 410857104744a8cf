// Reads a triangle surface from OBJ, OFF, PLY and STL files in double precision (CGAL's
// polygon-soup readers) and from any other format assimp understands (glTF, 3DS, FBX, ...) with
// node transforms baked in; polygons are triangulated exactly and vertices welded by exact
// position across all meshes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "polydg/mesh/surface.h"

namespace polydg {

/// What readSurface() found and did. For files read by assimp, counts are over the whole scene
/// after node transforms are applied (a mesh used by two nodes counts twice). For files read by
/// CGAL, `meshes` is the number of distinct OBJ materials (`usemtl` names, faces before the first
/// one counting as one default material) used by faces, points and lines, and 1 for OFF, PLY
/// and STL; `inputVertices` is the number of vertex records in the file (OBJ `v` lines, OFF and
/// PLY vertices, three corners per STL facet).
struct SurfaceReadInfo {
  std::size_t meshes = 0;             ///< meshes in the scene (assimp joins them per material)
  std::size_t inputVertices = 0;      ///< vertices over all meshes, before welding
  std::size_t weldedVertices = 0;     ///< vertices of the result (distinct positions)
  std::size_t triangles = 0;          ///< triangles of the result
  std::size_t polygons = 0;           ///< faces of four or more corners, triangulated here
  std::size_t fannedPolygons = 0;     ///< of those, split into a fan: zero area or self-crossing
  std::size_t droppedDegenerate = 0;  ///< triangles dropped: two corners at one position
  std::size_t ignoredPoints = 0;      ///< point primitives skipped
  std::size_t ignoredLines = 0;       ///< line primitives skipped
  /// The reader that parsed the file: "cgal" (double precision: CGAL's readers, or polydg's
  /// own reading of OBJ, plain OFF and STL files as CGAL's readers read them, see readSurface)
  /// or "assimp" (single precision).
  std::string reader;
  /// Lines of the file that were skipped (see "Malformed lines" at readSurface), one line each,
  /// "FILE:LINE: what; what was done", in file order: at most kMaxReadWarnings, then one line
  /// "... and N more" if there were more. Empty for files assimp read.
  std::vector<std::string> warnings;
};

/// The most warnings SurfaceReadInfo::warnings lists before its final "... and N more" line.
inline constexpr std::size_t kMaxReadWarnings = 20;

/// Reads the triangles of the surface in the file at `path`.
///
/// Readers. A file whose extension is .obj, .off, .ply or .stl (any letter case) is read by
/// CGAL's polygon-soup readers (CGAL/IO/OBJ.h, OFF.h, PLY.h, STL.h), which parse coordinates
/// into doubles, correctly rounded from the text (binary STL and PLY float32 values are widened
/// exactly). Before CGAL sees a file it is checked for what CGAL would misread or crash on
/// (OBJ: homogeneous `v` coordinates with w != 1, line continuations, binary content; PLY:
/// property types CGAL does not know, 32-bit list counts, x/y/z that are not float or double,
/// elements CGAL or assimp give another meaning; OFF: headers other than [ST][C][N][4]OFF with
/// the three ASCII counts on one line; STL: neither 84 + 50 n bytes (binary) nor starting with
/// "solid" (ASCII)), its text is checked line by line (below), and after CGAL it is checked that
/// every face index names a vertex. Three kinds of file are not parsed a second time by CGAL:
/// an OBJ file's `v` lines (x y z) and `f` lines of three or more corners (vertex indices only,
/// one counted back from -1 resolved against the vertices before its line) and a plain OFF
/// file's records ("OFF", records of exactly x y z or a face's size and indices, no comment)
/// and a plain ASCII STL file's facets (one solid after the other, names without keywords,
/// nothing warned about) are read while their lines are checked (correctly rounded, as CGAL's
/// streams read them), and a binary STL file's facets are read as CGAL's binary parser reads
/// them; neither STL reading merges equal points as CGAL's parsers do (the welding below merges
/// them). `info->reader` still says "cgal" (tests compare the OBJ, OFF and STL results with
/// CGAL's readers). If CGAL cannot read such a file (PLY
/// indices of 8 or 16 bits, an STL file without endsolid, ...), or the file fails one of the
/// checks, or CGAL finds no vertex, assimp reads it instead, in single precision as for every
/// other format: `info->reader` says which did. An OBJ file with `v` lines but no `f` line of
/// three or more corners is reported as holding only points/lines without asking assimp.
///
/// Malformed lines. The text of an OBJ, OFF, ASCII PLY or ASCII STL file is checked before CGAL
/// parses it (polydg/mesh/surface_text_check.h). The rule: a line that can be skipped without
/// changing the geometry is skipped with a warning (`info->warnings`); a line that would change
/// the geometry if it were skipped or misread (a vertex, a vertex index of a face, the corners
/// of a facet) is an error, thrown as std::runtime_error "FILE:LINE: what is wrong; what to do"
/// whichever reader would have read the file. Blank lines, comments, CR LF line ends and
/// well-formed attributes (normals of any length, texture coordinates, colours, groups,
/// materials) are neither. A number is a whole decimal number as C++ streams read it: not
/// "abc", "nan", "inf", "0x1p3", or a number with anything after it ("3.1+e2", "2x").
///
///   format  warning (line or word skipped)           error
///   OBJ     `f` without indices; `f` of 1 or 2      `v` with fewer than 3 numbers or an x/y/z
///           corners (counted as a point or line);   that is not a number or beyond double's
///           unknown keyword; free-form statement    range; `f` vertex index that is not an
///           (curv, surf, ...); after x y z a word   integer ("x", "1.5", "/2"), is 0, is beyond
///           that is not a number, or numbers that   the file's vertices, or counts back past
///           are neither w nor r g b; a texture or   the first (-k with fewer than k vertices
///           normal reference that is not an         before it)
///           integer ("1/2/x"); malformed vt/vn/vp
///   OFF     face of 0-2 vertices; a word after a    vertex with fewer than 3 (4OFF: 4) numbers
///           vertex's coordinates or a face's        or a coordinate that is not a number; face
///           indices that is not a number; lines     size or index that is not an integer, index
///           after the last face                     out of range, fewer indices than the size;
///                                                   fewer records than the header declares
///   PLY     face of 0-2 vertices; lines after the   a value that is not a number of its
///   ASCII   last element                            property's type or is beyond its range; a
///                                                   line with a value too many or too few for
///                                                   its element (CGAL reads a stream of values);
///                                                   face index out of range; fewer lines than
///                                                   the header declares
///   STL     `facet` line that is not "facet normal  vertex with fewer than 3 numbers or a
///   ASCII   nx ny nz" (normals are not used: zero,  coordinate that is not a number; vertex
///           non-unit and NaN normals are fine);     outside a facet; facet of other than 3
///           `outer` line that is not "outer loop";  vertices; facet without endfacet; the file
///           any other word (rest of its line)       ending inside a facet
///
/// Warnings are kept only when CGAL reads the file: for one that goes to assimp (homogeneous
/// coordinates, a line continuation, a header form CGAL does not read, ...) they would describe
/// another reader, and `info->warnings` is empty. Binary PLY, OFF and STL files have no lines
/// to check.
///
/// For assimp, every node's transform is applied to the meshes it references (instanced meshes
/// appear once per instance). For CGAL, faces are taken in file order.
///
/// Corners are welded across all meshes: two corners become one vertex exactly
/// when their coordinates are bitwise equal, -0.0 counting as 0.0. Attributes (normals, texture
/// coordinates, materials) play no part. A face of four or more corners is replaced by the
/// exact constrained triangulation of its projection onto the coordinate plane where it is
/// largest (triangulateFace, mesh/face_triangulation.h): n - 2 triangles over its own corners,
/// wound like the face, non-convex faces included. assimp's aiProcess_Triangulate is not used:
/// its ear clipping returns overlapping triangles for some non-convex faces. A face of zero area
/// or with crossing edges has no such triangulation and becomes a fan from its first corner.
/// A triangle with two corners at one position is dropped and counted; every other triangle is
/// kept as it is, with the winding the file gives it (no reorientation, no removal of zero-area
/// or duplicate triangles). Point and line primitives (OBJ `p`, `l` and faces of one or two
/// corners) are skipped and counted.
///
/// Before an OFF or PLY file is read, its header's vertex, face and element counts are checked
/// against the file size: both readers allocate what they declare before reading the data.
///
/// The result holds only vertices used by a kept triangle, numbered in order of first use
/// (meshes in scene order, triangles in mesh order, corners in triangle order); coordinates are
/// those of the file as parsed (double precision by CGAL; single precision by assimp, widened
/// exactly to double), with -0.0 stored as 0.0.
///
/// If `info` is not null it receives the counts above and the warnings. Throws
/// std::runtime_error with a one-line message naming the file (and the line, for a malformed
/// line) when the file is missing, its header declares more items than it can hold, a line is
/// malformed as above, neither reader can read it (quoting assimp's reason and, for the CGAL
/// formats, CGAL's), it holds no meshes or only points and lines, no triangle survives welding,
/// or a used vertex has a non-finite coordinate. Nothing is printed: polydg never creates
/// assimp's DefaultLogger, so assimp logs to its null logger unless the application installs
/// one itself; CGAL's readers run in verbose mode with std::cout, std::cerr and std::clog
/// redirected to a buffer (their last error line becomes the CGAL reason), so output that
/// another thread writes to those streams during a CGAL read is swallowed too.
TriangleSurface readSurface(const std::string& path, SurfaceReadInfo* info = nullptr);

}  // namespace polydg
