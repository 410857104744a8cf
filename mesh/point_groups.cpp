#include "mesh/point_groups.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace polydg {

namespace {

/// A disjoint-set forest over corners that threads may join at once: a root is only ever linked
/// under a smaller root, by compare-and-swap, so that each set's root is its smallest corner and
/// the sets and their roots do not depend on the order of the joins.
class ConcurrentSets {
 public:
  explicit ConcurrentSets(std::vector<std::uint32_t>& parent) : parent_(parent) {}

  std::uint32_t find(std::uint32_t i) const {
    while (true) {
      std::uint32_t p = load(i);
      if (p == i) return i;
      const std::uint32_t g = load(p);
      // Path halving; parents only move towards the root, so a lost race changes nothing.
      if (g != p) at(i).compare_exchange_weak(p, g, std::memory_order_relaxed);
      i = g;
    }
  }

  void unite(std::uint32_t a, std::uint32_t b) const {
    while (true) {
      a = find(a);
      b = find(b);
      if (a == b) return;
      if (a > b) std::swap(a, b);
      std::uint32_t root = b;  // linked only while it is still a root
      if (at(b).compare_exchange_strong(root, a, std::memory_order_relaxed)) return;
    }
  }

  std::atomic_ref<std::uint32_t> at(std::uint32_t i) const {
    return std::atomic_ref<std::uint32_t>(parent_[i]);
  }
  std::uint32_t load(std::uint32_t i) const { return at(i).load(std::memory_order_relaxed); }
  std::uint32_t size() const { return static_cast<std::uint32_t>(parent_.size()); }

 private:
  std::vector<std::uint32_t>& parent_;
};

/// Calls f(b, begin, end) for each block b of kBlock corners (the last may be shorter), the
/// blocks on all cores.
constexpr std::uint32_t kBlock = 1 << 14;
template <class F>
void forEachBlock(std::uint32_t n, F&& f) {
  const std::uint32_t blocks = (n + kBlock - 1) / kBlock;
  tbb::parallel_for(std::uint32_t(0), blocks,
                    [&](std::uint32_t b) { f(b, b * kBlock, std::min(n, (b + 1) * kBlock)); });
}

/// Point p is vertex p, for every entry of `pointVertex`; on all cores.
void numberAsVertices(std::vector<VertexId>& pointVertex) {
  forEachBlock(static_cast<std::uint32_t>(pointVertex.size()),
               [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
                 for (std::uint32_t v = begin; v < end; ++v)
                   pointVertex[v] = VertexId(std::size_t(v));
               });
}

/// Starts `sets` (over its parent array, all of whose entries are set here) with each entry a
/// set of its own, then joins the corners of each vertex v that `take(v)` accepts where an
/// interior face at v joins two elements, corner c at entry `entry(c)`; on all cores.
template <class Take, class Entry>
void joinThroughInteriorFaces(const PolyMesh& mesh, const ElementCorners& corners,
                              const ConcurrentSets& sets, Take&& take, Entry&& entry) {
  forEachBlock(sets.size(), [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i) sets.at(i).store(i, std::memory_order_relaxed);
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      // Both sides' corners, read once for all the face's vertices and kept
                      // while the next faces have the same sides (as a cell's new sides do).
                      ElementCorners::BoxRoom frontRoom, backRoom;
                      ElementId frontOf, backOf;
                      std::span<const VertexId> front, back;
                      for (std::size_t f = r.begin(); f != r.end(); ++f) {
                        const Face& face = mesh.face(FaceId(f));
                        if (!face.front.valid() || !face.back.valid()) continue;
                        if (std::none_of(face.vertices.begin(), face.vertices.end(),
                                         [&](VertexId v) { return take(v.value); }))
                          continue;
                        if (face.front != frontOf) {
                          frontOf = face.front;
                          front = corners.view(frontOf, frontRoom);
                        }
                        if (face.back != backOf) {
                          backOf = face.back;
                          back = corners.view(backOf, backRoom);
                        }
                        for (VertexId v : face.vertices)
                          if (take(v.value))
                            sets.unite(entry(corners.find(face.front, front, v)),
                                       entry(corners.find(face.back, back, v)));
                      }
                    });
}

}  // namespace

ElementCorners::ElementCorners(std::vector<std::uint32_t> begin, std::vector<VertexId> vertices)
    : begin_(std::move(begin)), stored_(std::move(vertices)) {}

ElementCorners::ElementCorners(const PolyMesh& mesh, std::vector<std::uint32_t> count,
                               const std::vector<char>& box)
    : mesh_(&mesh), begin_(std::move(count)) {
  const std::size_t ne = box.size();
  if (begin_.size() != ne + 1 || begin_[0] != 0)
    throw std::logic_error("ElementCorners: " + std::to_string(begin_.size()) + " counts for " +
                           std::to_string(ne) + " elements");
  box_.assign((ne + 63) / 64, 0);
  boxesBefore_.assign(box_.size(), 0);
  std::size_t boxes = 0;
  for (std::size_t w = 0; w < box_.size(); ++w) {
    boxesBefore_[w] = static_cast<std::uint32_t>(boxes);
    for (std::size_t e = 64 * w; e < std::min(ne, 64 * w + 64); ++e)
      if (box[e]) {
        if (begin_[e + 1] != kBoxCorners)
          throw std::logic_error("ElementCorners: a box with " + std::to_string(begin_[e + 1]) +
                                 " corners");
        box_[w] |= std::uint64_t(1) << (e % 64);
        ++boxes;
      }
  }
  // Counts to running ends, in place: begin_[e] is then element e's first corner.
  std::uint64_t total = 0;
  for (std::uint32_t& c : begin_) {
    total += c;
    if (total > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("writeVtu: the cells have more than 2^32 - 1 corners in all");
    c = static_cast<std::uint32_t>(total);
  }
  stored_.resize(total - kBoxCorners * boxes);
}

bool ElementCorners::hasBoxSides(const PolyMesh& mesh, ElementId e) {
  constexpr std::size_t kSides = 6, kSideCorners = 4;
  const FaceList& faces = mesh.element(e).faces;
  if (faces.size() != kSides) return false;
  std::array<VertexId, kBoxCorners> corner;
  std::size_t known = 0;  // the first two sides' corners so far
  for (std::size_t s = 0; s < kSides; ++s) {
    const Face& side = mesh.face(faces[s].face);
    if (side.numLoops() != 1 || side.vertices.size() != kSideCorners) return false;
    for (const VertexId v : side.vertices) {
      const bool seen =
          std::find(corner.begin(), corner.begin() + known, v) != corner.begin() + known;
      if (s >= 2 && !seen) return false;  // a ninth corner
      if (s >= 2) continue;
      if (seen) return false;  // a corner twice in the first two sides
      corner[known++] = v;
    }
  }
  return true;
}

std::size_t ElementCorners::elementOf(std::uint32_t i) const {
  return static_cast<std::size_t>(std::upper_bound(begin_.begin(), begin_.end(), i) -
                                  begin_.begin()) -
         1;
}

// The forest over all corners would be the largest array while a mesh of millions of elements
// is written (53 MB for the bunny at 200 cells).
bool detail::anyVertexSplits(const PolyMesh& mesh, const ElementCorners& corners,
                             std::uint32_t rangeCorners) {
  const auto nc = static_cast<std::uint32_t>(corners.size());
  const std::size_t nv = mesh.numVertices();
  const std::size_t ranges = std::max<std::size_t>(1, (nc + rangeCorners - 1) / rangeCorners);
  const std::uint32_t words = (nc + 63) / 64;
  std::vector<std::uint64_t> in(words);          // corner i is in the range: bit i % 64
  std::vector<std::uint32_t> before(words + 1);  // corners of the range before word w
  // Range r holds the vertices first[r] .. first[r + 1] - 1.
  std::vector<std::uint32_t> first(ranges + 1);
  for (std::size_t r = 0; r <= ranges; ++r) first[r] = static_cast<std::uint32_t>(nv * r / ranges);
  // In one pass: the vertices that have a corner, a bit each, and the corners of each range
  // (room for the largest range's forest is made once).
  std::vector<std::uint64_t> hasCorner((nv + 63) / 64, 0);
  std::vector<std::atomic<std::size_t>> cornersIn(ranges);
  forEachBlock(nc, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
    std::vector<std::size_t> own(ranges, 0);
    corners.forEachIn(begin, end, [&](std::uint32_t, VertexId v) {
      std::atomic_ref<std::uint64_t>(hasCorner[v.index() / 64])
          .fetch_or(std::uint64_t(1) << (v.index() % 64), std::memory_order_relaxed);
      ++own[std::upper_bound(first.begin() + 1, first.end() - 1, v.value) - first.begin() - 1];
    });
    for (std::size_t r = 0; r < ranges; ++r) cornersIn[r] += own[r];
  });
  std::size_t withCorners = 0;
  for (const std::uint64_t word : hasCorner) withCorners += std::popcount(word);
  std::size_t largest = 0;
  for (const std::atomic<std::size_t>& n : cornersIn) largest = std::max(largest, n.load());
  std::vector<std::uint32_t> slot;
  slot.reserve(largest);
  std::size_t groups = 0;
  for (std::size_t r = 0; r < ranges; ++r) {
    auto inRange = [&](std::uint32_t v) { return v >= first[r] && v < first[r + 1]; };
    forEachBlock(words, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
      std::fill(in.begin() + begin, in.begin() + end, 0);
      corners.forEachIn(begin * 64, std::min(nc, end * 64), [&](std::uint32_t i, VertexId v) {
        in[i / 64] |= std::uint64_t(inRange(v.value)) << (i % 64);
      });
      for (std::uint32_t w = begin; w < end; ++w)
        before[w + 1] = static_cast<std::uint32_t>(std::popcount(in[w]));
    });
    before[0] = 0;
    for (std::uint32_t w = 0; w < words; ++w) before[w + 1] += before[w];
    auto rank = [&](std::uint32_t i) {
      const std::uint64_t lower = in[i / 64] & ((std::uint64_t(1) << (i % 64)) - 1);
      return before[i / 64] + static_cast<std::uint32_t>(std::popcount(lower));
    };
    const std::uint32_t n = before[words];
    slot.resize(n);
    const ConcurrentSets sets(slot);
    joinThroughInteriorFaces(mesh, corners, sets, inRange, rank);
    std::atomic<std::size_t> roots{0};
    forEachBlock(n, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
      std::size_t own = 0;
      for (std::uint32_t i = begin; i < end; ++i) own += sets.load(i) == i;
      roots += own;
    });
    groups += roots;
  }
  return groups != withCorners;
}

PointGroups groupPoints(const PolyMesh& mesh, const ElementCorners& corners,
                        std::uint32_t rangeCorners) {
  const std::size_t numCorners = corners.size();
  const std::size_t nv = mesh.numVertices();
  // Corners and points are numbered in 31 bits: the top bit marks a root whose point is known.
  constexpr std::uint32_t kKnown = 0x80000000u;
  if (numCorners + nv >= kKnown)
    throw std::length_error("groupPoints: more than 2^31 corners and vertices");
  // With more corners than a range takes, whether any vertex splits is found range by range
  // first: when none does (a mesh fresh from slicing), the points are the vertices.
  if (numCorners > rangeCorners && !detail::anyVertexSplits(mesh, corners, rangeCorners)) {
    PointGroups out;
    out.pointVertex.resize(nv);
    numberAsVertices(out.pointVertex);
    return out;
  }
  const auto nc = static_cast<std::uint32_t>(numCorners);

  // The corners of each vertex joined through the interior faces that contain it, on all cores.
  // A group's corners share one vertex, and its root is its first corner.
  std::vector<std::uint32_t> slot(numCorners);
  const ConcurrentSets sets(slot);
  joinThroughInteriorFaces(
      mesh, corners, sets, [](std::uint32_t) { return true; },
      [](std::uint32_t corner) { return corner; });
  forEachBlock(nc, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i)
      sets.at(i).store(sets.find(i), std::memory_order_relaxed);
  });

  // Each vertex's first corner (in pointVertex's room, which holds the vertices themselves
  // afterwards): the group rooted there is the vertex's own point; every other root is a new
  // point after all vertices, numbered in corner order.
  PointGroups out;
  out.pointVertex.assign(nv, VertexId(std::size_t(nc)));
  auto firstOf = [&](std::uint32_t v) {
    return std::atomic_ref<std::uint32_t>(out.pointVertex[v].value);
  };
  forEachBlock(nc, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
    corners.forEachIn(begin, end, [&](std::uint32_t i, VertexId v) {
      std::atomic_ref<std::uint32_t> first = firstOf(v.value);
      std::uint32_t seen = first.load(std::memory_order_relaxed);
      while (i < seen && !first.compare_exchange_weak(seen, i, std::memory_order_relaxed)) {
      }
    });
  });
  auto isNewPoint = [&](std::uint32_t i, VertexId v) {
    return slot[i] == i && firstOf(v.value).load(std::memory_order_relaxed) != i;
  };
  const std::uint32_t blocks = (nc + kBlock - 1) / kBlock;
  std::vector<std::uint32_t> newBefore(std::size_t(blocks) + 1, 0);  // per block, then summed
  forEachBlock(nc, [&](std::uint32_t b, std::uint32_t begin, std::uint32_t end) {
    corners.forEachIn(begin, end,
                      [&](std::uint32_t i, VertexId v) { newBefore[b + 1] += isNewPoint(i, v); });
  });
  for (std::uint32_t b = 0; b < blocks; ++b) newBefore[b + 1] += newBefore[b];
  const std::uint32_t added = newBefore[blocks];
  std::vector<VertexId> newPoints(added);
  forEachBlock(nc, [&](std::uint32_t b, std::uint32_t begin, std::uint32_t end) {
    std::uint32_t next = newBefore[b];
    corners.forEachIn(begin, end, [&](std::uint32_t i, VertexId v) {
      if (slot[i] != i) return;
      std::uint32_t point = v.value;
      if (isNewPoint(i, v)) {
        newPoints[next] = v;
        point = static_cast<std::uint32_t>(nv + next++);
      }
      sets.at(i).store(point | kKnown, std::memory_order_relaxed);
    });
  });
  numberAsVertices(out.pointVertex);
  // Without a second point for any vertex, every corner's point is its vertex: no list needed.
  if (added == 0) return out;
  out.pointVertex.insert(out.pointVertex.end(), newPoints.begin(), newPoints.end());
  // Every corner takes its root's point. A root's slot holds its point marked, another corner's
  // its root's number (unmarked), which only that corner's thread replaces.
  forEachBlock(nc, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t own = sets.load(i);
      const std::uint32_t point = own & kKnown ? own : sets.load(own);
      sets.at(i).store(point & ~kKnown, std::memory_order_relaxed);
    }
  });
  out.cornerPoint = std::move(slot);
  return out;
}

}  // namespace polydg
