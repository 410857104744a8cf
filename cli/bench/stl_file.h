// A triangle surface written as an ASCII STL file for the programs polydg is compared with
// (snappyHexMesh in the openfoam suite, Gmsh in the meshing suite), which read STL but not all
// of polydg's input formats.
#pragma once

#include <filesystem>
#include <string>

#include "polydg/mesh/surface.h"

namespace polydg::bench {

/// Writes `surface` to `file` as ASCII STL ("solid NAME" ... "endsolid NAME"), one facet per
/// triangle in order, its corners in the triangle's order and its normal the unit vector
/// (b - a) x (c - a); coordinates with 17 significant digits, so they read back as the same
/// doubles. Atomic (a temporary file, then renamed). Throws InputError if it cannot be written.
void writeAsciiStl(const std::filesystem::path& file, const TriangleSurface& surface,
                   const std::string& name);

}  // namespace polydg::bench
