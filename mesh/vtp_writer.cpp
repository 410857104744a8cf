// writeVtp(): triangle surfaces as VTK XML PolyData (mesh/vtp_io.h).
#include <stdexcept>
#include <unordered_set>

#include "mesh/vtk_format.h"
#include "mesh/vtp_io.h"

namespace polydg {

void writeVtp(const std::string& path, std::span<const Vec3> points,
              std::span<const std::array<std::uint32_t, 3>> triangles,
              const std::vector<SurfacePointArray>& pointData, VtuEncoding encoding) {
  using vtk_format::ArrayOut;
  const std::size_t np = points.size();
  std::unordered_set<std::string> names;
  for (const SurfacePointArray& a : pointData) {
    if (a.name.empty()) throw std::invalid_argument("writeVtp: a point array has no name");
    if (!names.insert(a.name).second)
      throw std::invalid_argument("writeVtp: two point arrays are named '" + a.name + "'");
    if (a.components != 1 && a.components != 3)
      throw std::invalid_argument("writeVtp: point array '" + a.name +
                                  "' must have 1 or 3 components");
    if (a.values.size() != np * static_cast<std::size_t>(a.components))
      throw std::invalid_argument("writeVtp: point array '" + a.name + "' has the wrong size");
  }
  std::vector<double> coordinates;
  coordinates.reserve(3 * np);
  for (const Vec3& p : points) coordinates.insert(coordinates.end(), {p.x(), p.y(), p.z()});
  std::vector<std::int64_t> connectivity, offsets;
  connectivity.reserve(3 * triangles.size());
  for (const auto& t : triangles) {
    for (std::uint32_t v : t) {
      if (v >= np) throw std::invalid_argument("writeVtp: a triangle names a missing point");
      connectivity.push_back(v);
    }
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
  }
  const std::string inner = "          ";
  std::vector<ArrayOut> arrays;
  for (const SurfacePointArray& a : pointData)
    arrays.push_back(vtk_format::floatArray(inner, a.name, a.components, a.values));
  const std::size_t numPointArrays = arrays.size();
  arrays.push_back(vtk_format::floatArray(inner, "Points", 3, coordinates));
  arrays.push_back(vtk_format::intArray(inner, "connectivity", connectivity));
  arrays.push_back(vtk_format::intArray(inner, "offsets", offsets));
  std::vector<std::size_t> offsetOf;
  std::size_t offset = 0;
  for (const ArrayOut& a : arrays) {
    offsetOf.push_back(offset);
    offset += a.binaryBytes();
  }

  vtk_format::writeReplacing(path, [&](std::ostream& os) {
    auto put = [&](std::size_t k) {
      vtk_format::writeDataArray(os, arrays[k], encoding, offsetOf[k]);
    };
    os << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\""
          " header_type=\"UInt64\">\n"
       << "  <PolyData>\n"
       << "    <Piece NumberOfPoints=\"" << np << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\""
       << " NumberOfStrips=\"0\" NumberOfPolys=\"" << triangles.size() << "\">\n"
       << "      <PointData>\n";
    for (std::size_t k = 0; k < numPointArrays; ++k) put(k);
    os << "      </PointData>\n      <Points>\n";
    put(numPointArrays);
    os << "      </Points>\n      <Polys>\n";
    put(numPointArrays + 1);
    put(numPointArrays + 2);
    os << "      </Polys>\n    </Piece>\n  </PolyData>\n";
    if (encoding == VtuEncoding::Appended) {
      os << "  <AppendedData encoding=\"raw\">\n   _";
      for (const ArrayOut& a : arrays) vtk_format::writeAppendedBytes(os, a);
      os << "\n  </AppendedData>\n";
    }
    os << "</VTKFile>\n";
  });
}

}  // namespace polydg
