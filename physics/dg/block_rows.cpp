#include "physics/dg/block_rows.h"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "util/simd_clones.h"

namespace polydg {

namespace {

// The row-product kernels are compiled for the CPU's vector instructions (util/simd_clones.h):
// the wide clones take about a tenth off the solve (docs/benchmarks.md).

/// out -= (A x)_e with N functions per component (0: a.n, known at run time only): compile-time
/// sizes for the DG degrees let the short column loops unroll and vectorize (a third of the
/// solve time, docs/benchmarks.md). The row's sums stay in a local array: stored through
/// `out`, which may alias the blocks as far as the compiler knows, they would be written and
/// read again for every column (a quarter of a double-precision product's time).
template <int N, class T>
POLYDG_INLINE void subtractRows(const BlockRows<T>& a, int e, const double* x, double* out) {
  const int n = N > 0 ? N : a.n, bs = 3 * n;
  double sums[N > 0 ? 3 * N : 60];  // 60: 3 numMonomials(3), degree 3 at most
  std::copy(out, out + bs, sums);
  for (int k = a.start[static_cast<std::size_t>(e)]; k < a.start[static_cast<std::size_t>(e) + 1];
       ++k) {
    const std::size_t slot = static_cast<std::size_t>(k);
    const T* block = a.values.data() + a.offset[slot];
    const double* xf = x + static_cast<std::ptrdiff_t>(a.element[slot]) * bs;
    // Column by column: the inner loop has no reduction and vectorizes.
    if (a.diagonal[slot]) {
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < n; ++j) {
          const T* column = block + (d * n + j) * n;
          const double xj = xf[d * n + j];
          double* sd = sums + d * n;
          for (int i = 0; i < n; ++i) sd[i] -= static_cast<double>(column[i]) * xj;
        }
      continue;
    }
    for (int d = 0; d < bs; ++d) {
      const T* column = block + d * bs;
      const double xd = xf[d];
      for (int c = 0; c < bs; ++c) sums[c] -= static_cast<double>(column[c]) * xd;
    }
  }
  std::copy(sums, sums + bs, out);
}

template <class T>
POLYDG_INLINE void subtractRowsOfSize(const BlockRows<T>& a, int e, const double* x, double* out) {
  switch (a.n) {
    case 1: return subtractRows<1>(a, e, x, out);
    case 4: return subtractRows<4>(a, e, x, out);
    case 10: return subtractRows<10>(a, e, x, out);
    case 20: return subtractRows<20>(a, e, x, out);
    default: return subtractRows<0>(a, e, x, out);
  }
}

POLYDG_SIMD_CLONES void subtractRowProductKernel(const BlockRows<float>& a, int e, const double* x,
                                                 double* out) {
  subtractRowsOfSize(a, e, x, out);
}

POLYDG_SIMD_CLONES void subtractRowProductKernel(const BlockRows<double>& a, int e, const double* x,
                                                 double* out) {
  subtractRowsOfSize(a, e, x, out);
}

template <int BS>
POLYDG_INLINE void addDense(int bs, const double* matrix, const double* s, double* x) {
  const int size = BS > 0 ? BS : bs;
  for (int d = 0; d < size; ++d) {
    const double* column = matrix + d * size;
    const double sd = s[d];
    for (int c = 0; c < size; ++c) x[c] += column[c] * sd;
  }
}

}  // namespace

POLYDG_SIMD_CLONES void addDenseProduct(int bs, const double* matrix, const double* s, double* x) {
  switch (bs) {
    case 3: return addDense<3>(bs, matrix, s, x);
    case 12: return addDense<12>(bs, matrix, s, x);
    case 30: return addDense<30>(bs, matrix, s, x);
    case 60: return addDense<60>(bs, matrix, s, x);
    default: return addDense<0>(bs, matrix, s, x);
  }
}

template <class T>
void BlockRows<T>::subtractRowProduct(int e, const double* x, double* out) const {
  subtractRowProductKernel(*this, e, x, out);
}

template <class T>
bool BlockRows<T>::build(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, int functions,
                         double maxRatio) {
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
    // Every block with an entry in any of e's columns: K's own pattern has one in column e bs
    // of each, but added terms need not (contact couples only the normal components).
    for (int c = base; c < base + bs; ++c) {
      int blockEnd = 0;
      for (int k = outer[c]; k < outer[c + 1]; ++k)
        if (inner[k] >= blockEnd) {
          nb.push_back(inner[k] / bs);
          blockEnd = (nb.back() + 1) * bs;
        }
    }
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
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
std::vector<std::size_t> BlockRows<T>::offsetsInOrder(const std::vector<int>& order,
                                                      std::size_t count, std::size_t& total) const {
  std::vector<std::size_t> moved(count);
  std::size_t next = 0;
  for (int e : order)
    for (int k = start[static_cast<std::size_t>(e)]; k < start[static_cast<std::size_t>(e) + 1];
         ++k) {
      moved[static_cast<std::size_t>(k)] = next;
      next += slotSize(static_cast<std::size_t>(k));
    }
  if (count > static_cast<std::size_t>(start.back())) moved.back() = next;  // the values' end
  total = next;
  return moved;
}

template <class T>
void BlockRows<T>::layOutInOrder(const std::vector<int>& order) {
  std::size_t total = 0;
  std::vector<std::size_t> moved = offsetsInOrder(order, offset.size(), total);
  UninitializedVector<T> laidOut(total);
  tbb::parallel_for(std::size_t(0), order.size(), [&](std::size_t i) {
    const auto e = static_cast<std::size_t>(order[i]);
    for (auto k = static_cast<std::size_t>(start[e]); k < static_cast<std::size_t>(start[e + 1]);
         ++k)
      std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(offset[k]), slotSize(k),
                  laidOut.begin() + static_cast<std::ptrdiff_t>(moved[k]));
  });
  values.swap(laidOut);
  offset.swap(moved);
}

template <class T>
const T* BlockRows<T>::diagonalBlock(int e) const {
  std::size_t slot = static_cast<std::size_t>(start[static_cast<std::size_t>(e)]);
  while (element[slot] != e) ++slot;
  return values.data() + offset[slot];
}

template <class T>
Eigen::SparseMatrix<double, Eigen::ColMajor, int> BlockRows<T>::toSparse() const {
  const int ne = elements();
  const Eigen::Index dofs = static_cast<Eigen::Index>(ne) * bs;
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> a(dofs, dofs);
  // Column c of element e's rows is row c (symmetric): per slot, n (component-diagonal) or
  // bs entries.
  std::vector<int> outer(static_cast<std::size_t>(dofs) + 1, 0);
  for (int e = 0; e < ne; ++e) {
    int perColumn = 0;
    for (int k = start[static_cast<std::size_t>(e)]; k < start[static_cast<std::size_t>(e) + 1];
         ++k)
      perColumn += diagonal[static_cast<std::size_t>(k)] ? n : bs;
    for (int c = 0; c < bs; ++c) outer[static_cast<std::size_t>(e * bs + c) + 1] = perColumn;
  }
  for (std::size_t c = 1; c < outer.size(); ++c) outer[c] += outer[c - 1];
  a.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), a.outerIndexPtr());
  int* inner = a.innerIndexPtr();
  double* out = a.valuePtr();
  tbb::parallel_for(0, ne, [&](int e) {
    for (int c = 0; c < bs; ++c) {
      const int d = c / n, cn = c - d * n;
      int pos = outer[static_cast<std::size_t>(e * bs + c)];
      for (int k = start[static_cast<std::size_t>(e)]; k < start[static_cast<std::size_t>(e) + 1];
           ++k) {
        const std::size_t slot = static_cast<std::size_t>(k);
        const int base = element[slot] * bs;
        const T* block = values.data() + offset[slot];
        if (diagonal[slot]) {  // row c, columns d n .. d n + n - 1 of the block
          for (int j = 0; j < n; ++j) {
            inner[pos] = base + d * n + j;
            out[pos++] = static_cast<double>(block[d * n * n + j * n + cn]);
          }
          continue;
        }
        for (int j = 0; j < bs; ++j) {  // row c of the block, column-major
          inner[pos] = base + j;
          out[pos++] = static_cast<double>(block[j * bs + c]);
        }
      }
    }
  });
  return a;
}

template struct BlockRows<float>;
template struct BlockRows<double>;

BlockRows<double> blockRowsLayout(const std::vector<std::vector<std::uint32_t>>& neighbours, int n,
                                  bool componentDiagonal) {
  const int bs = 3 * n;
  const std::size_t ne = neighbours.size();
  BlockRows<double> rows;
  rows.n = n;
  rows.bs = bs;
  rows.start.assign(ne + 1, 0);
  for (std::size_t e = 0; e < ne; ++e)
    rows.start[e + 1] = rows.start[e] + static_cast<int>(neighbours[e].size());
  const std::size_t slots = static_cast<std::size_t>(rows.start.back());
  rows.element.resize(slots);
  rows.diagonal.resize(slots);
  rows.offset.assign(slots + 1, 0);
  std::size_t k = 0;
  for (std::size_t e = 0; e < ne; ++e)
    for (const std::uint32_t f : neighbours[e]) {
      rows.element[k] = static_cast<int>(f);
      rows.diagonal[k] = componentDiagonal && f != e ? 1 : 0;
      rows.offset[k + 1] = rows.offset[k] + rows.slotSize(k);
      ++k;
    }
  rows.values.resize(rows.offset.back());
  return rows;
}

void writeElementRows(BlockRows<double>& rows,
                      const std::vector<std::vector<std::uint32_t>>& neighbours, std::size_t e,
                      const double* self, const double* coupling) {
  const int n = rows.n, bs = rows.bs;
  const std::size_t bb = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  const auto& b = neighbours[e];
  const std::size_t first = static_cast<std::size_t>(rows.start[e]);
  const std::size_t own = static_cast<std::size_t>(
      std::lower_bound(b.begin(), b.end(), static_cast<std::uint32_t>(e)) - b.begin());
  std::copy(self, self + bb, rows.values.data() + rows.offset[first + own]);
  for (std::size_t t = own + 1; t < b.size(); ++t) {
    const std::size_t f = b[t];
    // K_ef(c, j) = block(c, j), the block row-major.
    const double* block = coupling + (t - own - 1) * bb;
    const auto& bf = neighbours[f];
    const std::size_t back =
        static_cast<std::size_t>(rows.start[f]) +
        static_cast<std::size_t>(
            std::lower_bound(bf.begin(), bf.end(), static_cast<std::uint32_t>(e)) - bf.begin());
    double* ef = rows.values.data() + rows.offset[first + t];
    double* fe = rows.values.data() + rows.offset[back];
    if (rows.diagonal[first + t]) {  // component d's n x n blocks, column-major; K_fe = K_ef^T
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < n; ++j)
          for (int c = 0; c < n; ++c) {
            const double v = block[(d * n + c) * bs + d * n + j];
            ef[d * n * n + j * n + c] = v;
            fe[d * n * n + c * n + j] = v;
          }
      continue;
    }
    for (int j = 0; j < bs; ++j)
      for (int c = 0; c < bs; ++c) {
        const double v = block[c * bs + j];
        ef[j * bs + c] = v;
        fe[c * bs + j] = v;
      }
  }
}

}  // namespace polydg
