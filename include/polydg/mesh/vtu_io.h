// Reading and writing PolyMesh as VTK XML UnstructuredGrid (.vtu) files of polyhedral cells,
// the layout read by VTK 9.1, ParaView 5.11 and meshio 5.
#pragma once

#include <functional>
#include <map>
#include <span>
#include <string>
#include <string_view>
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

/// Named values a file carries for the mesh as a whole (VTK FieldData), written after polydg's
/// own restore arrays: provenance that must travel with the mesh between commands (the grid cell
/// size, the sliver rule, the input file).
///
/// Names must be non-empty, must hold no control character (bytes 0x00-0x1f and 0x7f, which an
/// XML attribute cannot keep) and must not start with "polydg_face_", "polydg_element" or
/// "polydg_point_" (reserved for the exact restore, see writeVtu).
///
/// numbers: each is a Float64 array of one component and numbers[name].size() tuples, values in
/// order; it may be empty. Every value must be finite (writeVtu refuses NaN and infinities): in
/// an ascii file VTK 9.1 reads "-inf" as +inf and silently drops an array holding "Infinity"
/// (its own writer's spelling), and a NaN, which VTK and meshio do read, would lose its sign and
/// payload there; provenance has no use for them, so one is a caller's bug, reported early and
/// the same way in every encoding. Any finite double (-0.0, subnormals, 1e-300, 1e300) comes back
/// bit for bit, in every encoding.
///
/// strings: each is stored as a UInt8 array named NAME + kVtuTextSuffix ("input_file" as
/// "input_file.utf8") holding the text's bytes, without terminator: UTF-8 by convention, but
/// any bytes, NUL included, come back unchanged. Not a VTK String array: meshio 7 (Debian 12's
/// python3-meshio) refuses to open a file that has one ("Illegal data type 'String'"), while
/// VTK and meshio both read UInt8 arrays.
struct VtuFieldData {
  std::map<std::string, std::vector<double>> numbers;  ///< Float64 arrays
  std::map<std::string, std::string> strings;          ///< text values
};

/// The suffix that marks a UInt8 field data array as text (see VtuFieldData::strings).
inline constexpr std::string_view kVtuTextSuffix = ".utf8";

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
/// point the mean of its elements' values). polydg's field data lets readVtu
/// restore the mesh exactly:
///   - polydg_face_group: per face record, in file order, the id of the face it belongs to;
///   - polydg_face_reversed: per face record, 1 if it runs against its face's orientation
///     (written by the face's back element), 0 otherwise;
///   - polydg_face_origin: per face, its FaceOrigin as an integer;
///   - polydg_element: per cell, in file order, the element it is;
///   - polydg_point_vertex: per point, the vertex it is a copy of (only when some vertex has
///     several points).
/// `fieldData` follows: its numbers, then its strings, each in name order (see VtuFieldData). In
/// appended files their bytes come after all of polydg's arrays, last array first, which keeps
/// meshio 7 from mistaking one array for another (see mesh/vtu_writer.cpp) and leaves polydg's
/// arrays where they are without field data.
///
/// Writing holds the points, each element's corners and a few integers per cell; the cell and
/// restore arrays are made a chunk at a time as they are written (mesh/vtu_cell_streams.h), so
/// the memory it takes does not grow with the size of the file.
///
/// The file is written to `path + ".tmp"` and renamed over `path`, so `path` is never left
/// half-written. Throws std::invalid_argument if an array has the wrong size, a component count
/// other than 1 or 3, an empty name, or a name already used (`volume` is taken), or if a field
/// data name breaks VtuFieldData's rules, a field data number is not finite, or a number array
/// has the name a text is stored under (numbers "a.utf8" and strings "a"); throws
/// std::runtime_error("cannot write PATH: reason") if the file cannot be written, and
/// std::runtime_error if a face with holes cannot be triangulated.
///
/// `volumes`: empty, or the mesh's signedVolumes() if the caller has them already (to validate
/// them too); they are written as given instead of computed again. `boxes`: empty, or per
/// element 1 for a whole grid cell as slicing made it (MeshingResult::wholeCells): six sides of
/// four corners on eight distinct vertices, which the writer counts without numbering them
/// (std::logic_error if a flagged element turns out otherwise). Either must be one per element
/// if given (std::invalid_argument).
void writeVtu(const PolyMesh& mesh, const std::string& path, const VtuWriteOptions& options = {},
              const std::vector<CellArray>& cellData = {},
              const std::vector<PointArray>& pointData = {},
              const std::vector<CornerArray>& cornerData = {}, const VtuFieldData& fieldData = {},
              std::span<const double> volumes = {}, std::span<const char> boxes = {});

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
/// separate face, so that checkGeometry() reports the problem instead of the reader failing.
/// Boundary faces are tagged FaceOrigin::Imported. If the file carries writeVtu's field data
/// and it is consistent, the mesh is restored instead exactly as written: the copies of a
/// vertex become that vertex again (same vertex ids), same face ids, the
/// triangles of a face with holes merged back into its loops (outer loop first; holes may come
/// back in another order, which does not change the face), the same front/back sides and
/// origins. Point and cell data are not read.
///
/// If `fieldData` is not null it is replaced by the file's FieldData arrays, except polydg's
/// restore arrays (names with a reserved prefix) and arrays without a name:
///   - a UInt8 (or UChar) array named NAME + kVtuTextSuffix as strings[NAME], its bytes;
///   - a VTK String array (vtkStringArray, as VTK writes it) as strings[name], its values joined
///     by NUL characters (one value: the value itself);
///   - any other numeric array as numbers[name], values widened to double in file order
///     (components interleaved; integers beyond 2^53 rounded);
///   - arrays of other types (VTK's Bit arrays) are skipped.
/// If two arrays give one name, the later in the file wins. If reading fails, `fieldData` is left
/// as it was.
///
/// Throws std::runtime_error with one line naming the file and the problem, e.g.
/// "FILE: not a VTK UnstructuredGrid file" or "FILE: cell 3 has VTK type 5, which polydg does not
/// read; only 3D linear cells and polyhedra are supported".
PolyMesh readVtu(const std::string& path, VtuFieldData* fieldData = nullptr);

}  // namespace polydg
