// The MLS surface embedding (physics/contact/embedding.h): point location by piece, the fit of
// eq. (18) behind each point's Phi row, and the weights W = Phi S of eq. (19). The samples are
// made in embedding_samples.cpp and updated after an edit in embedding_update.cpp.
#include "polydg/physics/contact/embedding.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "mesh/face_triangulation.h"
#include "physics/contact/embedding_kernels.h"
#include "physics/contact/embedding_samples.h"
#include "polydg/mesh/geometry.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// Supports are widened by this factor, up to this many times, when a point's fit is singular;
/// after that the point takes every sample of its piece.
constexpr double kWidening = 1.5;
constexpr int kMaxWidenings = 8;

/// The truncated Gaussian of eq. (18): exp(-(2r/R)^2) shifted to vanish at r = R.
double kernel(double r, double radius) {
  if (r >= radius) return 0.0;
  const double q = 2.0 * r / radius;
  return std::exp(-q * q) - std::exp(-4.0);
}

/// Closest distance from x to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
double triangleDistance(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = x - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.norm();
  const Vec3 bp = x - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (x - (a + d1 / (d1 - d3) * ab)).norm();
  const Vec3 cp = x - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (x - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return (x - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (x - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

/// The solid angle of triangle (a, b, c) seen from x (Van Oosterom and Strackee), signed by
/// the triangle's orientation.
double solidAngle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 p = a - x, q = b - x, r = c - x;
  const double lp = p.norm(), lq = q.norm(), lr = r.norm();
  const double numerator = p.dot(q.cross(r));
  const double denominator = lp * lq * lr + p.dot(q) * lr + p.dot(r) * lq + q.dot(r) * lp;
  return 2.0 * std::atan2(numerator, denominator);
}

}  // namespace

namespace {

/// Inside (0) or the distance to the boundary of element e.
double elementDistance(const PolyMesh& mesh, ElementId e, const Vec3& x,
                       const std::vector<std::vector<std::array<VertexId, 3>>>& triangles) {
  double angle = 0.0, distance = std::numeric_limits<double>::infinity();
  for (const FaceUse& use : mesh.element(e).faces) {
    for (const auto& t : triangles[use.face.index()]) {
      const Vec3 &a = mesh.position(t[0]), &b = mesh.position(t[1]), &c = mesh.position(t[2]);
      // Face normals point out of the front element: reversed uses see them inward.
      angle += use.reversed ? -solidAngle(x, a, b, c) : solidAngle(x, a, b, c);
      distance = std::min(distance, triangleDistance(x, a, b, c));
    }
  }
  return angle > 2.0 * std::numbers::pi ? 0.0 : distance;
}

/// Resolves the points whose candidate elements disagree (`ambiguous[k]`, ascending) by a
/// geometric test: the element that holds point which[k], or else the nearest one (ties go
/// to the lowest element); the faces of those elements are triangulated once.
void locateAmbiguous(const PolyMesh& mesh, const std::vector<Vec3>& points,
                     std::span<const std::uint32_t> which,
                     const std::vector<std::vector<std::uint32_t>>& ambiguous,
                     std::vector<std::uint32_t>& element) {
  std::vector<char> needed(mesh.numFaces(), 0);
  bool any = false;
  for (const auto& list : ambiguous)
    for (std::uint32_t e : list) {
      for (const FaceUse& use : mesh.element(ElementId(e)).faces) needed[use.face.index()] = 1;
      any = true;
    }
  if (!any) return;
  std::vector<std::vector<std::array<VertexId, 3>>> triangles(mesh.numFaces());
  tbb::parallel_for(std::size_t(0), mesh.numFaces(), [&](std::size_t f) {
    if (needed[f]) triangles[f] = triangulateFace(mesh, FaceId(f));
  });
  tbb::parallel_for(std::size_t(0), which.size(), [&](std::size_t k) {
    if (ambiguous[k].empty()) return;
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t e : ambiguous[k]) {  // ascending: ties go to the lowest element
      const double d = elementDistance(mesh, ElementId(e), points[which[k]], triangles);
      if (d < best) best = d, element[k] = e;
    }
  });
}

}  // namespace

std::vector<std::uint32_t> SurfaceEmbedding::locatePoints(const PolyMesh& mesh, const Samples& s,
                                                          std::span<const std::uint32_t> which,
                                                          Rows& r) const {
  const std::size_t count = which.size();
  const bool elementLinear = options_.method == EmbeddingMethod::ElementLinear;
  // The elements whose box holds the point; a geometric test only where they disagree on what
  // matters (the piece; for ElementLinear the element).
  std::vector<std::uint32_t> element(count, 0);
  std::vector<std::vector<std::uint32_t>> ambiguous(count);
  tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
    const Vec3& x = points_[which[k]];
    std::vector<std::uint32_t> candidates;
    s.elementGrid.visit(x, 0, [&](std::uint32_t e) {
      if (s.boxes[e].contains(x)) candidates.push_back(e);
    });
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    if (candidates.empty()) {  // outside every element: the nearest box
      r.outside[k] = true;
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t e = 0; e < s.boxes.size(); ++e) {
        const double d = s.boxes[e].exteriorDistance(x);
        if (d < best) best = d, element[k] = static_cast<std::uint32_t>(e);
      }
      return;
    }
    element[k] = candidates.front();
    bool agree = true;
    for (std::uint32_t e : candidates)
      agree = agree && (elementLinear ? e == candidates.front()
                                      : s.elementPiece[e] == s.elementPiece[candidates.front()]);
    if (!agree) ambiguous[k] = std::move(candidates);
  });
  locateAmbiguous(mesh, points_, which, ambiguous, element);
  return element;
}

double SurfaceEmbedding::fitRow(const Samples& s, const Vec3& x, std::uint32_t element,
                                std::uint32_t piece,
                                std::vector<std::pair<std::uint32_t, double>>& row) const {
  const bool elementLinear = options_.method == EmbeddingMethod::ElementLinear;
  std::vector<std::uint32_t> chosen;
  std::vector<double> theta;
  double widening = 1.0;
  auto gather = [&](int attempt) {
    chosen.clear();
    theta.clear();
    if (elementLinear) {
      for (std::size_t q = s.elementSampleStart[element]; q < s.elementSampleStart[element + 1];
           ++q) {
        chosen.push_back(s.elementSamples[q]);
        theta.push_back(1.0);
      }
      return;
    }
    if (attempt > kMaxWidenings) {  // every sample of the piece
      for (std::size_t q = 0; q < s.positions.size(); ++q)
        if (s.piece[q] == piece) {
          chosen.push_back(static_cast<std::uint32_t>(q));
          theta.push_back(1.0);
        }
      return;
    }
    const int reach = static_cast<int>(std::ceil(widening - 1e-12));
    s.sampleGrid.visit(x, reach, [&](std::uint32_t q) {
      if (s.piece[q] != piece) return;
      const double w = kernel((x - s.positions[q]).norm(), widening * s.radius[q]);
      if (w > 0.0) {
        chosen.push_back(q);
        theta.push_back(w);
      }
    });
  };
  for (int attempt = 0;; ++attempt) {
    gather(attempt);
    double h = 0.0;
    for (std::uint32_t q : chosen) h = std::max(h, (s.positions[q] - x).norm());
    if (!(h > 0.0)) h = 1.0;
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    std::vector<Eigen::Vector4d> p(chosen.size());
    for (std::size_t j = 0; j < chosen.size(); ++j) {
      p[j] << 1.0, (s.positions[chosen[j]] - x) / h;
      a.noalias() += theta[j] * p[j] * p[j].transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(a);
    const double largest = eig.eigenvalues().maxCoeff(), smallest = eig.eigenvalues().minCoeff();
    const bool singular = !(largest > 0.0) || smallest < kMinimumConditioning * largest;
    if (singular && !elementLinear && attempt <= kMaxWidenings) {
      widening *= kWidening;
      continue;
    }
    if (singular)
      throw std::logic_error("SurfaceEmbedding: the samples of a point's piece do not span 3D");
    const Eigen::Vector4d y =
        eig.eigenvectors() * (eig.eigenvalues().cwiseInverse().asDiagonal() *
                              (eig.eigenvectors().transpose() * Eigen::Vector4d::UnitX()));
    row.clear();
    for (std::size_t j = 0; j < chosen.size(); ++j)
      row.emplace_back(chosen[j], theta[j] * p[j].dot(y));
    compressRow(row);
    break;
  }
  return widening;
}

SurfaceEmbedding::Rows SurfaceEmbedding::computeRows(const PolyMesh& mesh, const Samples& s,
                                                     std::span<const std::uint32_t> which) {
  const std::size_t count = which.size();
  Rows r;
  r.piece.assign(count, 0);
  r.widening.assign(count, 1.0f);
  r.outside.assign(count, false);
  r.rows.resize(count);
  const std::vector<std::uint32_t> element = locatePoints(mesh, s, which, r);
  tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
    const std::uint32_t piece = s.elementPiece[element[k]];
    r.piece[k] = piece;
    const double widening = fitRow(s, points_[which[k]], element[k], piece, r.rows[k]);
    r.widening[k] = static_cast<float>(widening);
  });
  return r;
}

SurfaceEmbedding::SurfaceEmbedding(const PolyMesh& mesh, const DgBasis& basis,
                                   std::vector<Vec3> points, const EmbeddingOptions& options)
    : options_(options), points_(std::move(points)), n_(basis.size()) {
  const Stopwatch watch;
  if (!(options_.support > 0.0) || !std::isfinite(options_.support))
    throw std::invalid_argument("the embedding's support must be a positive number");
  if (mesh.numElements() == 0) throw std::invalid_argument("cannot embed into an empty mesh");
  Samples s = makeSamples(mesh, basis);
  std::vector<std::uint32_t> all(points_.size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<std::uint32_t>(k);
  Rows rows = computeRows(mesh, s, all);
  pointPiece_ = std::move(rows.piece);
  pointWidening_ = std::move(rows.widening);
  pointOutside_.assign(rows.outside.begin(), rows.outside.end());
  outside_ = static_cast<std::size_t>(std::count(pointOutside_.begin(), pointOutside_.end(), 1));
  pointStart_.assign(1, 0);
  for (const auto& row : rows.rows) {
    for (const auto& [c, v] : row) {
      pointColumns_.push_back(c);
      pointValues_.push_back(v);
    }
    pointStart_.push_back(pointColumns_.size());
  }
  adopt(std::move(s));
  setupSeconds_ = watch.seconds();
}

void SurfaceEmbedding::adopt(Samples&& s) {
  numPieces_ = s.numPieces;
  numElements_ = s.elementPiece.size();
  constant_ = std::move(s.constant);
  samplePositions_ = std::move(s.positions);
  sampleRadius_ = std::move(s.radius);
  samplePiece_ = std::move(s.piece);
  sampleStart_ = std::move(s.start);
  sampleColumns_ = std::move(s.columns);
  sampleValues_ = std::move(s.values);
  computeWeights();
}

SurfaceEmbedding SurfaceEmbedding::boundaryNodes(const PolyMesh& mesh, const DgBasis& basis,
                                                 std::vector<double>& areas) {
  const Stopwatch watch;
  if (mesh.numElements() == 0) throw std::invalid_argument("cannot embed into an empty mesh");
  SurfaceEmbedding m;
  m.options_.method = EmbeddingMethod::Nodal;
  m.n_ = basis.size();
  m.pointStart_.assign(1, 0);
  Samples s = m.makeSamples(mesh, basis);
  // Boundary vertices per piece, in order of first appearance; area shares.
  std::unordered_map<std::uint32_t, std::uint32_t> pointOf;  // sample -> point
  areas.clear();
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Face& face = mesh.face(FaceId(f));
    if (face.back.valid()) continue;
    const std::uint32_t piece = s.elementPiece[face.front.index()];
    std::vector<VertexId> corners(face.vertices.begin(), face.vertices.end());
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    const double share = areaVector(mesh, FaceId(f)).norm() / static_cast<double>(corners.size());
    for (VertexId v : corners) {
      const std::uint32_t sample =
          s.vertexSample.at((static_cast<std::uint64_t>(v.value) << 32) | piece);
      const auto [it, added] =
          pointOf.emplace(sample, static_cast<std::uint32_t>(m.points_.size()));
      if (added) {
        m.points_.push_back(mesh.position(v));
        m.pointPiece_.push_back(piece);
        m.pointColumns_.push_back(sample);
        m.pointValues_.push_back(1.0);
        m.pointStart_.push_back(m.pointColumns_.size());
        areas.push_back(0.0);
      }
      areas[it->second] += share;
    }
  }
  m.pointWidening_.assign(m.points_.size(), 1.0f);
  m.pointOutside_.assign(m.points_.size(), 0);
  m.adopt(std::move(s));
  m.setupSeconds_ = watch.seconds();
  return m;
}

Eigen::Matrix<double, Eigen::Dynamic, 3> SurfaceEmbedding::displacements(
    const Eigen::VectorXd& coefficients) const {
  const std::size_t np = numPoints();
  const std::size_t n = static_cast<std::size_t>(n_);
  if (static_cast<std::size_t>(coefficients.size()) != numElements_ * 3 * n)
    throw std::invalid_argument("SurfaceEmbedding: coefficients of another mesh or degree");
  Eigen::Matrix<double, Eigen::Dynamic, 3> out(static_cast<Eigen::Index>(np), 3);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, np, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t p = range.begin(); p != range.end(); ++p)
                        out.row(static_cast<Eigen::Index>(p)) =
                            displacement(p, coefficients).transpose();
                    });
  return out;
}

void SurfaceEmbedding::computeWeights() {
  const std::size_t np = numPoints();
  std::vector<std::vector<std::pair<std::uint32_t, double>>> rows(np);
  tbb::parallel_for(std::size_t(0), np, [&](std::size_t p) {
    auto& row = rows[p];
    for (std::size_t q = pointStart_[p]; q < pointStart_[p + 1]; ++q) {
      const std::size_t s = pointColumns_[q];
      for (std::size_t r = sampleStart_[s]; r < sampleStart_[s + 1]; ++r)
        row.emplace_back(sampleColumns_[r], pointValues_[q] * sampleValues_[r]);
    }
    compressRow(row);
  });
  // Rows are sorted by column (compressRow), so an element's functions are adjacent.
  const std::size_t n = static_cast<std::size_t>(n_);
  weightStart_.assign(1, 0);
  weightElements_.clear();
  weightValues_.clear();
  for (const auto& row : rows) {
    for (const auto& [c, v] : row) {
      const std::uint32_t element = static_cast<std::uint32_t>(c / n);
      if (weightElements_.size() == weightStart_.back() || weightElements_.back() != element) {
        weightElements_.push_back(element);
        weightValues_.resize(weightValues_.size() + n, 0.0);
      }
      weightValues_[(weightElements_.size() - 1) * n + c % n] = v;
    }
    weightStart_.push_back(weightElements_.size());
  }
}

WeightBlocks SurfaceEmbedding::weightBlocks(std::size_t p) const {
  const std::size_t b = weightStart_[p], e = weightStart_[p + 1];
  const std::size_t n = static_cast<std::size_t>(n_);
  return {{weightElements_.data() + b, e - b}, {weightValues_.data() + b * n, (e - b) * n}};
}

Vec3 SurfaceEmbedding::displacement(std::size_t p, const Eigen::VectorXd& coefficients) const {
  const std::size_t b = weightStart_[p];
  double out[3];
  blockWeightedSum(n_, weightElements_.data() + b, weightStart_[p + 1] - b,
                   weightValues_.data() + b * static_cast<std::size_t>(n_), coefficients.data(),
                   out);
  return Vec3(out[0], out[1], out[2]);
}

Eigen::SparseMatrix<double, Eigen::RowMajor, int> SurfaceEmbedding::weights() const {
  const std::size_t n = static_cast<std::size_t>(n_);
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(weightValues_.size());
  for (std::size_t p = 0; p < numPoints(); ++p)
    for (std::size_t k = weightStart_[p]; k < weightStart_[p + 1]; ++k)
      for (std::size_t i = 0; i < n; ++i)
        if (weightValues_[k * n + i] != 0.0)
          triplets.emplace_back(static_cast<int>(p), static_cast<int>(weightElements_[k] * n + i),
                                weightValues_[k * n + i]);
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> w(
      static_cast<int>(numPoints()), static_cast<int>(numElements_ * static_cast<std::size_t>(n_)));
  w.setFromTriplets(triplets.begin(), triplets.end());
  return w;
}

}  // namespace polydg
