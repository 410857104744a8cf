// The last step of reading a surface (polydg/mesh/surface_io.h): the faces a reader found made
// into a triangle surface, vertices shared by exact position and polygons triangulated exactly.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_io.h"

namespace polydg {

/// A coordinate widened to double, with -0.0 replaced by 0.0: after this, two coordinates are
/// equal exactly when their bits are.
inline double canonical(double x) { return x == 0 ? 0.0 : x; }
/// A position with each coordinate canonical().
inline Vec3 canonical(const Vec3& p) {
  return {canonical(p.x()), canonical(p.y()), canonical(p.z())};
}

/// Builds the surface: triangles go in as given, vertices are shared by exact position and
/// numbered in order of first use. Counts what it drops or fans in `info`.
class SurfaceBuilder {
 public:
  /// `path` names the file in errors.
  SurfaceBuilder(const std::string& path, SurfaceReadInfo& info) : path_(path), info_(info) {}

  /// Adds triangle (a, b, c), or counts it as degenerate if two corners are at one position.
  void addTriangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const PositionKey ka = keyOf(a), kb = keyOf(b), kc = keyOf(c);
    if (droppedAsDegenerate(ka, kb, kc)) return;
    surface_.triangles.push_back({id(ka, a), id(kb, b), id(kc, c)});
  }

  /// Room for about `vertices` distinct vertices and `triangles` triangles.
  void reserve(std::size_t vertices, std::size_t triangles) {
    welded_.reserve(vertices);
    surface_.vertices.reserve(vertices);
    surface_.triangles.reserve(triangles);
  }

  /// Adds the triangle of corners a, b, c at positions pa, pb, pc, as addTriangle(pa, pb, pc),
  /// for readers whose faces index a list of points: `welded` holds the vertex of each point
  /// once it has one (kNoVertex before), so a point shared by many faces is looked up once.
  void addTriangle(const std::array<std::size_t, 3>& corners, const std::array<Vec3, 3>& at,
                   std::vector<std::uint32_t>& welded) {
    const PositionKey keys[3] = {keyOf(at[0]), keyOf(at[1]), keyOf(at[2])};
    if (droppedAsDegenerate(keys[0], keys[1], keys[2])) return;
    std::array<std::uint32_t, 3> t;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& w = welded[corners[k]];
      if (w == kNoVertex) w = id(keys[k], at[k]);
      t[k] = w;
    }
    surface_.triangles.push_back(t);
  }
  static constexpr std::uint32_t kNoVertex = 0xffffffffu;

  /// Adds the triangles of a planar polygon of four or more corners: its exact constrained
  /// triangulation (triangulateFace), or a fan from the first corner, counted, if it has zero
  /// area or crossing edges.
  void addPolygon(const std::vector<Vec3>& corners);

  TriangleSurface take() { return std::move(surface_); }
  std::size_t numTriangles() const { return surface_.triangles.size(); }
  std::size_t numVertices() const { return surface_.vertices.size(); }

 private:
  /// The bits of a canonical position; the weld key.
  using PositionKey = std::array<std::uint64_t, 3>;

  struct PositionKeyHash {
    std::size_t operator()(const PositionKey& k) const noexcept {
      std::uint64_t h = 0x9e3779b97f4a7c15ull;
      for (std::uint64_t v : k) {
        h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
        h *= 0xff51afd7ed558ccdull;
      }
      return static_cast<std::size_t>(h ^ (h >> 33));
    }
  };

  static PositionKey keyOf(const Vec3& p) {
    return {std::bit_cast<std::uint64_t>(p.x()), std::bit_cast<std::uint64_t>(p.y()),
            std::bit_cast<std::uint64_t>(p.z())};
  }

  /// True, and counted, if two corners of a triangle are at one position.
  bool droppedAsDegenerate(const PositionKey& a, const PositionKey& b, const PositionKey& c) {
    if (a != b && b != c && c != a) return false;
    ++info_.droppedDegenerate;
    return true;
  }

  /// The id of the vertex at `p` (key `key`), added if new; throws past 2^32 - 1 vertices.
  std::uint32_t id(const PositionKey& key, const Vec3& p);

  const std::string& path_;
  SurfaceReadInfo& info_;
  TriangleSurface surface_;
  std::unordered_map<PositionKey, std::uint32_t, PositionKeyHash> welded_;
};

}  // namespace polydg
