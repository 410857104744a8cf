// polydg's OpenVDB module (libpolydg_openvdb.so, see distance_grids.h): the narrow-band signed
// distance field of a surface obstacle, built with OpenVDB and made exact, and its samplers.
// It uses no polydg library code, only what the interface's header defines, so that it can be
// loaded into any process that holds polydg (the program, the shared library, the tests).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

// OpenVDB's library instantiates meshToVolume() for QuadAndTriangleDataAdapter<Vec3s, Vec3I>
// and gradient() for FloatGrid itself (OPENVDB_USE_EXPLICIT_INSTANTIATION), so this file
// compiles neither.
#include <openvdb/math/Proximity.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/GridOperators.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "physics/contact/distance_grids.h"

namespace polydg {

namespace {

/// The surface in the grid's index space (double precision): vertices and triangles.
struct IndexSpaceMesh {
  std::vector<openvdb::Vec3d> points;
  std::vector<openvdb::Vec3I> triangles;

  /// Distance, in voxels, from the voxel centre ijk to triangle t.
  double distance(const openvdb::Coord& ijk, std::int32_t t) const {
    const openvdb::Vec3d centre(ijk.x(), ijk.y(), ijk.z());
    const openvdb::Vec3I& v = triangles[static_cast<std::size_t>(t)];
    openvdb::Vec3d uvw;
    return (centre - openvdb::math::closestPointOnTriangleToPoint(points[v[0]], points[v[1]],
                                                                  points[v[2]], centre, uvw))
        .length();
  }
};

/// A voxel's distance and nearest triangle, replacing what OpenVDB found.
struct NearerTriangle {
  openvdb::Coord ijk;
  float distance;  ///< world units, signed
  std::int32_t triangle;
};

/// Reads the band's distances and nearest triangles; one per thread.
class BandReader {
 public:
  BandReader(const openvdb::FloatTree& distance, const openvdb::Int32Tree& nearest,
             const IndexSpaceMesh& mesh, double voxel)
      : distance_(distance), nearest_(nearest), mesh_(mesh), voxel_(voxel) {}

  /// The voxel's distance to the nearest of the triangles nearest to it and its 26 neighbours,
  /// if nearer than its own triangle; nothing for a voxel out of the band or voxelized exactly
  /// (within sqrt(3)/2 voxel of the surface, which OpenVDB's voxelization computes exactly).
  std::optional<NearerTriangle> nearer(const openvdb::Coord& ijk) const {
    constexpr double kExactWithin = 0.8660254037844386;
    constexpr double kImprovement = 1e-5;  // voxels: a nearer triangle, not float rounding
    float value;
    std::int32_t own;
    if (!distance_.probeValue(ijk, value) || !nearest_.probeValue(ijk, own)) return {};
    const double current = std::abs(value) / voxel_;
    if (current <= kExactWithin) return {};
    double best = current - kImprovement;
    std::int32_t bestTriangle = own;
    std::array<std::int32_t, 27> seen;
    seen[0] = own;
    int numSeen = 1;
    for (const openvdb::Coord& offset : openvdb::util::COORD_OFFSETS) {
      std::int32_t t;
      if (!nearest_.probeValue(ijk + offset, t) ||
          std::find(seen.begin(), seen.begin() + numSeen, t) != seen.begin() + numSeen)
        continue;
      seen[numSeen++] = t;
      const double d = mesh_.distance(ijk, t);
      if (d < best) {
        best = d;
        bestTriangle = t;
      }
    }
    if (bestTriangle == own) return {};
    const auto refined = static_cast<float>(best * voxel_);
    return NearerTriangle{ijk, value < 0 ? -refined : refined, bestTriangle};
  }

 private:
  openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> distance_;
  openvdb::tree::ValueAccessor<const openvdb::Int32Tree, false> nearest_;
  const IndexSpaceMesh& mesh_;
  double voxel_;
};

/// Makes the band's distances exact. OpenVDB's voxelization gives every voxel within
/// sqrt(3)/2 voxel of the surface its exact distance; it widens the band from there with the
/// triangle nearest a nearby voxel, which is not always the one nearest the voxel, so values a
/// few voxels out can be too large by a good part of a voxel (OpenVDB's optional
/// renormalization smooths them, but costs the exactness near the surface). The first sweep
/// gives each voxel the distance to the nearest of the triangles nearest to it and its 26
/// neighbours (BandReader::nearer()); a nearer triangle spreads one voxel per sweep, so the next
/// sweeps visit the neighbours of the voxels that changed, until none changes or after
/// `maxSweeps`. Every value is the distance to some triangle, so values only decrease; the sign
/// (inside or outside) is OpenVDB's.
void refineDistances(openvdb::FloatTree& distance, openvdb::Int32Tree& nearest,
                     const IndexSpaceMesh& mesh, double voxel, int maxSweeps) {
  using Leaf = openvdb::FloatTree::LeafNodeType;
  std::vector<const Leaf*> leaves;
  distance.getNodes(leaves);
  std::vector<std::vector<NearerTriangle>> perLeaf(leaves.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      const BandReader reader(distance, nearest, mesh, voxel);
                      for (std::size_t l = range.begin(); l != range.end(); ++l)
                        for (auto it = leaves[l]->cbeginValueOn(); it; ++it)
                          if (auto u = reader.nearer(it.getCoord())) perLeaf[l].push_back(*u);
                    });
  std::vector<NearerTriangle> updates;
  for (const auto& u : perLeaf) updates.insert(updates.end(), u.begin(), u.end());
  openvdb::tree::ValueAccessor<openvdb::FloatTree, false> distances(distance);
  openvdb::tree::ValueAccessor<openvdb::Int32Tree, false> nearests(nearest);
  for (int sweep = 1; !updates.empty(); ++sweep) {
    std::vector<openvdb::Coord> next;
    for (const NearerTriangle& u : updates) {
      distances.setValueOnly(u.ijk, u.distance);
      nearests.setValueOnly(u.ijk, u.triangle);
      for (const openvdb::Coord& offset : openvdb::util::COORD_OFFSETS)
        next.push_back(u.ijk + offset);
    }
    if (sweep == maxSweeps) return;
    std::sort(next.begin(), next.end());
    next.erase(std::unique(next.begin(), next.end()), next.end());
    std::vector<std::optional<NearerTriangle>> found(next.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, next.size()),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        const BandReader reader(distance, nearest, mesh, voxel);
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          found[i] = reader.nearer(next[i]);
                      });
    updates.clear();
    for (const auto& u : found)
      if (u) updates.push_back(*u);
  }
}

/// The grids, in the index space of voxels of edge `voxel` about the surface's origin.
class OpenVdbGrids final : public DistanceGrids {
 public:
  explicit OpenVdbGrids(const IndexSpaceSurface& s) {
    openvdb::initialize();  // idempotent; registers OpenVDB's types
    IndexSpaceMesh mesh;
    std::vector<openvdb::Vec3s> points;  // OpenVDB's adapter takes floats
    mesh.points.reserve(s.points.size());
    points.reserve(s.points.size());
    for (const Eigen::Vector3d& p : s.points) {
      mesh.points.emplace_back(p.x(), p.y(), p.z());
      points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z()));
    }
    mesh.triangles.reserve(s.triangles.size());
    for (const auto& t : s.triangles) mesh.triangles.emplace_back(t[0], t[1], t[2]);

    openvdb::math::Transform::Ptr transform =
        openvdb::math::Transform::createLinearTransform(s.voxel);
    transform->postTranslate(openvdb::Vec3d(s.origin.x(), s.origin.y(), s.origin.z()));
    const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(
        points, mesh.triangles);
    // Without renormalization: refineDistances() makes the values exact instead.
    openvdb::Int32Grid::Ptr nearest = openvdb::Int32Grid::create();
    openvdb::FloatGrid::Ptr distance = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        adapter, *transform, static_cast<float>(s.exteriorVoxels),
        static_cast<float>(s.interiorVoxels), openvdb::tools::DISABLE_RENORMALIZATION,
        nearest.get());
    refineDistances(distance->tree(), nearest->tree(), mesh, s.voxel, s.sweeps);
    activeBox_ = distance->evalActiveVoxelBoundingBox();
    gradient_ = openvdb::tools::gradient(*distance);
    distance_ = distance;
  }

  std::unique_ptr<Reader> reader() const override {
    return std::make_unique<GridReader>(*distance_, *gradient_);
  }

  std::array<int, 6> activeBox() const override {
    const openvdb::Coord lo = activeBox_.min(), hi = activeBox_.max();
    return {lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z()};
  }

  std::size_t activeVoxels() const override {
    return static_cast<std::size_t>(distance_->activeVoxelCount());
  }

 private:
  /// Accessors not registered with the trees (they never change once built).
  class GridReader final : public Reader {
   public:
    GridReader(const openvdb::FloatGrid& distance, const openvdb::Vec3SGrid& gradient)
        : distance_(distance.getConstUnsafeAccessor()),
          gradient_(gradient.getConstUnsafeAccessor()) {}

    bool distance(const Eigen::Vector3d& x, float& d) const override {
      return openvdb::tools::BoxSampler::sample(distance_, openvdb::Vec3d(x.x(), x.y(), x.z()), d);
    }

    Eigen::Vector3d gradient(const Eigen::Vector3d& x) const override {
      const openvdb::Vec3s g =
          openvdb::tools::BoxSampler::sample(gradient_, openvdb::Vec3d(x.x(), x.y(), x.z()));
      return {g.x(), g.y(), g.z()};
    }

   private:
    openvdb::FloatGrid::ConstUnsafeAccessor distance_;
    openvdb::Vec3SGrid::ConstUnsafeAccessor gradient_;
  };

  openvdb::FloatGrid::ConstPtr distance_;  ///< world units; background +exterior, -interior band
  openvdb::Vec3SGrid::ConstPtr gradient_;  ///< world units; background zero
  openvdb::CoordBBox activeBox_;           ///< of the distance grid's active voxels
};

}  // namespace

}  // namespace polydg

/// The module's entry point (kBuildDistanceGrids); the caller owns the result.
extern "C" polydg::DistanceGrids* polydg_build_distance_grids(
    const polydg::IndexSpaceSurface& surface) {
  return new polydg::OpenVdbGrids(surface);
}
