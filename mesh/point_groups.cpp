#include "mesh/point_groups.h"

#include <atomic>
#include <stdexcept>

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

}  // namespace

PointGroups groupPoints(const PolyMesh& mesh, const ElementCorners& corners) {
  const std::size_t numCorners = corners.vertices.size();
  const std::size_t nv = mesh.numVertices();
  // Corners and points are numbered in 31 bits: the top bit marks a root whose point is known.
  constexpr std::uint32_t kKnown = 0x80000000u;
  if (numCorners + nv >= kKnown)
    throw std::length_error("groupPoints: more than 2^31 corners and vertices");
  const auto nc = static_cast<std::uint32_t>(numCorners);
  auto vertexOf = [&](std::uint32_t corner) { return corners.vertices[corner].value; };

  // The corners of each vertex joined through the interior faces that contain it, on all cores.
  // A group's corners share one vertex, and its root is its first corner.
  std::vector<std::uint32_t> slot(numCorners);
  forEachBlock(nc, [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i) slot[i] = i;
  });
  const ConcurrentSets sets(slot);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f) {
                        const Face& face = mesh.face(FaceId(f));
                        if (!face.front.valid() || !face.back.valid()) continue;
                        for (VertexId v : face.vertices)
                          sets.unite(corners.find(face.front, v), corners.find(face.back, v));
                      }
                    });
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
    for (std::uint32_t i = begin; i < end; ++i) {
      std::atomic_ref<std::uint32_t> first = firstOf(vertexOf(i));
      std::uint32_t seen = first.load(std::memory_order_relaxed);
      while (i < seen && !first.compare_exchange_weak(seen, i, std::memory_order_relaxed)) {
      }
    }
  });
  auto isNewPoint = [&](std::uint32_t i) {
    return slot[i] == i && firstOf(vertexOf(i)).load(std::memory_order_relaxed) != i;
  };
  const std::uint32_t blocks = (nc + kBlock - 1) / kBlock;
  std::vector<std::uint32_t> newBefore(std::size_t(blocks) + 1, 0);  // per block, then summed
  forEachBlock(nc, [&](std::uint32_t b, std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i) newBefore[b + 1] += isNewPoint(i);
  });
  for (std::uint32_t b = 0; b < blocks; ++b) newBefore[b + 1] += newBefore[b];
  const std::uint32_t added = newBefore[blocks];
  std::vector<VertexId> newPoints(added);
  forEachBlock(nc, [&](std::uint32_t b, std::uint32_t begin, std::uint32_t end) {
    std::uint32_t next = newBefore[b];
    for (std::uint32_t i = begin; i < end; ++i) {
      if (slot[i] != i) continue;
      std::uint32_t point = vertexOf(i);
      if (isNewPoint(i)) {
        newPoints[next] = VertexId(std::size_t(vertexOf(i)));
        point = static_cast<std::uint32_t>(nv + next++);
      }
      sets.at(i).store(point | kKnown, std::memory_order_relaxed);
    }
  });
  forEachBlock(static_cast<std::uint32_t>(nv),
               [&](std::uint32_t, std::uint32_t begin, std::uint32_t end) {
                 for (std::uint32_t v = begin; v < end; ++v)
                   out.pointVertex[v] = VertexId(std::size_t(v));
               });
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
