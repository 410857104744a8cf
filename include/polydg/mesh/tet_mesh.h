// Tetrahedral meshes for the tet methods (linear and corotational FEM, face-based smoothed FEM):
// vertices and 4-node tetrahedra, read from VTU (VTK_TETRA), TetGen (.node/.ele) or Gmsh MSH 4.1,
// written as VTU, checked, and turned into a PolyMesh of tetrahedral elements for the DG methods.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "polydg/mesh/poly_mesh.h"
#include "polydg/mesh/vtu_io.h"

namespace polydg {

/// Vertices and tetrahedra. Tet t's corners are tets[t][0..3], positively oriented:
/// (v1 - v0) . ((v2 - v0) x (v3 - v0)) > 0, i.e. six times its volume.
struct TetMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 4>> tets;

  std::size_t numVertices() const { return vertices.size(); }
  std::size_t numTets() const { return tets.size(); }
};

/// Six times the signed volume of the tet (a, b, c, d): (b - a) . ((c - a) x (d - a)), computed
/// about `a` so that it loses no digits far from the origin.
double sixVolume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Six times tet t's signed volume (positive when it is positively oriented).
double sixVolume(const TetMesh& mesh, std::size_t t);

/// The faces of a tet by its corner slots, face k opposite corner k, each ordered so that its
/// normal (right-hand rule) points out of a positively oriented tet: VTK's vtkTetra faces.
inline constexpr std::array<std::array<int, 3>, 4> kTetFaces = {
    {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

/// Reads a tet mesh, choosing the format by the extension (case-insensitive):
///  - .vtu: a VTK XML UnstructuredGrid whose cells are all VTK_TETRA (type 10), in any encoding
///    polydg's VTU reader takes (ascii, inline base64 binary, appended raw or base64; zlib
///    compression; UInt32 or UInt64 headers; either byte order). Tets are cells in file order.
///  - .ele: TetGen's FILE.ele with its sibling FILE.node. Indices start at the first .node
///    index (0 or 1) and run on without gaps in both files; '#' starts a comment; 10-node tets
///    give their first 4 nodes (the corners). Tets are in file order.
///  - .msh: Gmsh MSH 4.1 ASCII. Tets are the elements of type 4 (4 nodes) and 11 (10 nodes; the
///    first 4 are the corners) in file order; points, lines, triangles and quadrangles are
///    ignored, other 3D elements refused. Binary files and other versions are refused.
/// Vertices are the points (nodes) that some tet uses, in file order; unused ones are dropped
/// (a vertex without a tet would leave the FEM's matrices singular). A tet the file gives with
/// negative orientation has its last two corners swapped, so that files of either convention
/// read alike (TetGen 1.5 and Gmsh 4.8 write positive tets, hand-made files may not); every
/// other corner order is kept. The result has passed checkTetMesh.
/// Throws InputError with one line "FILE[:LINE]: what is wrong; what to do" that names the
/// element by its number in the file (a TetGen index, a Gmsh element tag, a VTU cell index).
TetMesh readTetMesh(const std::string& path);

/// Whether `path` names a tet mesh file by its extension: .ele or .msh (case-insensitive). A
/// .vtu may hold tets too; readVtu reads those as polyhedra and toTetMesh turns them back.
bool isTetMeshFile(const std::string& path);

/// Checks that `mesh` is a conforming tet mesh, and throws InputError naming the first problem
/// ("tet T ..." with T its index in mesh.tets; first in order of the checks, then of T):
///  1. each tet: corner indices in range, four distinct corners, positive orientation by
///     CGAL's exact predicate (zero: flat, negative: inverted) and a positive sixVolume as
///     computed in double precision (an exactly positive tet can still be too thin for it);
///  2. each triangle is a face of at most two tets, which lie on opposite sides of it (two
///     tets on the same side overlap);
///  3. no T-junction on the boundary faces (faces of one tet only): no vertex of another
///     boundary face lies inside a boundary face or inside one of its edges, and no two
///     boundary faces in one plane overlap (neighbours that split a quadrilateral by different
///     diagonals). Decided with CGAL's exact predicates.
void checkTetMesh(const TetMesh& mesh);

/// Writes `mesh` to `path` as a VTK XML UnstructuredGrid (version 1.0, UInt64 headers) of
/// VTK_TETRA (10) cells, in `options`' encoding: points (Float64) are the vertices in order,
/// cells the tets in order with their corners as given, cell data `volume` (sixVolume() / 6),
/// field data `fieldData` (as writeVtu() writes it; VtuFieldData's rules apply). readTetMesh()
/// reads the file back with the same vertices and tets, bit for bit, provided every vertex is a
/// corner of some tet (it drops the others); VTK and meshio read it as tetra cells. Written to
/// `path + ".tmp"` and renamed over `path`. Throws std::invalid_argument for a corner index out
/// of range or field data that breaks VtuFieldData's rules, std::runtime_error("cannot write
/// PATH: reason") if the file cannot be written.
void writeTetVtu(const TetMesh& mesh, const std::string& path, const VtuWriteOptions& options = {},
                 const VtuFieldData& fieldData = {});

/// The tets as a PolyMesh: element t is tet t, bounded by its 4 triangles in kTetFaces order.
/// A triangle of two tets is one Interior face whose front is the tet that uses it first (its
/// corners in that tet's outward order) and whose back is the other; a triangle of one tet is
/// a Surface face, outward. Vertices are the tet mesh's, in order. Meant for meshes that pass
/// checkTetMesh: a triangle of three tets, or of two on one side, gives faces that
/// checkGeometry reports as duplicates; a corner index out of range throws std::out_of_range.
PolyMesh toPolyMesh(const TetMesh& mesh);

/// A PolyMesh whose elements are all tetrahedra (4 triangular faces without holes on 4
/// corners; e.g. read from a VTU of VTK_TETRA cells, or toPolyMesh's) as a TetMesh: tet t is
/// element t, its corners the apex opposite the element's first face and that face's corners
/// in outward order (so toPolyMesh's tets come back with their corners); vertices no element
/// uses are dropped, the others keep their order. Throws InputError naming the first element
/// that is not a tetrahedron, or what checkTetMesh finds.
TetMesh toTetMesh(const PolyMesh& mesh);

}  // namespace polydg
