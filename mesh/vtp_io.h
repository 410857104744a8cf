// Triangle surfaces as VTK XML PolyData (.vtp) files, for the deformed embedded surface of a
// solve or of each frame of a simulation (ParaView, VTK 9.1 and meshio read them).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/vtu_io.h"

namespace polydg {

/// A point data array: `components` (1 or 3) doubles per point, point by point.
struct SurfacePointArray {
  std::string name;
  int components = 1;
  std::span<const double> values;
};

/// Writes points and triangles (vertex indices into `points`) as PolyData with the given point
/// data, encoded like writeVtu() (header UInt64, little-endian, uncompressed). Written to
/// `path + ".tmp"` and renamed over `path`, so `path` is never left half-written. Throws
/// std::invalid_argument for a triangle index out of range or an array of the wrong size,
/// component count or an empty or repeated name; std::runtime_error("cannot write PATH: reason")
/// if the file cannot be written.
void writeVtp(const std::string& path, std::span<const Vec3> points,
              std::span<const std::array<std::uint32_t, 3>> triangles,
              const std::vector<SurfacePointArray>& pointData = {},
              VtuEncoding encoding = VtuEncoding::Appended);

}  // namespace polydg
