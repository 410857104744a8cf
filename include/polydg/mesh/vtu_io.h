// Reading and writing PolyMesh as VTK XML UnstructuredGrid (.vtu) files of polyhedral cells,
// the layout read by VTK 9.1, ParaView 5.11 and meshio 5.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// How the writer stores numbers: readable text; inline base64 of the raw little-endian bytes;
/// or those bytes raw in one AppendedData section after the XML (encoding "raw"), the smallest
/// and fastest. Binary data is uncompressed, each array preceded by a UInt64 byte count.
enum class VtuEncoding { Ascii, Binary, Appended };

struct VtuWriteOptions {
  VtuEncoding encoding = VtuEncoding::Appended;
};

/// A named array of doubles attached to the elements (`Tag = ElementTag`) or the vertices
/// (`Tag = VertexTag`) of a mesh: `components` values per entity (1 for a scalar, 3 for a vector),
/// stored entity by entity: values[i * components + c]. Written as Float64.
template <class Tag>
struct VtuArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
};
using CellArray = VtuArray<ElementTag>;  ///< numElements() * components values
using PointArray = VtuArray<VertexTag>;  ///< numVertices() * components values

/// Point data given per element corner: value(e, v, out) writes element e's `components`
/// values at its vertex v. Each point of the file gets the mean over the elements it stands
/// for: a vertex has one point per group of its elements joined by interior faces (see
/// writeVtu), so the two sides of a cut keep their own means (paper eq. 17 per side) where a
/// PointArray would give both the same value. value is called once per element and vertex,
/// from several threads at once.
struct CornerArray {
  std::string name;
  int components = 1;
  std::function<void(ElementId, VertexId, double*)> value;
};

/// Writes `mesh` to `path` as a VTK XML UnstructuredGrid (version 1.0, UInt64 headers).
///
/// Layout: points (Float64) are the mesh's vertices in id order, followed by extra copies of
/// vertices: per vertex, its elements are grouped by connectivity through the interior faces
/// that contain the vertex, and each group has its own point (the first group, in element
/// order, the vertex itself; polydg/mesh/point_groups.h). So elements coupled across interior faces
/// share points, while the two sides of a FaceOrigin::Cut face (boundary faces of both, on the same
/// vertex ids) do not: VTK and meshio see them as separate regions, and a finite cut shares points
/// only along its front. Each element is one VTK_POLYHEDRON (type 42) cell, cells ordered by point
/// count (see polydg_element). Cells/connectivity holds a cell's distinct point ids, Cells/faces
/// per cell the number of face records and then, per record, its number of points and point ids;
/// Cells/faceoffsets the end of each cell's run in `faces`. Integer arrays are stored as UInt8,
/// Int32 or Int64, the smallest that holds their values. Every record is oriented so that its
/// normal points out of the cell (the face's loop if the element uses it unreversed, the loop
/// backwards otherwise). A face with one loop is one record, convex or not; a face with holes
/// is written as the triangles of triangulateFace (one record each), which keeps the cell
/// watertight.
///
/// Cell data: `volume` (signedVolume of each element) followed by `cellData`; point data:
/// `pointData` (every copy of a vertex carries the vertex's value), then `cornerData` (each
/// point the mean of its elements' values). Field data lets readVtu
/// restore the mesh exactly:
///   - polydg_face_group: per face record, in file order, the id of the face it belongs to;
///   - polydg_face_reversed: per face record, 1 if it runs against its face's orientation
///     (written by the face's back element), 0 otherwise;
///   - polydg_face_origin: per face, its FaceOrigin as an integer;
///   - polydg_element: per cell, in file order, the element it is;
///   - polydg_point_vertex: per point, the vertex it is a copy of (only when some vertex has
///     several points).
///
/// The file is written to `path + ".tmp"` and renamed over `path`, so `path` is never left
/// half-written. Throws std::invalid_argument if an array has the wrong size, a component count
/// other than 1 or 3, an empty name, or a name already used (`volume` is taken); throws
/// std::runtime_error("cannot write PATH: reason") if the file cannot be written, and
/// std::runtime_error if a face with holes cannot be triangulated.
void writeVtu(const PolyMesh& mesh, const std::string& path, const VtuWriteOptions& options = {},
              const std::vector<CellArray>& cellData = {},
              const std::vector<PointArray>& pointData = {},
              const std::vector<CornerArray>& cornerData = {});

/// Reads a VTK XML UnstructuredGrid file into a PolyMesh.
///
/// Accepts files written by writeVtu and by VTK's vtkXMLUnstructuredGridWriter: ascii, inline
/// binary and appended (base64 or raw) data, uncompressed or vtkZLibDataCompressor-compressed,
/// UInt32 or UInt64 headers, either byte order, any numeric array type, several pieces. Cells
/// may be polyhedra (type 42, with faces/faceoffsets) or 3D linear cells: tetra (10),
/// voxel (11), hexahedron (12), wedge (13), pyramid (14), pentagonal prism (15), hexagonal
/// prism (16), whose faces are taken in VTK's point numbering and oriented outward (for a cell
/// of positive volume).
///
/// Points become vertices and cells elements, both in file order. Faces of two different cells
/// with the same vertices in opposite cyclic order become one shared face, whose front is the
/// earlier cell; any other face (used a third time, or twice in the same orientation) stays a
/// separate face, so that validate() reports the problem instead of the reader failing.
/// Boundary faces are tagged FaceOrigin::Imported. If the file carries writeVtu's field data
/// and it is consistent, the mesh is restored instead exactly as written: the copies of a
/// vertex become that vertex again (same vertex ids), same face ids, the
/// triangles of a face with holes merged back into its loops (outer loop first; holes may come
/// back in another order, which does not change the face), the same front/back sides and
/// origins. Point and cell data are not read.
///
/// Throws std::runtime_error with one line naming the file and the problem, e.g.
/// "FILE: not a VTK UnstructuredGrid file" or "FILE: cell 3 has VTK type 5, which polydg does not
/// read; only 3D linear cells and polyhedra are supported".
PolyMesh readVtu(const std::string& path);

}  // namespace polydg
