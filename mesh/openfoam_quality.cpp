#include "mesh/openfoam_quality.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

namespace polydg {

namespace {

// checkMesh's thresholds (primitiveMesh::nonOrthThreshold_, skewThreshold_, aspect ratio,
// OpenFOAM's SMALL as the least pyramid volume).
constexpr double kSevereNonOrthogonality = 70.0;
constexpr double kMaxSkewness = 4.0;
constexpr double kMaxAspectRatio = 1000.0;
constexpr double kSmall = 1e-15;
constexpr double kMinPyramidVolume = -kSmall;
constexpr double kRootVSmall = 1e-150;

double degrees(double cosine) {
  return std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

/// The face's centre and area vector as OpenFOAM v1912 computes them: a triangle as it is,
/// other polygons as the fan about their corners' mean, each triangle's centroid weighted by
/// its unsigned area (so a non-convex face's centre is not quite its centroid, as checkMesh
/// sees it).
void faceGeometry(const OpenFoamFaces& m, std::size_t f, Vec3& centre, Vec3& area) {
  const std::vector<std::uint32_t>& c = m.corners[f];
  const std::size_t n = c.size();
  if (n == 3) {
    const Vec3 &a = m.points[c[0]], &b = m.points[c[1]], &d = m.points[c[2]];
    centre = (a + b + d) / 3.0;
    area = 0.5 * (b - a).cross(d - a);
    return;
  }
  Vec3 mean = Vec3::Zero();
  for (std::uint32_t v : c) mean += m.points[v];
  mean /= static_cast<double>(n);
  Vec3 sumN = Vec3::Zero(), sumAc = Vec3::Zero();
  double sumA = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 &p = m.points[c[i]], &q = m.points[c[(i + 1) % n]];
    const Vec3 normal = (q - p).cross(mean - p);
    const double a = normal.norm();
    sumN += normal;
    sumA += a;
    sumAc += a * (p + q + mean);
  }
  centre = sumA > 1e-300 ? Vec3(sumAc / (3.0 * sumA)) : mean;
  area = 0.5 * sumN;
}

/// The face's extent from its centre along the unit vector `along`.
double extent(const OpenFoamFaces& m, std::size_t f, const Vec3& centre, const Vec3& along) {
  double least = 0.0;
  for (std::uint32_t v : m.corners[f])
    least = std::max(least, std::abs(along.dot(m.points[v] - centre)));
  return least;
}

}  // namespace

std::vector<std::string> OpenFoamQuality::failedChecks() const {
  std::vector<std::string> out;
  if (maxAspectRatio > kMaxAspectRatio) out.push_back("aspect ratio");
  if (nonOrthogonalityErrors > 0) out.push_back("non-orthogonality");
  if (wrongOrientedFaces > 0) out.push_back("face pyramids");
  if (skewFaces > 0) out.push_back("skewness");
  return out;
}

std::vector<std::string> OpenFoamQuality::advice() const {
  std::vector<std::string> out;
  if (wrongOrientedFaces > 0 || nonOrthogonalityErrors > 0)
    out.push_back(
        "some cells are non-convex so that their centre sees a face from behind or edge-on: "
        "cells the surface cuts into non-convex pieces, or slivers merged into a neighbour "
        "(polydg mesh --merge-slivers 0 avoids the latter; finite volumes take small cells)");
  if (skewBoundaryFaces > 0)
    out.push_back(
        "boundary faces that are small pieces of the input's triangles lie far to the side of "
        "their cell's centre (exact boundaries of finely triangulated curved surfaces in cut "
        "cells); OpenFOAM runs on such meshes, with less accurate boundary gradients");
  if (skewFaces > skewBoundaryFaces)
    out.push_back("internal faces are skewed between cells of very different shapes");
  return out;
}

OpenFoamQuality openFoamQuality(const OpenFoamFaces& m) {
  OpenFoamQuality q;
  const std::size_t nFaces = m.corners.size(), nInternal = m.neighbour.size();
  std::vector<Vec3> fc(nFaces), fa(nFaces);
  for (std::size_t f = 0; f < nFaces; ++f) faceGeometry(m, f, fc[f], fa[f]);

  // Cell centres and volumes: pyramids on each face from the mean of the cell's face centres.
  std::vector<Vec3> estimate(m.cells, Vec3::Zero()), centre(m.cells, Vec3::Zero());
  std::vector<double> count(m.cells, 0.0), volume(m.cells, 0.0);
  std::vector<Vec3> sumMag(m.cells, Vec3::Zero());  // per cell, the faces' |area| components
  auto eachSide = [&](auto&& visit) {
    for (std::size_t f = 0; f < nFaces; ++f) {
      visit(f, m.owner[f], 1.0);
      if (f < nInternal) visit(f, m.neighbour[f], -1.0);
    }
  };
  eachSide([&](std::size_t f, std::uint32_t c, double) {
    estimate[c] += fc[f];
    count[c] += 1.0;
    sumMag[c] += fa[f].cwiseAbs();
  });
  for (std::size_t c = 0; c < m.cells; ++c) estimate[c] /= count[c];
  eachSide([&](std::size_t f, std::uint32_t c, double sign) {
    const double pyramid3 = sign * fa[f].dot(fc[f] - estimate[c]);
    centre[c] += pyramid3 * (0.75 * fc[f] + 0.25 * estimate[c]);
    volume[c] += pyramid3;
  });
  q.minVolume = m.cells ? volume[0] / 3.0 : 0.0;
  for (std::size_t c = 0; c < m.cells; ++c) {
    centre[c] /= volume[c];
    volume[c] /= 3.0;
    q.totalVolume += volume[c];
    q.minVolume = std::min(q.minVolume, volume[c]);
    q.maxVolume = std::max(q.maxVolume, volume[c]);
    const Vec3& s = sumMag[c];
    const double ratio =
        std::max(s.maxCoeff() / (s.minCoeff() + kRootVSmall),
                 s.sum() / 6.0 / std::pow(std::max(kRootVSmall, volume[c]), 2.0 / 3.0));
    q.maxAspectRatio = std::max(q.maxAspectRatio, ratio);
  }

  std::vector<OpenFoamFlaggedFace> flagged;
  double sumCos = 0.0;
  double minCos = 1.0;
  for (std::size_t f = 0; f < nFaces; ++f) {
    const Vec3& own = centre[m.owner[f]];
    OpenFoamFlaggedFace r;
    r.face = f;
    r.cell = m.owner[f];
    const Vec3 cpf = fc[f] - own;
    Vec3 d;
    double least;
    bool cosineError = false;
    if (f < nInternal) {
      const Vec3& nei = centre[m.neighbour[f]];
      d = nei - own;
      const double cosine = d.dot(fa[f]) / (d.norm() * fa[f].norm() + kRootVSmall);
      sumCos += cosine;
      minCos = std::min(minCos, cosine);
      r.nonOrthogonality = degrees(cosine);
      cosineError = cosine <= kSmall;
      // checkMesh counts a face past 70 degrees as severe, and as an error if its cosine is
      // not above OpenFOAM's SMALL.
      if (r.nonOrthogonality > kSevereNonOrthogonality)
        ++(cosine > kSmall ? q.severelyNonOrthogonal : q.nonOrthogonalityErrors);
      least = 0.2 * d.norm();
      r.wrongOriented = fa[f].dot(fc[f] - nei) / 3.0 > -kMinPyramidVolume;
    } else {
      const Vec3 normal = fa[f] / (fa[f].norm() + kRootVSmall);
      d = normal * normal.dot(cpf);
      least = 0.4 * d.norm();
      r.depth = d.norm();
    }
    r.wrongOriented = r.wrongOriented || fa[f].dot(fc[f] - own) / 3.0 < kMinPyramidVolume;
    const Vec3 sv = cpf - (fa[f].dot(cpf) / (fa[f].dot(d) + kRootVSmall)) * d;
    const Vec3 svHat = sv / (sv.norm() + kRootVSmall);
    r.offset = sv.norm();
    r.width = extent(m, f, fc[f], svHat);
    r.skewness = r.offset / (std::max(least, r.width) + kRootVSmall);
    q.maxSkewness = std::max(q.maxSkewness, r.skewness);
    if (r.wrongOriented) ++q.wrongOrientedFaces;
    const bool skew = r.skewness > kMaxSkewness;
    if (skew) {
      ++q.skewFaces;
      if (f >= nInternal) ++q.skewBoundaryFaces;
    }
    if (skew || r.wrongOriented || cosineError) {
      r.kind = f < nInternal ? "internal" : m.patch[f - nInternal];  // only the flagged need it
      flagged.push_back(std::move(r));
    }
  }
  if (nInternal) {
    q.maxNonOrthogonality = degrees(minCos);
    q.averageNonOrthogonality = degrees(sumCos / static_cast<double>(nInternal));
  }
  auto rank = [](const OpenFoamFlaggedFace& r) {
    return std::make_tuple(!r.wrongOriented, -r.nonOrthogonality, -r.skewness, r.face);
  };
  const std::size_t keep = std::min<std::size_t>(flagged.size(), 20);
  std::partial_sort(flagged.begin(), flagged.begin() + static_cast<std::ptrdiff_t>(keep),
                    flagged.end(), [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
  flagged.resize(keep);
  q.worst = std::move(flagged);
  return q;
}

}  // namespace polydg
