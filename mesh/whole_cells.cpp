#include "mesh/whole_cells.h"

#include <algorithm>
#include <tuple>

#include <tbb/parallel_for.h>

#include "mesh/welded_polygons.h"

namespace polydg {

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
  std::size_t cells = 0;
  for (const std::vector<Box>& list : boxes_)
    for (const Box& box : list) cells += box.cells();
  return cells;
}

std::uint32_t WholeCells::node(const std::array<int, 3>& c) const {
  return table_.empty() ? map_.at(nodeIndex(c)) : table_[nodeIndex(c)];
}

std::vector<std::array<int, 3>> WholeCells::finish(std::uint32_t firstPoint,
                                                   std::vector<Vec3>& points) {
  std::vector<Box> boxes;
  for (std::vector<Box>& list : boxes_) {
    boxes.insert(boxes.end(), list.begin(), list.end());
    std::vector<Box>().swap(list);
  }
  std::sort(boxes.begin(), boxes.end(), [](const Box& a, const Box& b) {
    return std::tie(a.lo[2], a.lo[1], a.lo[0]) < std::tie(b.lo[2], b.lo[1], b.lo[0]);
  });
  std::size_t cells = 0;
  for (const Box& box : boxes) cells += box.cells();
  if (cells == 0) return {};
  const std::size_t nodes = nodeIndex(grid_.cells) + 1;
  if (nodes <= 8 * cells + (std::size_t(1) << 20)) table_.assign(nodes, kNone);
  std::vector<std::array<int, 3>> out;
  out.reserve(cells);
  for (const Box& box : boxes) {
    for (int k = box.lo[2]; k <= box.hi[2]; ++k)
      for (int j = box.lo[1]; j <= box.hi[1]; ++j)
        for (int i = box.lo[0]; i <= box.hi[0]; ++i) {
          const std::size_t n = nodeIndex({i, j, k});
          std::uint32_t& id = table_.empty() ? map_.try_emplace(n, kNone).first->second : table_[n];
          if (id != kNone) continue;
          id = static_cast<std::uint32_t>(firstPoint + points.size());
          points.emplace_back(grid_.plane(0, i), grid_.plane(1, j), grid_.plane(2, k));
        }
    for (int k = box.lo[2]; k < box.hi[2]; ++k)
      for (int j = box.lo[1]; j < box.hi[1]; ++j)
        for (int i = box.lo[0]; i < box.hi[0]; ++i) out.push_back({i, j, k});
  }
  return out;
}

void WholeCells::sides(const std::array<int, 3>& cell, Piece& piece) const {
  std::array<std::uint32_t, 8> corner;  // bit a of the index: +1 along axis a
  for (int b = 0; b < 8; ++b)
    corner[b] = node({cell[0] + (b & 1), cell[1] + (b >> 1 & 1), cell[2] + (b >> 2 & 1)});
  piece.resize(6);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = 1 << (axis + 1) % 3, w = 1 << (axis + 2) % 3, a = side << axis;
      // Counter-clockwise about +axis (u, w, axis are right-handed); the low side faces -axis.
      std::array<std::uint32_t, 4> loop{corner[a], corner[a | u], corner[a | u | w], corner[a | w]};
      if (side == 0) std::reverse(loop.begin(), loop.end());
      PiecePolygon& polygon = piece[2 * axis + side];
      polygon.origin = FaceOrigin::Interior;
      polygon.vertices.assign(loop.begin(), loop.end());
      polygon.loopEnd.assign(1, 4);
    }
}

std::vector<std::uint32_t> WholeCells::pairSides(
    const std::vector<std::pair<std::array<int, 3>, std::uint32_t>>& firstSide,
    std::size_t polygons, const std::function<bool(std::uint32_t, std::uint32_t)>& canPair) const {
  const std::size_t cells =
      std::size_t(grid_.cells[0]) * std::size_t(grid_.cells[1]) * std::size_t(grid_.cells[2]);
  if (firstSide.empty() || cells > 8 * firstSide.size() + (std::size_t(1) << 20)) return {};
  auto index = [&](const std::array<int, 3>& c) {
    return linearIndex(c, grid_.cells[0], grid_.cells[1]);
  };
  std::vector<std::uint32_t> at(cells, kNone);  // each whole cell's entry in firstSide
  tbb::parallel_for(std::size_t(0), firstSide.size(), [&](std::size_t w) {
    at[index(firstSide[w].first)] = static_cast<std::uint32_t>(w);
  });
  std::vector<std::uint32_t> paired(polygons, kNoSide);
  tbb::parallel_for(std::size_t(0), firstSide.size(), [&](std::size_t w) {
    for (int axis = 0; axis < 3; ++axis) {
      std::array<int, 3> next = firstSide[w].first;
      if (++next[axis] == grid_.cells[axis]) continue;
      const std::uint32_t m = at[index(next)];
      if (m == kNone) continue;
      const std::uint32_t p = firstSide[w].second + 2 * axis + 1,
                          q = firstSide[m].second + 2 * axis;
      if (!canPair(p, q)) continue;
      paired[q] = p;  // the next cell's sides come later
      paired[p] = p;
    }
  });
  return paired;
}

}  // namespace polydg
