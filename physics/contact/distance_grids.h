// The signed distance field of a surface obstacle (physics/contact/obstacles.h) as OpenVDB
// builds and samples it, behind an interface: OpenVDB lives in a module of its own,
// libpolydg_openvdb.so, loaded the first time a field is built. Loading OpenVDB's library took
// about 30 ms, two thirds of every polydg command's start, and only scenes with a surface
// obstacle use it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace polydg {

/// A closed, outward-oriented triangle surface in the grid's index space: voxel (i, j, k) is
/// centred at index point (i, j, k), world point origin + voxel * index.
struct IndexSpaceSurface {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double voxel = 1.0;
  double exteriorVoxels = 0.0, interiorVoxels = 0.0;  ///< the band's widths
  int sweeps = 0;  ///< the most sweeps that make the band's distances exact
};

/// The band's signed distances (world units) and their gradient, sampled trilinearly.
class DistanceGrids {
 public:
  /// Samples through accessors of its own: one per thread.
  class Reader {
   public:
    virtual ~Reader() = default;
    /// The distance at index point x into d; false if no active voxel is among the eight
    /// around x (outside the band, or deeper inside: d then has the background's sign).
    virtual bool distance(const Eigen::Vector3d& x, float& d) const = 0;
    /// The gradient at index point x (world units per world unit).
    virtual Eigen::Vector3d gradient(const Eigen::Vector3d& x) const = 0;
  };

  virtual ~DistanceGrids() = default;
  virtual std::unique_ptr<Reader> reader() const = 0;
  /// The active voxels' bounding box: lowest then highest index, inclusive.
  virtual std::array<int, 6> activeBox() const = 0;
  virtual std::size_t activeVoxels() const = 0;
};

/// The module's entry point, looked up by this name.
using BuildDistanceGrids = DistanceGrids* (*)(const IndexSpaceSurface&);
inline constexpr const char* kBuildDistanceGrids = "polydg_build_distance_grids";

/// The grids of `surface`, built by the OpenVDB module, which is loaded on first use from
/// beside the library or program that holds this code, or from where the build put it. Throws
/// std::runtime_error, naming the places tried, if it cannot be loaded.
std::shared_ptr<const DistanceGrids> buildDistanceGrids(const IndexSpaceSurface& surface);

}  // namespace polydg
