// The p-multigrid's coarse matrices (physics/solvers/multigrid_coarsening.h).
#include "physics/solvers/multigrid_coarsening.h"

#include <algorithm>
#include <atomic>
#include <cstddef>

#include <tbb/parallel_for.h>

namespace polydg::multigrid {

SpMat restrictMatrix(const SpMat& fine, int n, int nc) {
  const int bs = 3 * n, bsc = 3 * nc;
  const Eigen::Index ne = fine.cols() / bs;
  const Eigen::Index ncols = ne * bsc;
  // Local fine index -> local coarse index (or -1), and coarse -> fine: no integer division
  // per nonzero (the walks below were division-bound).
  std::vector<int> toCoarse(static_cast<std::size_t>(bs), -1),
      toFine(static_cast<std::size_t>(bsc));
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < nc; ++i) {
      toCoarse[static_cast<std::size_t>(d * n + i)] = d * nc + i;
      toFine[static_cast<std::size_t>(d * nc + i)] = d * n + i;
    }
  const int* outer = fine.outerIndexPtr();
  const int* inner = fine.innerIndexPtr();
  const double* values = fine.valuePtr();
  // Calls visit(coarse row, fine position) for the kept entries of coarse column (e, local).
  auto walk = [&](Eigen::Index e, int local, auto&& visit) {
    const Eigen::Index fc = e * bs + toFine[static_cast<std::size_t>(local)];
    int blockBase = -bs, blockEnd = 0, coarseBase = 0;
    for (int k = outer[fc]; k < outer[fc + 1]; ++k) {
      const int row = inner[k];
      if (row >= blockEnd) {  // a new element block: rows are sorted
        const int f = row / bs;
        blockBase = f * bs;
        blockEnd = blockBase + bs;
        coarseBase = f * bsc;
      }
      const int c = toCoarse[static_cast<std::size_t>(row - blockBase)];
      if (c >= 0) visit(coarseBase + c, k);
    }
  };
  std::vector<int> counts(static_cast<std::size_t>(ncols) + 1, 0);
  tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
    for (int local = 0; local < bsc; ++local) {
      int count = 0;
      walk(e, local, [&](int, int) { ++count; });
      counts[static_cast<std::size_t>(e * bsc + local) + 1] = count;
    }
  });
  for (std::size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
  SpMat coarse(ncols, ncols);
  coarse.resizeNonZeros(counts.back());
  std::copy(counts.begin(), counts.end(), coarse.outerIndexPtr());
  int* cinner = coarse.innerIndexPtr();
  double* cvalues = coarse.valuePtr();
  tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
    for (int local = 0; local < bsc; ++local) {
      int pos = counts[static_cast<std::size_t>(e * bsc + local)];
      // Fine rows are sorted and the renumbering is monotone: coarse rows come out sorted.
      walk(e, local, [&](int row, int k) {
        cinner[pos] = row;
        cvalues[pos++] = values[k];
      });
    }
  });
  return coarse;
}

SpMat restrictBlocks(const BlockRows<double>& fine, int nc) {
  BlockRows<double> coarse;
  const int n = fine.n, bs = fine.bs, bsc = 3 * nc;
  coarse.n = nc;
  coarse.bs = bsc;
  coarse.start = fine.start;
  coarse.element = fine.element;
  coarse.diagonal = fine.diagonal;
  coarse.offset.assign(fine.offset.size(), 0);
  for (std::size_t k = 0; k + 1 < fine.offset.size(); ++k)
    coarse.offset[k + 1] =
        coarse.offset[k] + static_cast<std::size_t>(fine.diagonal[k] ? 3 * nc * nc : bsc * bsc);
  coarse.values.resize(coarse.offset.back());
  tbb::parallel_for(std::size_t(0), fine.element.size(), [&](std::size_t k) {
    const double* from = fine.values.data() + fine.offset[k];
    double* to = coarse.values.data() + coarse.offset[k];
    if (fine.diagonal[k]) {
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < nc; ++j)
          for (int i = 0; i < nc; ++i) to[d * nc * nc + j * nc + i] = from[d * n * n + j * n + i];
      return;
    }
    for (int dj = 0; dj < 3; ++dj)
      for (int j = 0; j < nc; ++j)
        for (int di = 0; di < 3; ++di)
          for (int i = 0; i < nc; ++i)
            to[(dj * nc + j) * bsc + di * nc + i] = from[(dj * n + j) * bs + di * n + i];
  });
  return coarse.toSparse();
}

bool splitComponents(const SpMat& a, std::vector<SpMat>& parts) {
  parts.clear();
  const Eigen::Index ne = a.cols() / 3;
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  std::atomic<bool> uncoupled{true}, equal{true};
  tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
    const int first = outer[3 * e], count = outer[3 * e + 1] - first;
    for (int d = 0; d < 3; ++d) {
      const int start = outer[3 * e + d], end = outer[3 * e + d + 1];
      for (int k = start; k < end; ++k)
        if (inner[k] % 3 != d) {
          uncoupled = false;
          return;
        }
      if (!equal) continue;
      bool same = end - start == count;
      for (int k = 0; same && k < count; ++k)
        same = inner[start + k] == inner[first + k] + d && values[start + k] == values[first + k];
      if (!same) equal = false;
    }
  });
  if (!uncoupled) return false;
  parts.resize(equal ? 1 : 3);
  for (std::size_t d = 0; d < parts.size(); ++d) {
    SpMat& part = parts[d];
    part.resize(ne, ne);
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<std::size_t>(a.nonZeros() / 3));
    for (Eigen::Index e = 0; e < ne; ++e)
      for (int k = outer[3 * e + static_cast<Eigen::Index>(d)];
           k < outer[3 * e + static_cast<Eigen::Index>(d) + 1]; ++k)
        entries.emplace_back(inner[k] / 3, static_cast<int>(e), values[k]);
    part.setFromTriplets(entries.begin(), entries.end());
  }
  return true;
}

}  // namespace polydg::multigrid
