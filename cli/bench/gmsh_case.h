// Gmsh's HXT tetrahedral mesher run on a surface as polydg meshes it (the Gmsh comparison of
// the meshing suite): the .geo that has Gmsh fill the inside of the surface with tetrahedra,
// the surface's triangles kept as the mesh's boundary; the mesh size limit that matches
// `polydg mesh --cells N`; and the command line.
#pragma once

#include <filesystem>
#include <string>

#include "polydg/mesh/surface.h"

namespace polydg::bench {

/// The edge of polydg's grid cells for `polydg mesh --cells cells`: the longest side of the
/// bounding box of `surface` over `cells` (Grid::withCellsAlongLongest). Throws
/// std::invalid_argument if cells < 1.
double polydgCellSize(const TriangleSurface& surface, int cells);

/// A .geo script that merges the STL file `stl` (a name relative to the .geo's folder; Gmsh
/// reads it as one discrete surface, tag 1, its triangles as they are), makes that surface the
/// boundary of volume 1 (Surface Loop, Volume) and selects HXT (Mesh.Algorithm3D = 10). The
/// surface is neither reclassified nor remeshed.
std::string gmshGeo(const std::string& stl);

/// How Gmsh is run on a .geo of gmshGeo().
struct GmshOptions {
  /// Mesh.MeshSizeMax (-clmax), in the surface's units; 0: none, Gmsh's own sizes (from the
  /// surface's triangles), as issue 35 measured it.
  double meshSizeMax = 0.0;
  int threads = 2;  ///< -nt
};

/// `gmsh GEO -3 -nt THREADS -clmax SIZE -format msh41 -o MSH` (SIZE with 17 significant digits,
/// left out for a size of 0; the paths quoted for /bin/sh): the volume meshed and written as
/// MSH 4.1 ASCII.
std::string gmshCommand(const std::filesystem::path& geo, const std::filesystem::path& msh,
                        const GmshOptions& options);

}  // namespace polydg::bench
