#include "cli/bench/gmsh_case.h"

#include <cstdio>

#include "cli/bench/external_commands.h"
#include "polydg/mesh/slice.h"

namespace polydg::bench {

double polydgCellSize(const TriangleSurface& surface, int cells) {
  return Grid::withCellsAlongLongest(bounds(surface), cells).cellSize;
}

std::string gmshGeo(const std::string& stl) {
  return "// polydg bench --suite meshing: Gmsh's HXT on the surface as it is\n"
         "Merge \"" +
         stl +
         "\";\n"
         "Surface Loop(1) = {1};\n"
         "Volume(1) = {1};\n"
         "Mesh.Algorithm3D = 10;  // HXT\n";
}

std::string gmshCommand(const std::filesystem::path& geo, const std::filesystem::path& msh,
                        const GmshOptions& options) {
  char size[32];
  std::snprintf(size, sizeof size, "%.17g", options.meshSizeMax);
  return "gmsh " + shellQuoted(geo.string()) + " -3 -nt " + std::to_string(options.threads) +
         (options.meshSizeMax > 0 ? std::string(" -clmax ") + size : std::string()) +
         " -format msh41 -o " + shellQuoted(msh.string());
}

}  // namespace polydg::bench
