#include "cli/bench/stl_file.h"

#include <ostream>

#include "model/files.h"
#include "util/format.h"

namespace polydg::bench {

void writeAsciiStl(const std::filesystem::path& file, const TriangleSurface& surface,
                   const std::string& name) {
  writeFileAtomically(file, [&](std::ostream& os) {
    os << "solid " << name << "\n";
    for (const auto& t : surface.triangles) {
      const Vec3 &a = surface.vertices[t[0]], &b = surface.vertices[t[1]],
                 &c = surface.vertices[t[2]];
      const Vec3 n = (b - a).cross(c - a).normalized();
      os << " facet normal " << formatNumber(n.x(), 17) << ' ' << formatNumber(n.y(), 17) << ' '
         << formatNumber(n.z(), 17) << "\n  outer loop\n";
      for (const Vec3* v : {&a, &b, &c})
        os << "   vertex " << formatNumber(v->x(), 17) << ' ' << formatNumber(v->y(), 17) << ' '
           << formatNumber(v->z(), 17) << "\n";
      os << "  endloop\n endfacet\n";
    }
    os << "endsolid " << name << "\n";
  });
}

}  // namespace polydg::bench
