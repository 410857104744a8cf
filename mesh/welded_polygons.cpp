#include "mesh/welded_polygons.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/concurrent_vector.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <boost/container/small_vector.hpp>

namespace polydg {

std::vector<std::uint32_t> weldTargets(const std::vector<Vec3>& points,
                                       const std::vector<std::uint32_t>& used, double resolution) {
  using Cell = std::array<std::int64_t, 3>;
  // A point's cell by multiplying with the cell's inverse: the cell index only has to grow
  // with the coordinate for every pair within the resolution to be found, each once.
  const double cellSize = kWeldCellResolutions * resolution;
  const double perCell = cellSize > 0 ? 1.0 / cellSize : 0.0;
  auto cellIndex = [&](double x) {
    return static_cast<std::int64_t>(std::floor(x * perCell + 0.5));
  };
  auto cellOf = [&](const Vec3& p) {
    return Cell{cellIndex(p.x()), cellIndex(p.y()), cellIndex(p.z())};
  };
  // Points are sorted by a hash of their cell, not the cell itself (16 bytes to sort instead of
  // 32): cells whose hashes collide only share a run, whose points the distance test filters.
  auto key = [](const Cell& c) {
    std::uint64_t h = 0;
    for (const std::int64_t x : c) h = (h ^ static_cast<std::uint64_t>(x)) * 0x9E3779B97F4A7C15ull;
    return h ^ (h >> 29);
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sorted(used.size());
  tbb::parallel_for(std::size_t(0), used.size(), [&](std::size_t i) {
    sorted[i] = {key(cellOf(points[used[i]])), static_cast<std::uint32_t>(i)};
  });
  tbb::parallel_sort(sorted.begin(), sorted.end());
  // The points in that order: a point and the earlier ones of its run are read in sequence.
  std::vector<Vec3> inOrder(used.size());
  tbb::parallel_for(std::size_t(0), used.size(),
                    [&](std::size_t s) { inOrder[s] = points[used[sorted[s].second]]; });
  tbb::concurrent_vector<std::pair<std::uint32_t, std::uint32_t>> near;  // (later, earlier)
  auto nearPoint = [&](std::uint32_t i, const Vec3& p, std::uint32_t j, const Vec3& q) {
    if ((q - p).cwiseAbs().maxCoeff() <= resolution) near.push_back({i, j});
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t at = r.begin(); at != r.end(); ++at) {
                        const auto [own, i] = sorted[at];
                        const Vec3& p = inOrder[at];
                        // Earlier points of the own cell: just before i in the sorted order.
                        for (std::size_t s = at; s > 0 && sorted[s - 1].first == own; --s)
                          nearPoint(i, p, sorted[s - 1].second, inOrder[s - 1]);
                        const Cell centre = cellOf(p);
                        Cell lo, hi;
                        for (int a = 0; a < 3; ++a) {
                          lo[a] = cellIndex(p[a] - resolution);
                          hi[a] = cellIndex(p[a] + resolution);
                        }
                        if (lo == centre && hi == centre) continue;
                        // The other cells' runs, each once (a run shared by colliding cells
                        // is searched with the first of them).
                        boost::container::small_vector<std::uint64_t, 8> searched{own};
                        for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
                          for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                            for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
                              const std::uint64_t k = key({x, y, z});
                              if (std::find(searched.begin(), searched.end(), k) != searched.end())
                                continue;
                              searched.push_back(k);
                              auto it = std::lower_bound(sorted.begin(), sorted.end(),
                                                         std::make_pair(k, 0u));
                              for (; it != sorted.end() && it->first == k && it->second < i; ++it)
                                nearPoint(i, p, it->second,
                                          inOrder[static_cast<std::size_t>(it - sorted.begin())]);
                            }
                      }
                    });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs(near.begin(), near.end());
  std::sort(pairs.begin(), pairs.end());
  std::vector<std::uint32_t> target(used.size());
  std::iota(target.begin(), target.end(), 0u);
  for (const auto& [later, earlier] : pairs)
    if (target[later] == later && target[earlier] == earlier) target[later] = earlier;
  return target;
}

std::size_t simplifyWalk(std::span<VertexId> walk, std::uint32_t& size) {
  // The walk as a stack: a vertex met again closes the cycle from its first visit, which is
  // popped off; the stack left at the end is the last cycle.
  boost::container::small_vector<VertexId, 16> stack, kept;
  std::size_t cycles = 0;
  auto close = [&](std::size_t from) {
    if (stack.size() - from >= 3) {
      ++cycles;
      kept.assign(stack.begin() + static_cast<std::ptrdiff_t>(from), stack.end());
    }
    stack.resize(from + 1);
  };
  for (std::size_t i = 0; i < size; ++i) {
    const auto seen = std::find(stack.begin(), stack.end(), walk[i]);
    if (seen == stack.end())
      stack.push_back(walk[i]);
    else
      close(static_cast<std::size_t>(seen - stack.begin()));
  }
  if (stack.size() >= 3) {
    ++cycles;
    kept.assign(stack.begin(), stack.end());
  }
  if (cycles == 1) {
    std::copy(kept.begin(), kept.end(), walk.begin());
    size = static_cast<std::uint32_t>(kept.size());
  }
  return cycles;
}

bool WeldedPolygons::isReversed(std::size_t a, std::size_t b) const {
  const auto x = corners(a), y = corners(b);
  if (loopEnds(a).size() != 1 || loopEnds(b).size() != 1) {
    Face face;
    copyTo(a, face);
    return isReverseOf(face, y, loopEnds(b));
  }
  const std::size_t n = x.size();
  if (y.size() != n) return false;
  for (std::size_t j = 0; j < n; ++j) {  // every start (a pinched loop repeats a vertex)
    if (y[j] != x[0]) continue;
    std::size_t i = 1;
    while (i < n && x[i] == y[(j + n - i) % n]) ++i;
    if (i == n) return true;
  }
  return false;
}

std::vector<std::uint32_t> matchSides(const WeldedPolygons& welded,
                                      const std::vector<FaceOrigin>& origin,
                                      const std::vector<char>& kept,
                                      const std::vector<char>& touched,
                                      const std::vector<std::uint64_t>& keys,
                                      std::vector<std::uint32_t> paired) {
  const std::size_t np = kept.size();
  if (paired.empty()) paired.assign(np, kNoSide);
  auto isCap = [&](std::size_t p) { return origin[p] == FaceOrigin::Interior; };
  auto candidate = [&](std::size_t p) {
    return kept[p] && (isCap(p) || touched[p]) && paired[p] == kNoSide;
  };
  // Candidates in polygon order (that is, leaf order), gathered in parallel blocks.
  constexpr std::size_t kBlock = 16384;
  const std::size_t blocks = (np + kBlock - 1) / kBlock;
  std::vector<std::size_t> blockBase(blocks + 1, 0);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    std::size_t count = 0;
    for (std::size_t p = b * kBlock; p < std::min(np, (b + 1) * kBlock); ++p) count += candidate(p);
    blockBase[b + 1] = count;
  });
  for (std::size_t b = 0; b < blocks; ++b) blockBase[b + 1] += blockBase[b];
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sides(blockBase[blocks]);  // (key, p)
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    std::size_t next = blockBase[b];
    for (std::size_t p = b * kBlock; p < std::min(np, (b + 1) * kBlock); ++p)
      if (candidate(p)) sides[next++] = {keys[p], static_cast<std::uint32_t>(p)};
  });
  tbb::parallel_sort(sides.begin(), sides.end());
  std::vector<std::uint32_t> groupStart;
  for (std::size_t c = 0; c < sides.size(); ++c)
    if (c == 0 || sides[c].first != sides[c - 1].first)
      groupStart.push_back(static_cast<std::uint32_t>(c));
  groupStart.push_back(static_cast<std::uint32_t>(sides.size()));
  std::vector<std::uint32_t>& shares = paired;  // the pairs given, then those found
  tbb::parallel_for(std::size_t(0), np, [&](std::size_t p) {
    if (shares[p] == p) shares[p] = kNoSide;
  });
  tbb::parallel_for(std::size_t(0), groupStart.size() - 1, [&](std::size_t g) {
    boost::container::small_vector<std::uint32_t, 4> open;
    for (std::size_t c = groupStart[g]; c < groupStart[g + 1]; ++c) {
      const std::uint32_t p = sides[c].second;
      auto match = std::find_if(open.begin(), open.end(), [&](std::uint32_t o) {
        return isCap(o) == isCap(p) && welded.isReversed(o, p);
      });
      if (match != open.end()) {
        shares[p] = *match;
        open.erase(match);
      } else {
        open.push_back(p);
      }
    }
  });
  return shares;
}

}  // namespace polydg
