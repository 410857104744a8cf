// A uniform hash grid of boxes or points: the cells each item overlaps, and the items near a
// point (the surface embedding's point location and sample search).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg {

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

}  // namespace polydg
