// The MLS surface embedding (physics/contact/embedding.h): samples, point location by piece, the
// weights of eq. (18)-(19), and their update after an edit.
#include "polydg/physics/contact/embedding.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "mesh/face_triangulation.h"
#include "polydg/mesh/geometry.h"
#include "util/stopwatch.h"
#include "util/union_find.h"

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

/// A uniform hash grid of boxes or points: the cells each item overlaps.
class HashGrid {
 public:
  HashGrid() = default;
  HashGrid(const Box3& bounds, double cell) : origin_(bounds.min()), cell_(cell) {}

  std::array<std::int64_t, 3> cellOf(const Vec3& x) const {
    std::array<std::int64_t, 3> c;
    for (int k = 0; k < 3; ++k)
      c[static_cast<std::size_t>(k)] =
          static_cast<std::int64_t>(std::floor((x[k] - origin_[k]) / cell_));
    return c;
  }
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    auto part = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
    return part(i) | (part(j) << 21) | (part(k) << 42);
  }
  void insert(const Box3& box, std::uint32_t item) {
    const auto lo = cellOf(box.min()), hi = cellOf(box.max());
    for (std::int64_t i = lo[0]; i <= hi[0]; ++i)
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
        for (std::int64_t k = lo[2]; k <= hi[2]; ++k) cells_[key(i, j, k)].push_back(item);
  }
  void insert(const Vec3& x, std::uint32_t item) {
    const auto c = cellOf(x);
    cells_[key(c[0], c[1], c[2])].push_back(item);
  }
  /// Items of the cells within `reach` cells of x's cell.
  template <class F>
  void visit(const Vec3& x, int reach, F&& f) const {
    const auto c = cellOf(x);
    for (std::int64_t i = c[0] - reach; i <= c[0] + reach; ++i)
      for (std::int64_t j = c[1] - reach; j <= c[1] + reach; ++j)
        for (std::int64_t k = c[2] - reach; k <= c[2] + reach; ++k) {
          const auto it = cells_.find(key(i, j, k));
          if (it == cells_.end()) continue;
          for (std::uint32_t item : it->second) f(item);
        }
  }
  double cell() const { return cell_; }

 private:
  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1.0;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

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

/// Sorts a sparse row by column and sums duplicate columns.
void compress(std::vector<std::pair<std::uint32_t, double>>& row) {
  // Stable: duplicates are summed in the order given (deterministic sums).
  std::stable_sort(row.begin(), row.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::size_t out = 0;
  for (std::size_t k = 0; k < row.size(); ++k) {
    if (out > 0 && row[out - 1].first == row[k].first)
      row[out - 1].second += row[k].second;
    else
      row[out++] = row[k];
  }
  row.resize(out);
}

}  // namespace

struct SurfaceEmbedding::Samples {
  std::vector<Vec3> positions;
  std::vector<double> radius;
  std::vector<std::uint32_t> piece;
  std::vector<std::size_t> start{0};
  std::vector<std::uint32_t> columns;
  std::vector<double> values;
  std::size_t numPieces = 0;
  std::vector<std::uint32_t> elementPiece;
  /// The vertex samples of each element (ElementLinear).
  std::vector<std::size_t> elementSampleStart{0};
  std::vector<std::uint32_t> elementSamples;
  std::vector<Box3> boxes;
  HashGrid elementGrid, sampleGrid;
  std::unordered_map<std::uint64_t, std::uint32_t> vertexSample;  ///< (vertex << 32 | piece)
  double largestRadius = 0.0;

  void addRow(std::vector<std::pair<std::uint32_t, double>>& row) {
    compress(row);
    for (const auto& [c, v] : row) {
      columns.push_back(c);
      values.push_back(v);
    }
    start.push_back(columns.size());
  }
};

struct SurfaceEmbedding::Rows {
  std::vector<std::uint32_t> piece;
  std::vector<float> widening;
  std::vector<bool> outside;
  std::vector<std::vector<std::pair<std::uint32_t, double>>> rows;
};

/// Merges samples closer than a quarter to a half of their elements' size (cells of 2^L / 2
/// for the level L = floor(log2 scale), per piece): mean position, mean value (an affine field
/// stays exact), largest support. A surface of far more vertices than the mesh's elements
/// otherwise brings as many samples into every point's fit. Members are summed in order of
/// position, so the result does not depend on element numbering.
SurfaceEmbedding::Samples SurfaceEmbedding::clustered(Samples&& raw) {
  struct Key {
    int level;
    std::uint32_t piece;
    std::int64_t i, j, k;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const {
      std::uint64_t h = 1469598103934665603ull;
      for (std::uint64_t v : {static_cast<std::uint64_t>(key.level), std::uint64_t(key.piece),
                              static_cast<std::uint64_t>(key.i), static_cast<std::uint64_t>(key.j),
                              static_cast<std::uint64_t>(key.k)})
        h = (h ^ v) * 1099511628211ull;
      return static_cast<std::size_t>(h);
    }
  };
  const std::size_t count = raw.positions.size();
  std::vector<std::uint32_t> order(count);
  for (std::size_t q = 0; q < count; ++q) order[q] = static_cast<std::uint32_t>(q);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Vec3 &x = raw.positions[a], &y = raw.positions[b];
    return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3) ||
           (x == y && raw.piece[a] < raw.piece[b]);
  });
  std::unordered_map<Key, std::uint32_t, KeyHash> clusterOf;
  std::vector<std::vector<std::uint32_t>> members;
  for (std::uint32_t q : order) {
    // radius = support * scale; the level of the scale itself.
    const double scale = raw.radius[q];
    const int level = static_cast<int>(std::floor(std::log2(scale)));
    const double cell = std::ldexp(1.0, level) / 4.0;  // radius / 4..8: scale / 2..4 at support 2
    const Vec3& x = raw.positions[q];
    const Key key{level, raw.piece[q], static_cast<std::int64_t>(std::floor(x.x() / cell)),
                  static_cast<std::int64_t>(std::floor(x.y() / cell)),
                  static_cast<std::int64_t>(std::floor(x.z() / cell))};
    const auto [it, added] = clusterOf.emplace(key, static_cast<std::uint32_t>(members.size()));
    if (added) members.emplace_back();
    members[it->second].push_back(q);
  }
  SurfaceEmbedding::Samples out;
  out.numPieces = raw.numPieces;
  out.elementPiece = std::move(raw.elementPiece);
  out.boxes = std::move(raw.boxes);
  out.largestRadius = raw.largestRadius;
  std::vector<std::pair<std::uint32_t, double>> row;
  for (const auto& group : members) {
    Vec3 x = Vec3::Zero();
    double radius = 0.0;
    const double w = 1.0 / static_cast<double>(group.size());
    row.clear();
    for (std::uint32_t q : group) {
      x += raw.positions[q];
      radius = std::max(radius, raw.radius[q]);
      for (std::size_t r = raw.start[q]; r < raw.start[q + 1]; ++r)
        row.emplace_back(raw.columns[r], w * raw.values[r]);
    }
    out.positions.push_back(group.size() == 1 ? raw.positions[group.front()] : Vec3(x * w));
    out.radius.push_back(radius);
    out.piece.push_back(raw.piece[group.front()]);
    out.addRow(row);
  }
  return out;
}

SurfaceEmbedding::Samples SurfaceEmbedding::makeSamples(const PolyMesh& mesh,
                                                        const DgBasis& basis) const {
  Samples s;
  const std::size_t ne = mesh.numElements();
  const int n = basis.size();
  // Pieces: elements joined through interior faces; a cut leaves its two sides apart.
  UnionFind groups(ne);
  for (const Face& f : mesh.faces())
    if (f.front.valid() && f.back.valid()) groups.unite(f.front.value, f.back.value);
  s.elementPiece.resize(ne);
  {
    std::unordered_map<std::uint32_t, std::uint32_t> label;
    for (std::size_t e = 0; e < ne; ++e) {
      const auto root = groups.find(static_cast<std::uint32_t>(e));
      const auto [it, added] = label.emplace(root, static_cast<std::uint32_t>(label.size()));
      s.elementPiece[e] = it->second;
    }
    s.numPieces = label.size();
  }
  std::vector<double> phi(static_cast<std::size_t>(n));
  std::vector<std::pair<std::uint32_t, double>> row;
  auto addValues = [&](ElementId e, const Vec3& x, double w) {
    basis.values(e, x, phi);
    for (int i = 0; i < n; ++i)
      row.emplace_back(static_cast<std::uint32_t>(e.index() * static_cast<std::size_t>(n) + i),
                       w * phi[static_cast<std::size_t>(i)]);
  };
  auto addSample = [&](const Vec3& x, std::uint32_t piece, double scale) {
    s.positions.push_back(x);
    s.piece.push_back(piece);
    s.radius.push_back(options_.support * scale);
    s.largestRadius = std::max(s.largestRadius, s.radius.back());
    s.addRow(row);
    row.clear();
  };

  // Vertex samples, one per (vertex, piece): eq. (17) over the piece's elements.
  std::unordered_map<std::uint64_t, std::uint32_t>& vertexSample = s.vertexSample;
  std::vector<std::vector<std::uint32_t>> sampleElements;
  s.boxes.resize(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    s.boxes[e] = elementBounds(mesh, ElementId(e));
    for (VertexId v : elementVertices(mesh, ElementId(e))) {
      const std::uint64_t key = (static_cast<std::uint64_t>(v.value) << 32) | s.elementPiece[e];
      const auto [it, added] =
          vertexSample.emplace(key, static_cast<std::uint32_t>(sampleElements.size()));
      if (added) sampleElements.emplace_back();
      sampleElements[it->second].push_back(static_cast<std::uint32_t>(e));
      s.elementSamples.push_back(it->second);
    }
    s.elementSampleStart.push_back(s.elementSamples.size());
  }
  std::vector<Vec3> vertexOf(sampleElements.size());
  for (const auto& [key, id] : vertexSample) vertexOf[id] = mesh.position(VertexId(key >> 32));
  for (std::size_t k = 0; k < sampleElements.size(); ++k) {
    const auto& elements = sampleElements[k];
    double scale = 0.0;
    for (std::uint32_t e : elements) {
      addValues(ElementId(e), vertexOf[k], 1.0 / static_cast<double>(elements.size()));
      scale = std::max(scale, basis.scale(ElementId(e)));
    }
    addSample(vertexOf[k], s.elementPiece[elements.front()], scale);
  }
  // Degree 2 and 3: face and element centres follow the higher-order field.
  if (basis.degree() >= 2) {
    for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
      const Face& face = mesh.face(FaceId(f));
      Vec3 c = Vec3::Zero();
      for (VertexId v : face.vertices) c += mesh.position(v);
      c /= static_cast<double>(face.vertices.size());
      const double w = face.back.valid() ? 0.5 : 1.0;
      addValues(face.front, c, w);
      double scale = basis.scale(face.front);
      if (face.back.valid()) {
        addValues(face.back, c, w);
        scale = std::max(scale, basis.scale(face.back));
      }
      addSample(c, s.elementPiece[face.front.index()], scale);
    }
    for (std::size_t e = 0; e < ne; ++e) {
      const ElementId id(e);
      addValues(id, basis.centre(id), 1.0);
      addSample(basis.centre(id), s.elementPiece[e], basis.scale(id));
    }
  }

  if (options_.method == EmbeddingMethod::Mls) s = clustered(std::move(s));

  Box3 all;
  for (const Box3& b : s.boxes) all.extend(b);
  for (const Vec3& x : s.positions) all.extend(x);
  double meanSide = 0.0;
  for (const Box3& b : s.boxes) meanSide += b.sizes().maxCoeff();
  meanSide = ne > 0 ? meanSide / static_cast<double>(ne) : 1.0;
  if (!(meanSide > 0.0)) meanSide = 1.0;
  s.elementGrid = HashGrid(all, meanSide);
  for (std::size_t e = 0; e < ne; ++e)
    s.elementGrid.insert(s.boxes[e], static_cast<std::uint32_t>(e));
  s.sampleGrid = HashGrid(all, s.largestRadius > 0.0 ? s.largestRadius : meanSide);
  for (std::size_t k = 0; k < s.positions.size(); ++k)
    s.sampleGrid.insert(s.positions[k], static_cast<std::uint32_t>(k));
  return s;
}

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

}  // namespace

SurfaceEmbedding::Rows SurfaceEmbedding::computeRows(const PolyMesh& mesh, const Samples& s,
                                                     std::span<const std::uint32_t> which) {
  const std::size_t count = which.size();
  Rows r;
  r.piece.assign(count, 0);
  r.widening.assign(count, 1.0f);
  r.outside.assign(count, false);
  r.rows.resize(count);
  const bool elementLinear = options_.method == EmbeddingMethod::ElementLinear;

  // Location: the elements whose box holds the point; a geometric test only where they
  // disagree on what matters (the piece; for ElementLinear the element).
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
  {
    std::vector<char> needed(mesh.numFaces(), 0);
    bool any = false;
    for (const auto& list : ambiguous)
      for (std::uint32_t e : list) {
        for (const FaceUse& use : mesh.element(ElementId(e)).faces) needed[use.face.index()] = 1;
        any = true;
      }
    if (any) {
      std::vector<std::vector<std::array<VertexId, 3>>> triangles(mesh.numFaces());
      tbb::parallel_for(std::size_t(0), mesh.numFaces(), [&](std::size_t f) {
        if (needed[f]) triangles[f] = triangulateFace(mesh, FaceId(f));
      });
      tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
        if (ambiguous[k].empty()) return;
        double best = std::numeric_limits<double>::infinity();
        for (std::uint32_t e : ambiguous[k]) {  // ascending: ties go to the lowest element
          const double d = elementDistance(mesh, ElementId(e), points_[which[k]], triangles);
          if (d < best) best = d, element[k] = e;
        }
      });
    }
  }

  tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
    const Vec3& x = points_[which[k]];
    const std::uint32_t piece = s.elementPiece[element[k]];
    r.piece[k] = piece;
    std::vector<std::uint32_t> chosen;
    std::vector<double> theta;
    double widening = 1.0;
    auto gather = [&](int attempt) {
      chosen.clear();
      theta.clear();
      if (elementLinear) {
        for (std::size_t q = s.elementSampleStart[element[k]];
             q < s.elementSampleStart[element[k] + 1]; ++q) {
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
    std::vector<std::pair<std::uint32_t, double>>& row = r.rows[k];
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
      compress(row);
      break;
    }
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
                      for (std::size_t p = range.begin(); p != range.end(); ++p) {
                        double sum[3] = {0.0, 0.0, 0.0};
                        for (std::size_t q = weightStart_[p]; q < weightStart_[p + 1]; ++q) {
                          const std::size_t c = weightColumns_[q], e = c / n, i = c % n;
                          const double* u = coefficients.data() + e * 3 * n + i;
                          const double w = weightValues_[q];
                          sum[0] += w * u[0];
                          sum[1] += w * u[n];
                          sum[2] += w * u[2 * n];
                        }
                        out.row(static_cast<Eigen::Index>(p)) << sum[0], sum[1], sum[2];
                      }
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
    compress(row);
  });
  weightStart_.assign(1, 0);
  weightColumns_.clear();
  weightValues_.clear();
  for (const auto& row : rows) {
    for (const auto& [c, v] : row) {
      weightColumns_.push_back(c);
      weightValues_.push_back(v);
    }
    weightStart_.push_back(weightColumns_.size());
  }
}

SparseRow SurfaceEmbedding::weightRow(std::size_t p) const {
  const std::size_t b = weightStart_[p], e = weightStart_[p + 1];
  return {{weightColumns_.data() + b, e - b}, {weightValues_.data() + b, e - b}};
}

Eigen::SparseMatrix<double, Eigen::RowMajor, int> SurfaceEmbedding::weights() const {
  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(weightValues_.size());
  for (std::size_t p = 0; p < numPoints(); ++p)
    for (std::size_t q = weightStart_[p]; q < weightStart_[p + 1]; ++q)
      triplets.emplace_back(static_cast<int>(p), static_cast<int>(weightColumns_[q]),
                            weightValues_[q]);
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> w(
      static_cast<int>(numPoints()), static_cast<int>(numElements_ * static_cast<std::size_t>(n_)));
  w.setFromTriplets(triplets.begin(), triplets.end());
  return w;
}

EmbeddingUpdate SurfaceEmbedding::update(const PolyMesh& mesh, const DgBasis& basis,
                                         std::span<const ElementId> source) {
  const Stopwatch watch;
  if (options_.method == EmbeddingMethod::Nodal)
    throw std::logic_error("SurfaceEmbedding::update: make boundary nodes again after an edit");
  if (basis.size() != n_)
    throw std::invalid_argument("SurfaceEmbedding::update: the basis changed its degree");
  if (source.size() != mesh.numElements())
    throw std::invalid_argument("SurfaceEmbedding::update: one source per new element");
  Samples s = makeSamples(mesh, basis);
  const std::size_t n = static_cast<std::size_t>(n_);

  // Old element -> the new element made from it alone (none if it was split or merged).
  std::unordered_map<std::uint32_t, std::int64_t> renamed;
  for (std::size_t e = 0; e < source.size(); ++e) {
    if (!source[e].valid()) continue;
    const auto [it, added] = renamed.emplace(source[e].value, static_cast<std::int64_t>(e));
    if (!added) it->second = -1;
  }
  // A sample's identity: its position, support and row, bit for bit.
  auto signature = [](const Vec3& x, double radius,
                      const std::vector<std::pair<std::uint32_t, double>>& row) {
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](std::uint64_t v) { h = (h ^ v) * 1099511628211ull; };
    auto bits = [](double d) {
      std::uint64_t b;
      std::memcpy(&b, &d, sizeof b);
      return b;
    };
    for (int k = 0; k < 3; ++k) mix(bits(x[k]));
    mix(bits(radius));
    for (const auto& [c, v] : row) {
      mix(c);
      mix(bits(v));
    }
    return h;
  };
  std::unordered_multimap<std::uint64_t, std::uint32_t> bySignature;
  std::vector<std::pair<std::uint32_t, double>> row;
  auto rowOf = [&](const std::vector<std::size_t>& start, const std::vector<std::uint32_t>& cols,
                   const std::vector<double>& vals, std::size_t q) {
    row.assign({});
    for (std::size_t r = start[q]; r < start[q + 1]; ++r) row.emplace_back(cols[r], vals[r]);
  };
  for (std::size_t q = 0; q < s.positions.size(); ++q) {
    rowOf(s.start, s.columns, s.values, q);
    bySignature.emplace(signature(s.positions[q], s.radius[q], row), static_cast<std::uint32_t>(q));
  }
  std::vector<std::int64_t> matched(samplePositions_.size(), -1);
  std::vector<char> used(s.positions.size(), 0);
  for (std::size_t q = 0; q < samplePositions_.size(); ++q) {
    rowOf(sampleStart_, sampleColumns_, sampleValues_, q);
    bool ok = true;
    for (auto& [c, v] : row) {
      const auto it = renamed.find(static_cast<std::uint32_t>(c / n));
      if (it == renamed.end() || it->second < 0) {
        ok = false;
        break;
      }
      c = static_cast<std::uint32_t>(static_cast<std::size_t>(it->second) * n + c % n);
    }
    if (!ok) continue;
    compress(row);
    const auto range =
        bySignature.equal_range(signature(samplePositions_[q], sampleRadius_[q], row));
    for (auto it = range.first; it != range.second; ++it) {
      const std::uint32_t candidate = it->second;
      if (used[candidate] || s.positions[candidate] != samplePositions_[q]) continue;
      matched[q] = candidate;
      used[candidate] = 1;
      break;
    }
  }
  HashGrid fresh;
  {
    Box3 all;
    for (const Vec3& x : s.positions) all.extend(x);
    for (const Vec3& x : points_) all.extend(x);
    fresh = HashGrid(all, s.largestRadius > 0.0 ? s.largestRadius : 1.0);
  }
  bool anyFresh = false;
  for (std::size_t q = 0; q < s.positions.size(); ++q)
    if (!used[q]) {
      fresh.insert(s.positions[q], static_cast<std::uint32_t>(q));
      anyFresh = true;
    }

  // Points that keep their rows, and the others.
  const std::size_t np = numPoints();
  std::vector<char> keep(np, 0);
  std::vector<std::uint32_t> newPiece(pointPiece_);
  tbb::parallel_for(std::size_t(0), np, [&](std::size_t p) {
    if (options_.method == EmbeddingMethod::ElementLinear) return;
    std::int64_t piece = -1;
    for (std::size_t q = pointStart_[p]; q < pointStart_[p + 1]; ++q) {
      const std::int64_t m = matched[pointColumns_[q]];
      if (m < 0) return;
      const std::int64_t mp = s.piece[static_cast<std::size_t>(m)];
      if (piece >= 0 && mp != piece) return;
      piece = mp;
    }
    if (piece < 0) return;
    const Vec3& x = points_[p];
    const double widening = pointWidening_[p];
    bool reached = false;
    if (anyFresh)
      fresh.visit(x, static_cast<int>(std::ceil(widening - 1e-12)), [&](std::uint32_t q) {
        reached = reached || (x - s.positions[q]).norm() < widening * s.radius[q];
      });
    if (reached) return;
    keep[p] = 1;
    newPiece[p] = static_cast<std::uint32_t>(piece);
  });
  std::vector<std::uint32_t> redo;
  for (std::size_t p = 0; p < np; ++p)
    if (!keep[p]) redo.push_back(static_cast<std::uint32_t>(p));
  Rows rows = computeRows(mesh, s, redo);

  std::vector<std::size_t> start{0};
  std::vector<std::uint32_t> columns;
  std::vector<double> values;
  std::vector<char>& outsideNow = pointOutside_;
  std::size_t next = 0;
  for (std::size_t p = 0; p < np; ++p) {
    if (keep[p]) {
      for (std::size_t q = pointStart_[p]; q < pointStart_[p + 1]; ++q) {
        columns.push_back(static_cast<std::uint32_t>(matched[pointColumns_[q]]));
        values.push_back(pointValues_[q]);
      }
    } else {
      for (const auto& [c, v] : rows.rows[next]) {
        columns.push_back(c);
        values.push_back(v);
      }
      newPiece[p] = rows.piece[next];
      pointWidening_[p] = rows.widening[next];
      outsideNow[p] = rows.outside[next] ? 1 : 0;
      ++next;
    }
    start.push_back(columns.size());
  }
  // Kept rows stay sorted by sample only up to the renumbering: sort them again.
  for (std::size_t p = 0; p < np; ++p) {
    if (!keep[p]) continue;
    std::vector<std::pair<std::uint32_t, double>> r;
    for (std::size_t q = start[p]; q < start[p + 1]; ++q) r.emplace_back(columns[q], values[q]);
    compress(r);
    for (std::size_t q = 0; q < r.size(); ++q) {
      columns[start[p] + q] = r[q].first;
      values[start[p] + q] = r[q].second;
    }
  }
  pointStart_ = std::move(start);
  pointColumns_ = std::move(columns);
  pointValues_ = std::move(values);
  pointPiece_ = std::move(newPiece);
  outside_ = static_cast<std::size_t>(std::count(outsideNow.begin(), outsideNow.end(), 1));
  adopt(std::move(s));

  EmbeddingUpdate report;
  report.recomputed = redo.size();
  report.kept = np - redo.size();
  report.seconds = watch.seconds();
  return report;
}

}  // namespace polydg
