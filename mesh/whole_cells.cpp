#include "mesh/whole_cells.h"

#include <algorithm>
#include <tuple>

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
  std::sort(boxes.begin(), boxes.end(),
            [](const Box& a, const Box& b) { return cellBefore(a.lo, b.lo); });
  std::size_t cells = 0;
  for (const Box& box : boxes) cells += box.cells();
  finished_ += cells;
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

std::array<std::uint32_t, 4> WholeCells::side(const std::array<int, 3>& cell, int s) const {
  const int axis = s / 2;
  // Corner b of the cell: bit a of b is +1 along axis a.
  auto corner = [&](int b) {
    return node({cell[0] + (b & 1), cell[1] + (b >> 1 & 1), cell[2] + (b >> 2 & 1)});
  };
  const int u = 1 << (axis + 1) % 3, w = 1 << (axis + 2) % 3, a = (s % 2) << axis;
  // Counter-clockwise about +axis (u, w, axis are right-handed); the low side faces -axis.
  std::array<std::uint32_t, 4> loop{corner(a), corner(a | u), corner(a | u | w), corner(a | w)};
  if (s % 2 == 0) std::reverse(loop.begin(), loop.end());
  return loop;
}

void WholeCells::sides(const std::array<int, 3>& cell, Piece& piece, unsigned skip) const {
  piece.clear();
  for (int s = 0; s < 6; ++s) {
    if (skip >> s & 1) continue;
    const std::array<std::uint32_t, 4> loop = side(cell, s);
    PiecePolygon& polygon = piece.emplace_back();
    polygon.origin = FaceOrigin::Interior;
    polygon.vertices.assign(loop.begin(), loop.end());
    polygon.loopEnd.assign(1, 4);
  }
}

}  // namespace polydg
