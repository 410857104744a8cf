#include "physics/contact/obstacles.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

// OpenVDB is included here only: it takes long to compile. The library instantiates
// meshToVolume() for QuadAndTriangleDataAdapter<Vec3s, Vec3I> and gradient() for FloatGrid
// itself (OPENVDB_USE_EXPLICIT_INSTANTIATION), so this file compiles neither.
#include <openvdb/math/Proximity.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/GridOperators.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "util/format.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// The narrowest band, in voxels, OpenVDB's meshToVolume() builds (its minBandWidth).
constexpr double kMinBandVoxels = 2.0;
/// The largest extent of a surface, in voxels. OpenVDB takes the vertices in index space as
/// floats, about the surface's centre here: half this extent keeps 1/32 voxel of precision.
constexpr double kMaxVoxelsAcross = 1 << 20;
/// The gradient of a distance field has length 1; a sampled gradient shorter than this (at a
/// medial point, or where the band's active voxels run out) gives no direction.
constexpr double kMinGradientLength = 1e-3;
/// Points per task of a parallel query.
constexpr std::size_t kQueryGrain = 1024;

bool isFinite(const Vec3& v) { return v.allFinite(); }

void requireFiniteVelocity(const char* where, const Vec3& velocity) {
  if (!isFinite(velocity))
    throw std::invalid_argument(std::string(where) + ": the velocity must be finite");
}

void checkOptions(const DistanceFieldOptions& o) {
  const std::string where = "Obstacle::fromSurface: ";
  if (!(std::isfinite(o.voxel) && o.voxel > 0))
    throw std::invalid_argument(where + "the voxel size must be positive and finite (got " +
                                formatNumber(o.voxel) + ")");
  const auto band = [&](const char* name, double width) {
    if (!(std::isfinite(width) && width >= kMinBandVoxels * o.voxel))
      throw std::invalid_argument(where + "the " + name + " band must be finite and at least " +
                                  formatNumber(kMinBandVoxels) + " voxels, " +
                                  formatNumber(kMinBandVoxels * o.voxel) + " (got " +
                                  formatNumber(width) + ")");
  };
  band("exterior", o.exteriorBand);
  band("interior", o.interiorBand);
}

/// Throws unless `s` is a non-empty, closed, outward-oriented surface with finite vertices.
void checkSurface(const TriangleSurface& s) {
  const std::string where = "Obstacle::fromSurface: ";
  if (s.triangles.empty()) throw std::invalid_argument(where + "the surface has no triangles");
  for (const Vec3& p : s.vertices)
    if (!isFinite(p)) throw std::invalid_argument(where + "the surface has a non-finite vertex");
  for (const auto& t : s.triangles)
    for (std::uint32_t v : t)
      if (v >= s.vertices.size())
        throw std::invalid_argument(where + "a triangle names vertex " + std::to_string(v) +
                                    " of " + std::to_string(s.vertices.size()));
  const SurfaceTopology topology = analyzeTopology(s);
  if (!topology.closed())
    throw std::invalid_argument(
        where + "the surface is not closed and consistently oriented (" +
        std::to_string(topology.boundaryEdges) + " boundary, " +
        std::to_string(topology.nonManifoldEdges) + " non-manifold, " +
        std::to_string(topology.misorientedEdges) +
        " misoriented edges): an obstacle is the inside of a closed surface");
  const double volume = enclosedVolume(s);
  if (!(volume > 0))
    throw std::invalid_argument(where + "the surface encloses volume " + formatNumber(volume) +
                                ": it must be oriented outward (reverse it)");
}

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

}  // namespace

/// The distance field and its gradient, in the index space of voxels of edge `voxel` centred at
/// origin + voxel * (i, j, k). The origin is the surface's bounding-box centre, so index
/// coordinates stay small wherever the surface is; world points are taken to index space here,
/// in double precision (the grids' own transforms say the same, for anyone reading them).
struct Obstacle::Field {
  openvdb::FloatGrid::ConstPtr distance;  ///< world units; background +exterior, -interior band
  openvdb::Vec3SGrid::ConstPtr gradient;  ///< world units; background zero
  Vec3 origin = Vec3::Zero();
  double voxel = 0.0;
  openvdb::CoordBBox activeBox;  ///< of the distance grid's active voxels

  /// Samples the grids through accessors of its own: one reader per thread. The accessors are
  /// not registered with the trees (they never change after fromSurface()).
  class Reader {
   public:
    Reader(const Field& field, const DistanceFieldOptions& options)
        : field_(field),
          options_(options),
          distance_(field.distance->getConstUnsafeAccessor()),
          gradient_(field.gradient->getConstUnsafeAccessor()) {}

    /// Distance and normal at the world point x of the field at rest (time 0).
    ObstacleQuery at(const Vec3& x) const {
      const Vec3 index = (x - field_.origin) / field_.voxel;
      const openvdb::Vec3d ijk(index.x(), index.y(), index.z());
      float d = 0.0f;
      // No active voxel among the eight around x: outside the band, or deeper in.
      if (!openvdb::tools::BoxSampler::sample(distance_, ijk, d))
        return {d < 0 ? -options_.interiorBand : options_.exteriorBand, Vec3::Zero()};
      // The outermost voxel layer of a band interpolates with the background: no normal there,
      // as beyond the band.
      if (d >= options_.exteriorBand - field_.voxel) return {options_.exteriorBand, Vec3::Zero()};
      if (d <= -options_.interiorBand + field_.voxel) return {-options_.interiorBand, Vec3::Zero()};
      ObstacleQuery q;
      q.distance = d;
      const openvdb::Vec3s g = openvdb::tools::BoxSampler::sample(gradient_, ijk);
      const Vec3 gradient(g.x(), g.y(), g.z());
      const double length = gradient.norm();
      if (length >= kMinGradientLength) q.normal = gradient / length;
      return q;
    }

   private:
    const Field& field_;
    const DistanceFieldOptions& options_;
    openvdb::FloatGrid::ConstUnsafeAccessor distance_;
    openvdb::Vec3SGrid::ConstUnsafeAccessor gradient_;
  };
};

Obstacle Obstacle::halfSpace(const Plane& below, const Vec3& velocity) {
  const double length = below.normal.norm();
  if (!isFinite(below.normal) || !(length > 0) || !std::isfinite(length))
    throw std::invalid_argument(
        "Obstacle::halfSpace: the plane's normal must be finite and non-zero");
  if (!std::isfinite(below.offset))
    throw std::invalid_argument("Obstacle::halfSpace: the plane's offset must be finite");
  requireFiniteVelocity("Obstacle::halfSpace", velocity);
  Obstacle o;
  o.velocity_ = velocity;
  o.plane_ = below;
  o.unitNormal_ = below.normal / length;
  o.unitOffset_ = below.offset / length;
  return o;
}

Obstacle Obstacle::fromSurface(const TriangleSurface& surface, const DistanceFieldOptions& options,
                               const Vec3& velocity) {
  const Stopwatch watch;
  checkOptions(options);
  requireFiniteVelocity("Obstacle::fromSurface", velocity);
  checkSurface(surface);
  const Box3 box = polydg::bounds(surface);
  const double across = box.sizes().maxCoeff() / options.voxel;
  if (across > kMaxVoxelsAcross)
    throw std::invalid_argument("Obstacle::fromSurface: the surface is " + formatNumber(across) +
                                " voxels across, more than " + formatNumber(kMaxVoxelsAcross) +
                                ": use a larger voxel");
  openvdb::initialize();  // idempotent; registers OpenVDB's types

  auto field = std::make_shared<Field>();
  field->origin = box.center();
  field->voxel = options.voxel;
  IndexSpaceMesh mesh;
  std::vector<openvdb::Vec3s> points;  // OpenVDB's adapter takes floats
  mesh.points.reserve(surface.vertices.size());
  points.reserve(surface.vertices.size());
  for (const Vec3& p : surface.vertices) {
    const Vec3 index = (p - field->origin) / options.voxel;  // small: about the centre
    mesh.points.emplace_back(index.x(), index.y(), index.z());
    points.emplace_back(static_cast<float>(index.x()), static_cast<float>(index.y()),
                        static_cast<float>(index.z()));
  }
  mesh.triangles.reserve(surface.triangles.size());
  for (const auto& t : surface.triangles) mesh.triangles.emplace_back(t[0], t[1], t[2]);

  openvdb::math::Transform::Ptr transform =
      openvdb::math::Transform::createLinearTransform(options.voxel);
  transform->postTranslate(openvdb::Vec3d(field->origin.x(), field->origin.y(), field->origin.z()));
  const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(
      points, mesh.triangles);
  // Without renormalization: refineDistances() makes the values exact instead.
  openvdb::Int32Grid::Ptr nearest = openvdb::Int32Grid::create();
  openvdb::FloatGrid::Ptr distance = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      adapter, *transform, static_cast<float>(options.exteriorBand / options.voxel),
      static_cast<float>(options.interiorBand / options.voxel),
      openvdb::tools::DISABLE_RENORMALIZATION, nearest.get());
  const int sweeps =
      static_cast<int>(std::ceil((options.exteriorBand + options.interiorBand) / options.voxel));
  refineDistances(distance->tree(), nearest->tree(), mesh, options.voxel, sweeps);
  field->activeBox = distance->evalActiveVoxelBoundingBox();
  field->gradient = openvdb::tools::gradient(*distance);
  field->distance = distance;

  Obstacle o;
  o.velocity_ = velocity;
  o.options_ = options;
  o.field_ = std::move(field);
  o.setupSeconds_ = watch.seconds();
  return o;
}

void Obstacle::query(std::span<const Vec3> points, double t, std::span<ObstacleQuery> out) const {
  if (points.size() != out.size())
    throw std::invalid_argument("Obstacle::query: " + std::to_string(points.size()) +
                                " points but room for " + std::to_string(out.size()) + " answers");
  const Vec3 shift = velocity_ * t;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), kQueryGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (!field_) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          out[i] = query(points[i], t);
                        return;
                      }
                      const Field::Reader reader(*field_, options_);
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        out[i] = reader.at(points[i] - shift);
                    });
}

ObstacleQuery Obstacle::query(const Vec3& point, double t) const {
  const Vec3 x = point - velocity_ * t;
  if (field_) return Field::Reader(*field_, options_).at(x);
  return {unitNormal_.dot(x) - unitOffset_, unitNormal_};
}

Box3 Obstacle::bounds(double t) const {
  if (!field_) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    return Box3(Vec3::Constant(-inf), Vec3::Constant(inf));
  }
  // Trilinear samples reach one voxel beyond the active voxels.
  const openvdb::Coord lo = field_->activeBox.min(), hi = field_->activeBox.max();
  const Vec3 shift = field_->origin + velocity_ * t;
  return Box3(shift + field_->voxel * Vec3(lo.x() - 1, lo.y() - 1, lo.z() - 1),
              shift + field_->voxel * Vec3(hi.x() + 1, hi.y() + 1, hi.z() + 1));
}

std::size_t Obstacle::activeVoxels() const {
  return field_ ? static_cast<std::size_t>(field_->distance->activeVoxelCount()) : 0;
}

}  // namespace polydg
