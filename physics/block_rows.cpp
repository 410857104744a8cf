#include "physics/block_rows.h"

#include <algorithm>

#include <tbb/parallel_for.h>

namespace polydg {

template <class T>
bool BlockRows<T>::build(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a,
                         int functions, double maxRatio) {
  n = functions;
  bs = 3 * n;
  const int ne = static_cast<int>(a.cols() / bs);
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* entries = a.valuePtr();
  // Neighbours of e (sorted, e included) and whether each block couples other components.
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(ne));
  std::vector<std::vector<std::uint8_t>> coupled(static_cast<std::size_t>(ne));
  tbb::parallel_for(0, ne, [&](int e) {
    std::vector<int>& nb = neighbours[static_cast<std::size_t>(e)];
    const int base = e * bs;
    // Column e bs has a nonzero in every neighbour block (BZ's included: component 0).
    int blockEnd = 0;
    for (int k = outer[base]; k < outer[base + 1]; ++k)
      if (inner[k] >= blockEnd) {
        nb.push_back(inner[k] / bs);
        blockEnd = (nb.back() + 1) * bs;
      }
    std::vector<std::uint8_t>& cp = coupled[static_cast<std::size_t>(e)];
    // Every block stored whole (IP's pattern): all slots full, no need to look further.
    const std::size_t stored = static_cast<std::size_t>(outer[base + bs] - outer[base]);
    if (stored == nb.size() * static_cast<std::size_t>(bs * bs)) {
      cp.assign(nb.size(), 1);
      return;
    }
    cp.assign(nb.size(), 0);
    for (int c = 0; c < bs; ++c) {
      const int lo = (c / n) * n, hi = lo + n;  // c's component range in a block
      std::size_t slot = 0;
      for (int k = outer[base + c]; k < outer[base + c + 1]; ++k) {
        while ((nb[slot] + 1) * bs <= inner[k]) ++slot;  // both sorted
        const int local = inner[k] - nb[slot] * bs;
        if (nb[slot] == e || local < lo || local >= hi) cp[slot] = 1;
      }
    }
  });
  start.assign(static_cast<std::size_t>(ne) + 1, 0);
  for (int e = 0; e < ne; ++e)
    start[static_cast<std::size_t>(e) + 1] =
        start[static_cast<std::size_t>(e)] +
        static_cast<int>(neighbours[static_cast<std::size_t>(e)].size());
  const std::size_t slots = static_cast<std::size_t>(start.back());
  element.resize(slots);
  diagonal.resize(slots);
  offset.assign(slots + 1, 0);
  for (int e = 0; e < ne; ++e) {
    const std::size_t first = static_cast<std::size_t>(start[static_cast<std::size_t>(e)]);
    const auto& nb = neighbours[static_cast<std::size_t>(e)];
    const auto& cp = coupled[static_cast<std::size_t>(e)];
    for (std::size_t t = 0; t < nb.size(); ++t) {
      element[first + t] = nb[t];
      diagonal[first + t] = cp[t] ? 0 : 1;
      offset[first + t + 1] =
          offset[first + t] + static_cast<std::size_t>(cp[t] ? bs * bs : 3 * n * n);
    }
  }
  values.clear();
  if (static_cast<double>(offset.back()) > maxRatio * static_cast<double>(a.nonZeros()))
    return false;
  values.resize(offset.back());
  tbb::parallel_for(0, ne, [&](int e) {
    const std::size_t first = static_cast<std::size_t>(start[static_cast<std::size_t>(e)]);
    const std::size_t last = static_cast<std::size_t>(start[static_cast<std::size_t>(e) + 1]);
    std::fill(values.begin() + static_cast<std::ptrdiff_t>(offset[first]),
              values.begin() + static_cast<std::ptrdiff_t>(offset[last]), T(0));
    for (int c = 0; c < bs; ++c) {
      const int d = c / n, cn = c - d * n;  // component of c and its index in it
      std::size_t slot = first;
      for (int k = outer[e * bs + c]; k < outer[e * bs + c + 1]; ++k) {
        while ((element[slot] + 1) * bs <= inner[k]) ++slot;  // both sorted
        // Entry (c, local) of block (e, f) goes to column local, row c.
        const int local = inner[k] - element[slot] * bs;
        const std::size_t index =
            diagonal[slot] ? static_cast<std::size_t>(d * n * n + (local - d * n) * n + cn)
                           : static_cast<std::size_t>(local * bs + c);
        values[offset[slot] + index] = static_cast<T>(entries[k]);
      }
    }
  });
  return true;
}

template <class T>
const T* BlockRows<T>::diagonalBlock(int e) const {
  std::size_t slot = static_cast<std::size_t>(start[static_cast<std::size_t>(e)]);
  while (element[slot] != e) ++slot;
  return values.data() + offset[slot];
}

template struct BlockRows<float>;
template struct BlockRows<double>;

}  // namespace polydg
