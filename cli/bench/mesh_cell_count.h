// The number of cells in a mesh file a mesher wrote, read from the file's headers without
// loading the mesh: the tetrahedra of a Gmsh MSH 4.1 ASCII file and the cells of a VTK XML
// UnstructuredGrid (polydg's VTU). The meshing suite counts the meshes of its Gmsh comparison
// this way; the library's readers (readTetMesh, readVtu) would load and check meshes of
// millions of cells only to count them.
#pragma once

#include <cstddef>
#include <filesystem>
#include <istream>
#include <string>

namespace polydg::bench {

/// The 4-node tetrahedra (element type 4) of `in`, a Gmsh MSH 4.1 ASCII file named `name` in
/// messages: the sum over the element blocks of its $Elements section whose header
/// "entityDim entityTag elementType numElementsInBlock" has element type 4. The element lines
/// themselves are skipped, not read. Throws InputError if the file is not MSH 4.1 ASCII
/// ($MeshFormat "4.1 0 ..."), has no $Elements section, or the section's block counts do not add up
/// to the number of elements its first line gives or it ends early.
std::size_t mshTetrahedra(std::istream& in, const std::string& name);
/// mshTetrahedra() of the file `file`; InputError also if it cannot be opened.
std::size_t mshTetrahedra(const std::filesystem::path& file);

/// The cells of `in`, a VTK XML UnstructuredGrid file named `name` in messages: the sum of the
/// NumberOfCells attributes of its <Piece> elements, read up to <AppendedData> (the raw data
/// after it is not read). Throws InputError if it has no Piece, or a Piece without a
/// NumberOfCells that is a whole number.
std::size_t vtuCells(std::istream& in, const std::string& name);
/// vtuCells() of the file `file`; InputError also if it cannot be opened.
std::size_t vtuCells(const std::filesystem::path& file);

}  // namespace polydg::bench
