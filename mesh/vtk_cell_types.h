// VTK's cell type ids that polydg reads and writes, and the faces of VTK's linear 3D cells in
// VTK's point numbering, for turning such cells into polyhedra.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace polydg::vtk_format {

/// VTK_TETRA: four points, positive when (p1 - p0) . ((p2 - p0) x (p3 - p0)) > 0.
constexpr std::int64_t kVtkTetra = 10;

/// VTK_POLYHEDRON: a cell given by its faces (Cells/faces and Cells/faceoffsets).
constexpr std::int64_t kVtkPolyhedron = 42;

/// A linear 3D cell type: its VTK id, its number of points, and its faces as indices into the
/// cell's points (the faces of vtkTetra::GetFaceArray and the other cells' tables), each
/// ordered so that its normal (right-hand rule) points out of a cell of positive volume.
struct LinearCellType {
  std::int64_t type;
  std::size_t points;
  std::vector<std::vector<int>> faces;
};

/// The table entry of VTK type `type` if it is a linear 3D cell: tetra (10), voxel (11),
/// hexahedron (12), wedge (13), pyramid (14), pentagonal prism (15), hexagonal prism (16);
/// nullptr for any other type.
const LinearCellType* linearCellType(std::int64_t type);

}  // namespace polydg::vtk_format
