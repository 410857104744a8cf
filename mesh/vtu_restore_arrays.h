// The names of the field data arrays with which readVtu restores writeVtu's mesh exactly (their
// contents are documented at writeVtu in polydg/mesh/vtu_io.h), shared by the writer and reader.
#pragma once

#include <array>
#include <string_view>

namespace polydg {

/// Per face record, in file order, the id of the face it belongs to.
constexpr std::string_view kFaceGroupArray = "polydg_face_group";
/// Per face record, 1 if it runs against its face's orientation, 0 otherwise.
constexpr std::string_view kFaceReversedArray = "polydg_face_reversed";
/// Per face, its FaceOrigin as an integer.
constexpr std::string_view kFaceOriginArray = "polydg_face_origin";
/// For each cell in file order, the polydg element it is. Cells are written in increasing
/// order of their point count: meshio 5 groups polyhedra into blocks by point count in order
/// of first appearance but splits cell data by point count in increasing order, so only that
/// order keeps cell data with its cells.
constexpr std::string_view kElementArray = "polydg_element";
/// For each VTU point, the mesh vertex it is a copy of; written only when some vertex has
/// several points (see polydg/mesh/point_groups.h).
constexpr std::string_view kPointVertexArray = "polydg_point_vertex";

/// The name prefixes reserved for the restore arrays: no VtuFieldData name may start with one,
/// and readVtu returns no field data array whose name does.
constexpr std::array<std::string_view, 3> kReservedPrefixes{"polydg_face_", "polydg_element",
                                                            "polydg_point_"};

/// True if `name` starts with one of kReservedPrefixes.
constexpr bool isReservedArrayName(std::string_view name) {
  for (std::string_view prefix : kReservedPrefixes)
    if (name.starts_with(prefix)) return true;
  return false;
}

}  // namespace polydg
