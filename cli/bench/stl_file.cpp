#include "cli/bench/stl_file.h"

#include <cstdio>
#include <ostream>

#include "model/files.h"

namespace polydg::bench {

namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

}  // namespace

void writeAsciiStl(const std::filesystem::path& file, const TriangleSurface& surface,
                   const std::string& name) {
  writeFileAtomically(file, [&](std::ostream& os) {
    os << "solid " << name << "\n";
    for (const auto& t : surface.triangles) {
      const Vec3 &a = surface.vertices[t[0]], &b = surface.vertices[t[1]],
                 &c = surface.vertices[t[2]];
      const Vec3 n = (b - a).cross(c - a).normalized();
      os << " facet normal " << number(n.x()) << ' ' << number(n.y()) << ' ' << number(n.z())
         << "\n  outer loop\n";
      for (const Vec3* v : {&a, &b, &c})
        os << "   vertex " << number(v->x()) << ' ' << number(v->y()) << ' ' << number(v->z())
           << "\n";
      os << "  endloop\n endfacet\n";
    }
    os << "endsolid " << name << "\n";
  });
}

}  // namespace polydg::bench
