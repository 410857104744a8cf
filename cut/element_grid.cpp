#include "cut/element_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace polydg {

namespace {
/// Cell coordinates are packed in 21 bits each (offset so that negative ones fit).
constexpr std::int64_t kBias = 1 << 20;
constexpr std::int64_t kMask = (1 << 21) - 1;
}  // namespace

ElementGrid::ElementGrid(double cellSize) : cellSize_(cellSize) {
  if (!(cellSize > 0.0) || !std::isfinite(cellSize))
    throw std::invalid_argument("ElementGrid: the cell size must be positive and finite");
}

ElementGrid::ElementGrid(const PolyMesh& mesh, double cellSize) : ElementGrid(cellSize) {
  cells_.reserve(mesh.numElements());
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    insert(ElementId(e), elementBounds(mesh, ElementId(e)));
}

std::uint64_t ElementGrid::key(const Cell& c) const {
  std::uint64_t k = 0;
  for (int a = 0; a < 3; ++a) k = k << 21 | static_cast<std::uint64_t>((c[a] + kBias) & kMask);
  return k;
}

ElementGrid::Cell ElementGrid::cellOf(const Vec3& p) const {
  Cell c;
  for (int a = 0; a < 3; ++a) {
    const double x = std::floor(p[a] / cellSize_);
    c[a] = static_cast<std::int64_t>(std::clamp(x, double(-kBias + 1), double(kBias - 2)));
  }
  return c;
}

template <class F>
void ElementGrid::forEachCellOf(const Box3& box, F&& f) {
  const Cell a = cellOf(box.min()), b = cellOf(box.max());
  for (std::int64_t x = a[0]; x <= b[0]; ++x)
    for (std::int64_t y = a[1]; y <= b[1]; ++y)
      for (std::int64_t z = a[2]; z <= b[2]; ++z) f(Cell{x, y, z});
}

void ElementGrid::insert(ElementId e, const Box3& box) {
  erase(e);
  if (e.index() >= boxes_.size()) {
    boxes_.resize(e.index() + 1);
    inGrid_.resize(e.index() + 1, 0);
  }
  boxes_[e.index()] = box;
  inGrid_[e.index()] = 1;
  const bool empty = hi_[0] < lo_[0];
  const Cell a = cellOf(box.min()), b = cellOf(box.max());
  for (int i = 0; i < 3; ++i) {
    lo_[i] = empty ? a[i] : std::min(lo_[i], a[i]);
    hi_[i] = empty ? b[i] : std::max(hi_[i], b[i]);
  }
  forEachCellOf(box, [&](const Cell& c) { cells_[key(c)].push_back(e); });
}

void ElementGrid::erase(ElementId e) {
  if (!contains(e)) return;
  forEachCellOf(boxes_[e.index()], [&](const Cell& c) {
    auto it = cells_.find(key(c));
    if (it == cells_.end()) return;
    auto& list = it->second;
    const auto at = std::find(list.begin(), list.end(), e);
    if (at != list.end()) {
      *at = list.back();
      list.pop_back();
    }
    if (list.empty()) cells_.erase(it);
  });
  inGrid_[e.index()] = 0;
}

void ElementGrid::move(ElementId from, ElementId to) {
  if (contains(to)) throw std::logic_error("ElementGrid::move: the destination has an entry");
  if (!contains(from)) return;
  if (to.index() >= boxes_.size()) {
    boxes_.resize(to.index() + 1);
    inGrid_.resize(to.index() + 1, 0);
  }
  forEachCellOf(boxes_[from.index()], [&](const Cell& c) {
    auto& list = cells_[key(c)];
    std::replace(list.begin(), list.end(), from, to);
  });
  boxes_[to.index()] = boxes_[from.index()];
  inGrid_[to.index()] = 1;
  inGrid_[from.index()] = 0;
}

void ElementGrid::forEachNear(const Vec3& normal, double offset, int side,
                              const std::function<void(ElementId)>& visit) const {
  if (hi_[0] < lo_[0]) return;
  // Walk the columns along the normal's largest component k; in each, the cells the plane
  // passes through (from its heights at the column's corners, one cell of margin for
  // rounding) and, for a side, every occupied cell beyond them on that side.
  int k = 0;
  if (std::abs(normal.y()) > std::abs(normal[k])) k = 1;
  if (std::abs(normal.z()) > std::abs(normal[k])) k = 2;
  const int u = (k + 1) % 3, w = (k + 2) % 3;
  const double h = cellSize_;
  for (std::int64_t i = lo_[u]; i <= hi_[u]; ++i)
    for (std::int64_t j = lo_[w]; j <= hi_[w]; ++j) {
      double zMin = std::numeric_limits<double>::infinity(), zMax = -zMin;
      for (int cu = 0; cu < 2; ++cu)
        for (int cw = 0; cw < 2; ++cw) {
          const double xu = double(i + cu) * h, xw = double(j + cw) * h;
          const double z = (offset - normal[u] * xu - normal[w] * xw) / normal[k];
          zMin = std::min(zMin, z);
          zMax = std::max(zMax, z);
        }
      std::int64_t from = static_cast<std::int64_t>(
          std::clamp(std::floor(zMin / h) - 1, double(lo_[k] - 1), double(hi_[k] + 1)));
      std::int64_t to = static_cast<std::int64_t>(
          std::clamp(std::floor(zMax / h) + 1, double(lo_[k] - 1), double(hi_[k] + 1)));
      // Along +k the plane's plus side (normal . x > offset) is where normal[k] > 0.
      const int upward = normal[k] > 0 ? 1 : -1;
      if (side == upward) to = hi_[k];
      if (side == -upward) from = lo_[k];
      from = std::max(from, lo_[k]);
      to = std::min(to, hi_[k]);
      for (std::int64_t z = from; z <= to; ++z) {
        Cell c;
        c[u] = i;
        c[w] = j;
        c[k] = z;
        const auto it = cells_.find(key(c));
        if (it == cells_.end()) continue;
        for (ElementId e : it->second) visit(e);
      }
    }
}

}  // namespace polydg
