// The boundary of an OpenFOAM case's mesh read back from its ASCII constant/polyMesh (points,
// faces, boundary), for the openfoam suite to measure how closely a mesher's boundary follows
// the input surface and what volume it encloses. Written here because OpenFOAM ships no library
// for C++ programs outside its own build, and the three files need a few dozen lines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg::bench {

/// A patch of the boundary file: its name and its faces, `start` .. `start + faces - 1` of the
/// faces file.
struct FoamPatch {
  std::string name;
  std::size_t start = 0, faces = 0;
};

/// The mesh's points and the faces of all its patches, each listing point indices in OpenFOAM's
/// order (its normal, by the right-hand rule, points out of the mesh).
struct FoamBoundary {
  std::vector<Vec3> points;
  std::vector<std::vector<std::uint32_t>> faces;  ///< patch by patch, in the boundary file's order
  std::vector<FoamPatch> patches;
};

/// Reads CASE/constant/polyMesh/{points,faces,boundary} in OpenFOAM's ASCII format: the FoamFile
/// header and comments skipped, lists as `N ( ... )` (or `N{value}` for a uniform one), points
/// as `(x y z)`, faces as `k(a b ...)` (class faceList) or as the offsets and indices of class
/// faceCompactList. Throws InputError naming the file for a missing or gzipped file, a binary
/// one, or text it cannot read, and for a patch or face index out of range.
FoamBoundary readFoamBoundary(const std::filesystem::path& caseDir);

/// Points on every face: its vertices, the midpoints of its edges and its vertex mean (a point
/// shared by two faces appears twice).
std::vector<Vec3> boundarySamples(const FoamBoundary& boundary);

/// The volume the faces enclose (positive when they point outward): each face fanned from its
/// vertex mean into triangles, the signed tetrahedra from `reference` to them summed.
double enclosedVolume(const FoamBoundary& boundary, const Vec3& reference);

}  // namespace polydg::bench
