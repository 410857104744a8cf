// The grid of slicing (declared in polydg/mesh/slice.h).
#include "polydg/mesh/slice.h"

#include <cmath>
#include <stdexcept>

namespace polydg {

Grid Grid::covering(const Box3& bounds, double cellSize) {
  if (!(cellSize > 0.0) || !std::isfinite(cellSize))
    throw std::invalid_argument("grid cell size must be positive and finite");
  if (bounds.isEmpty()) throw std::invalid_argument("cannot build a grid around an empty box");
  Grid g;
  g.cellSize = cellSize;
  const Vec3 extent = bounds.diagonal();
  const Vec3 centre = 0.5 * (bounds.min() + bounds.max());
  for (int a = 0; a < 3; ++a) {
    const double n = std::max(1.0, std::ceil(extent[a] / cellSize));
    if (n > 1 << 20) throw std::invalid_argument("grid would have more than 2^20 cells per axis");
    g.cells[a] = static_cast<int>(n);
  }
  g.centre = centre;
  return g;
}

Grid Grid::withCellsAlongLongest(const Box3& bounds, int cellsAlongLongest) {
  if (cellsAlongLongest < 1) throw std::invalid_argument("need at least one cell");
  return covering(bounds, bounds.diagonal().maxCoeff() / cellsAlongLongest);
}

}  // namespace polydg
