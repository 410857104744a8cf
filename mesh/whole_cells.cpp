#include "mesh/whole_cells.h"

#include <algorithm>
#include <atomic>
#include <numeric>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "util/resident.h"

namespace polydg {

std::vector<char> mergeWholeFlags(const std::vector<char>& whole,
                                  const std::vector<std::uint32_t>& group, std::size_t elements) {
  if (whole.empty()) return {};
  std::vector<char> merged(elements, 1);
  for (std::size_t e = 0; e < group.size(); ++e)
    if (group[e] != kDroppedElement) merged[group[e]] &= whole[e];
  return merged;
}

bool WholeCells::isWholeBox(const Piece& piece) {
  return piece.size() == 6 && std::all_of(piece.begin(), piece.end(), [](const PiecePolygon& p) {
           return p.origin == FaceOrigin::Interior && p.vertices.size() == 4 && p.numLoops() == 1;
         });
}

std::size_t WholeCells::add(const std::array<int, 3>& lo, const std::array<int, 3>& hi) {
  boxes_.local().push_back({lo, hi});
  return boxes_.local().back().cells();
}

std::size_t WholeCells::count() const {
  std::size_t cells = finished_;
  for (const std::vector<Box>& list : boxes_)
    for (const Box& box : list) cells += box.cells();
  return cells;
}

std::vector<std::array<int, 3>> WholeCells::finish(std::uint32_t firstPoint,
                                                   std::vector<Vec3>& points) {
  std::vector<Box> boxes;
  for (std::vector<Box>& list : boxes_) {
    boxes.insert(boxes.end(), list.begin(), list.end());
    std::vector<Box>().swap(list);
  }
  // Boxes are disjoint, so no two have the same first cell: the order is total.
  tbb::parallel_sort(boxes.begin(), boxes.end(),
                     [](const Box& a, const Box& b) { return cellBefore(a.lo, b.lo); });
  std::vector<std::size_t> cellStart(boxes.size() + 1, 0);
  for (std::size_t b = 0; b < boxes.size(); ++b) cellStart[b + 1] = cellStart[b] + boxes[b].cells();
  const std::size_t cells = cellStart.back();
  finished_ += cells;
  if (cells == 0) return {};
  const std::size_t nodes = nodeIndex(grid_.cells) + 1;
  if (nodes <= 8 * cells + (std::size_t(1) << 20)) {
    numberNodesInParallel(boxes, firstPoint, points);
  } else {
    numberNodesInOrder(boxes, firstPoint, points);
  }
  auto out = residentVector<std::array<int, 3>>(cells);
  tbb::parallel_for(std::size_t(0), boxes.size(), [&](std::size_t b) {
    const Box& box = boxes[b];
    std::size_t c = cellStart[b];
    for (int k = box.lo[2]; k < box.hi[2]; ++k)
      for (int j = box.lo[1]; j < box.hi[1]; ++j)
        for (int i = box.lo[0]; i < box.hi[0]; ++i) out[c++] = {i, j, k};
  });
  return out;
}

void WholeCells::numberNodesInOrder(const std::vector<Box>& boxes, std::uint32_t firstPoint,
                                    std::vector<Vec3>& points) {
  for (const Box& box : boxes)
    forEachNode(box, [&](std::size_t n, int i, int j, int k) {
      std::uint32_t& id = table_.empty() ? map_.try_emplace(n, kNone).first->second : table_[n];
      if (id != kNone) return;
      id = static_cast<std::uint32_t>(firstPoint + points.size());
      points.emplace_back(grid_.plane(0, i), grid_.plane(1, j), grid_.plane(2, k));
    });
}

void WholeCells::numberNodesInParallel(const std::vector<Box>& boxes, std::uint32_t firstPoint,
                                       std::vector<Vec3>& points) {
  // While numbering, a node's slot holds kOwner | the first box (in order) that has it; its
  // number, once given, is below kOwner, so that no box mistakes it for its own mark.
  constexpr std::uint32_t kOwner = 0x80000000u;
  std::size_t visits = 0;
  for (const Box& box : boxes) visits += box.nodes();
  if (boxes.size() >= kOwner - 1 || firstPoint + points.size() + visits >= kOwner) {
    table_.assign(nodeIndex(grid_.cells) + 1, kNone);
    numberNodesInOrder(boxes, firstPoint, points);
    return;
  }
  table_.clear();
  growResident(table_, nodeIndex(grid_.cells) + 1, kNone);
  auto slot = [&](std::size_t n) { return std::atomic_ref<std::uint32_t>(table_[n]); };
  tbb::parallel_for(std::size_t(0), boxes.size(), [&](std::size_t b) {
    const std::uint32_t mark = kOwner | static_cast<std::uint32_t>(b);
    forEachNode(boxes[b], [&](std::size_t n, int, int, int) {
      std::atomic_ref<std::uint32_t> s = slot(n);
      std::uint32_t seen = s.load(std::memory_order_relaxed);
      while (mark < seen && !s.compare_exchange_weak(seen, mark, std::memory_order_relaxed)) {
      }
    });
  });
  // The first box of a node numbers it, as one box after the other would: box b's nodes come
  // after those of the boxes before it, in the order forEachNode visits them.
  std::vector<std::size_t> nodeStart(boxes.size() + 1, 0);
  tbb::parallel_for(std::size_t(0), boxes.size(), [&](std::size_t b) {
    const std::uint32_t mark = kOwner | static_cast<std::uint32_t>(b);
    std::size_t owned = 0;
    forEachNode(boxes[b], [&](std::size_t n, int, int, int) {
      owned += slot(n).load(std::memory_order_relaxed) == mark;
    });
    nodeStart[b + 1] = owned;
  });
  std::inclusive_scan(nodeStart.begin(), nodeStart.end(), nodeStart.begin());
  const std::size_t first = points.size();
  growResident(points, first + nodeStart.back());
  tbb::parallel_for(std::size_t(0), boxes.size(), [&](std::size_t b) {
    const std::uint32_t mark = kOwner | static_cast<std::uint32_t>(b);
    std::size_t p = first + nodeStart[b];
    forEachNode(boxes[b], [&](std::size_t n, int i, int j, int k) {
      std::atomic_ref<std::uint32_t> s = slot(n);
      if (s.load(std::memory_order_relaxed) != mark) return;
      points[p] = Vec3(grid_.plane(0, i), grid_.plane(1, j), grid_.plane(2, k));
      s.store(static_cast<std::uint32_t>(firstPoint + p), std::memory_order_relaxed);
      ++p;
    });
  });
}

void WholeCells::sides(const std::array<int, 3>& cell, Piece& piece, unsigned skip) const {
  piece.clear();
  const std::array<std::uint32_t, 8> corner = corners(cell);
  for (int s = 0; s < 6; ++s) {
    if (skip >> s & 1) continue;
    const std::array<std::uint32_t, 4> loop = sideOf(corner, s);
    PiecePolygon& polygon = piece.emplace_back();
    polygon.origin = FaceOrigin::Interior;
    polygon.vertices.assign(loop.begin(), loop.end());
    polygon.loopEnd.assign(1, 4);
  }
}

}  // namespace polydg
