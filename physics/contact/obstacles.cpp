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

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "physics/contact/distance_grids.h"
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

}  // namespace

/// The distance field and its gradient (built by the OpenVDB module: distance_grids.h), in the
/// index space of voxels of edge `voxel` centred at origin + voxel * (i, j, k). The origin is the
/// surface's bounding-box centre, so index coordinates stay small wherever the surface is; world
/// points are taken to index space here, in double precision.
struct Obstacle::Field {
  std::shared_ptr<const DistanceGrids> grids;
  Vec3 origin = Vec3::Zero();
  double voxel = 0.0;

  /// Samples the grids through a reader of its own: one per thread.
  class Reader {
   public:
    Reader(const Field& field, const DistanceFieldOptions& options)
        : field_(field), options_(options), grids_(field.grids->reader()) {}

    /// Distance and normal at the world point x of the field at rest (time 0).
    ObstacleQuery at(const Vec3& x) const {
      const Vec3 index = (x - field_.origin) / field_.voxel;
      float d = 0.0f;
      // No active voxel among the eight around x: outside the band, or deeper in.
      if (!grids_->distance(index, d))
        return {d < 0 ? -options_.interiorBand : options_.exteriorBand, Vec3::Zero()};
      // The outermost voxel layer of a band interpolates with the background: no normal there,
      // as beyond the band.
      if (d >= options_.exteriorBand - field_.voxel) return {options_.exteriorBand, Vec3::Zero()};
      if (d <= -options_.interiorBand + field_.voxel) return {-options_.interiorBand, Vec3::Zero()};
      ObstacleQuery q;
      q.distance = d;
      const Vec3 gradient = grids_->gradient(index);
      const double length = gradient.norm();
      if (length >= kMinGradientLength) q.normal = gradient / length;
      return q;
    }

   private:
    const Field& field_;
    const DistanceFieldOptions& options_;
    std::unique_ptr<DistanceGrids::Reader> grids_;
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
  auto field = std::make_shared<Field>();
  field->origin = box.center();
  field->voxel = options.voxel;
  IndexSpaceSurface index;
  index.origin = field->origin;
  index.voxel = options.voxel;
  index.points.reserve(surface.vertices.size());
  for (const Vec3& p : surface.vertices)
    index.points.push_back((p - field->origin) / options.voxel);  // small: about the centre
  index.triangles.assign(surface.triangles.begin(), surface.triangles.end());
  index.exteriorVoxels = options.exteriorBand / options.voxel;
  index.interiorVoxels = options.interiorBand / options.voxel;
  index.sweeps =
      static_cast<int>(std::ceil((options.exteriorBand + options.interiorBand) / options.voxel));
  field->grids = buildDistanceGrids(index);

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
  const std::array<int, 6> active = field_->grids->activeBox();
  const Vec3 lo(active[0], active[1], active[2]), hi(active[3], active[4], active[5]);
  const Vec3 shift = field_->origin + velocity_ * t;
  return Box3(shift + field_->voxel * (lo - Vec3::Ones()),
              shift + field_->voxel * (hi + Vec3::Ones()));
}

std::size_t Obstacle::activeVoxels() const { return field_ ? field_->grids->activeVoxels() : 0; }

}  // namespace polydg
