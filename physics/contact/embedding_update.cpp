// SurfaceEmbedding::update (polydg/physics/contact/embedding.h): after an edit of the mesh, the
// samples made again, the unchanged ones matched to the old, and only the points that an
// edit reached fitted again.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_for.h>

#include "physics/contact/embedding_samples.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// A sample's identity: its position, support and row, bit for bit.
std::uint64_t signature(const Vec3& x, double radius,
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
}

}  // namespace

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
  std::vector<char> used;
  const std::vector<std::int64_t> matched = matchSamples(s, source, used);

  // Points that keep their rows, and the others.
  const std::size_t np = numPoints();
  std::vector<std::uint32_t> newPiece(pointPiece_);
  const std::vector<char> keep = keptPoints(s, matched, used, newPiece);
  std::vector<std::uint32_t> redo;
  for (std::size_t p = 0; p < np; ++p)
    if (!keep[p]) redo.push_back(static_cast<std::uint32_t>(p));
  Rows rows = computeRows(mesh, s, redo);
  mergeRows(keep, matched, rows, std::move(newPiece));
  adopt(std::move(s));

  EmbeddingUpdate report;
  report.recomputed = redo.size();
  report.kept = np - redo.size();
  report.seconds = watch.seconds();
  return report;
}

std::vector<std::int64_t> SurfaceEmbedding::matchSamples(const Samples& s,
                                                         std::span<const ElementId> source,
                                                         std::vector<char>& used) const {
  const std::size_t n = static_cast<std::size_t>(n_);
  // Old element -> the new element made from it alone (none if it was split or merged).
  std::unordered_map<std::uint32_t, std::int64_t> renamed;
  for (std::size_t e = 0; e < source.size(); ++e) {
    if (!source[e].valid()) continue;
    const auto [it, added] = renamed.emplace(source[e].value, static_cast<std::int64_t>(e));
    if (!added) it->second = -1;
  }
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
  used.assign(s.positions.size(), 0);
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
    compressRow(row);
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
  return matched;
}

std::vector<char> SurfaceEmbedding::keptPoints(const Samples& s,
                                               const std::vector<std::int64_t>& matched,
                                               const std::vector<char>& used,
                                               std::vector<std::uint32_t>& newPiece) const {
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

  const std::size_t np = numPoints();
  std::vector<char> keep(np, 0);
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
  return keep;
}

void SurfaceEmbedding::mergeRows(const std::vector<char>& keep,
                                 const std::vector<std::int64_t>& matched, const Rows& rows,
                                 std::vector<std::uint32_t> newPiece) {
  const std::size_t np = numPoints();
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
    compressRow(r);
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
}

}  // namespace polydg
