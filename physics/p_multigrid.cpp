#include "physics/p_multigrid.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <stdexcept>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "integrate/monomials.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Level-0 unknowns up to which CHOLMOD factorizes it simplicially (see compute()).
constexpr Eigen::Index kSimplicialCoarseLimit = 30000;

/// Largest element block handled (3 numMonomials(3)).
constexpr int kMaxBlock = 60;

/// One degree q: its matrix (the top level borrows K), functions per component and the
/// inverses of its element diagonal blocks (bs x bs each, column-major).
struct Level {
  const SpMat* matrix = nullptr;
  SpMat owned;
  int n = 0, bs = 0;
  std::vector<double> inverses;
  /// The smoother's copy of the matrix in single precision, by element block rows: element
  /// e's blocks are slots blockStart[e] .. blockStart[e + 1] - 1, slot k the block against
  /// element blockElement[k], its values from blockValues[slotOffset[k]]. A slot is either
  /// full (bs x bs, column-major) or, when the block couples equal components only (BZ's
  /// neighbour blocks, and IP's p = 0 level on axis-aligned faces), component-diagonal: its
  /// three n x n diagonal blocks one after the other, each column-major. Half the bytes of the
  /// CSR values (a sixth for component-diagonal blocks) and no index per entry: the smoother
  /// is bound by memory bandwidth. Symmetric like the matrix, so the V-cycle stays symmetric
  /// (it is the V-cycle of the rounded matrix).
  /// Used when it stores at most twice the matrix's nonzeros; otherwise (very sparse blocks)
  /// the smoother reads the CSR matrix.
  bool useBlocks = false;
  std::vector<int> blockStart, blockElement;
  std::vector<std::size_t> slotOffset;
  std::vector<std::uint8_t> slotDiagonal;  ///< 1: component-diagonal slot
  std::vector<float> blockValues;
  // Scratch of apply(): right-hand side, solution and residual of this level.
  mutable Eigen::VectorXd b, x, r;
};

/// The principal submatrix of `fine` (n functions per component) on the DOFs of the first
/// `nc` functions of each component, renumbered (e, d, i) -> e 3 nc + d nc + i.
SpMat restrictMatrix(const SpMat& fine, int n, int nc) {
  const int bs = 3 * n, bsc = 3 * nc;
  const Eigen::Index ne = fine.cols() / bs;
  const Eigen::Index ncols = ne * bsc;
  // Local fine index -> local coarse index (or -1), and coarse -> fine: no integer division
  // per nonzero (the walks below were division-bound).
  std::vector<int> toCoarse(static_cast<std::size_t>(bs), -1), toFine(static_cast<std::size_t>(bsc));
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

/// Fills the single-precision block rows of `level` from its matrix.
void buildBlockRows(Level& level) {
  const SpMat& a = *level.matrix;
  const int bs = level.bs, n = level.n;
  const int ne = static_cast<int>(a.cols() / bs);
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
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
  level.blockStart.assign(static_cast<std::size_t>(ne) + 1, 0);
  for (int e = 0; e < ne; ++e)
    level.blockStart[static_cast<std::size_t>(e) + 1] =
        level.blockStart[static_cast<std::size_t>(e)] +
        static_cast<int>(neighbours[static_cast<std::size_t>(e)].size());
  const std::size_t slots = static_cast<std::size_t>(level.blockStart.back());
  level.blockElement.resize(slots);
  level.slotDiagonal.resize(slots);
  level.slotOffset.assign(slots + 1, 0);
  for (int e = 0; e < ne; ++e) {
    const std::size_t first = static_cast<std::size_t>(level.blockStart[static_cast<std::size_t>(e)]);
    const auto& nb = neighbours[static_cast<std::size_t>(e)];
    const auto& cp = coupled[static_cast<std::size_t>(e)];
    for (std::size_t t = 0; t < nb.size(); ++t) {
      level.blockElement[first + t] = nb[t];
      level.slotDiagonal[first + t] = cp[t] ? 0 : 1;
      level.slotOffset[first + t + 1] =
          level.slotOffset[first + t] +
          static_cast<std::size_t>(cp[t] ? bs * bs : 3 * n * n);
    }
  }
  level.useBlocks = level.slotOffset.back() <= 2 * static_cast<std::size_t>(a.nonZeros());
  if (!level.useBlocks) return;
  level.blockValues.resize(level.slotOffset.back());
  tbb::parallel_for(0, ne, [&](int e) {
    const std::size_t first = static_cast<std::size_t>(level.blockStart[static_cast<std::size_t>(e)]);
    const std::size_t last = static_cast<std::size_t>(level.blockStart[static_cast<std::size_t>(e) + 1]);
    std::fill(level.blockValues.begin() + static_cast<std::ptrdiff_t>(level.slotOffset[first]),
              level.blockValues.begin() + static_cast<std::ptrdiff_t>(level.slotOffset[last]), 0.0f);
    for (int c = 0; c < bs; ++c) {
      const int d = c / n, cn = c - d * n;  // component of c and its index in it
      std::size_t slot = first;
      for (int k = outer[e * bs + c]; k < outer[e * bs + c + 1]; ++k) {
        while ((level.blockElement[slot] + 1) * bs <= inner[k]) ++slot;  // both sorted
        // Entry (c, local) of block (e, f) goes to column local, row c.
        const int local = inner[k] - level.blockElement[slot] * bs;
        const std::size_t index =
            level.slotDiagonal[slot]
                ? static_cast<std::size_t>(d * n * n + (local - d * n) * n + cn)
                : static_cast<std::size_t>(local * bs + c);
        level.blockValues[level.slotOffset[slot] + index] = static_cast<float>(values[k]);
      }
    }
  });
}

/// s = b_e - (A x)_e for element e's rows, from the block rows of `level`.
inline void blockResidual(const Level& level, int e, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& x, double* s) {
  const int bs = level.bs;
  const Eigen::Index base = static_cast<Eigen::Index>(e) * bs;
  if (!level.useBlocks) {
    const SpMat& a = *level.matrix;
    const int* outer = a.outerIndexPtr();
    const int* inner = a.innerIndexPtr();
    const double* values = a.valuePtr();
    // Column base + c of A is row base + c (symmetric storage).
    for (int c = 0; c < bs; ++c) {
      double sum = 0.0;
      for (int k = outer[base + c]; k < outer[base + c + 1]; ++k) sum += values[k] * x[inner[k]];
      s[c] = b[base + c] - sum;
    }
    return;
  }
  const int n = level.n;
  for (int c = 0; c < bs; ++c) s[c] = b[base + c];
  for (int k = level.blockStart[static_cast<std::size_t>(e)];
       k < level.blockStart[static_cast<std::size_t>(e) + 1]; ++k) {
    const std::size_t slot = static_cast<std::size_t>(k);
    const float* block = level.blockValues.data() + level.slotOffset[slot];
    const double* xf =
        x.data() + static_cast<Eigen::Index>(level.blockElement[slot]) * bs;
    // Column by column: the inner loop has no reduction and vectorizes.
    if (level.slotDiagonal[slot]) {
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < n; ++j) {
          const float* column = block + (d * n + j) * n;
          const double xj = xf[d * n + j];
          double* sd = s + d * n;
          for (int i = 0; i < n; ++i) sd[i] -= static_cast<double>(column[i]) * xj;
        }
      continue;
    }
    for (int d = 0; d < bs; ++d) {
      const float* column = block + d * bs;
      const double xd = xf[d];
      for (int c = 0; c < bs; ++c) s[c] -= static_cast<double>(column[c]) * xd;
    }
  }
}

/// D^-1 of one symmetric positive definite block D (column-major, BS x BS) into `inverse`;
/// false if D is not positive definite. Fixed sizes: a 30 x 30 block inverts 3-4x faster
/// than with Eigen's dynamic-size LLT (p = 2 setup on B2).
template <int BS>
bool invertBlock(const double* block, double* inverse) {
  using Mat = Eigen::Matrix<double, BS, BS>;
  const Eigen::LLT<Mat> llt{Eigen::Map<const Mat>(block)};
  if (llt.info() != Eigen::Success) return false;
  Eigen::Map<Mat> out(inverse);
  out = llt.solve(Mat::Identity());
  return true;
}

bool invertBlock(int bs, const double* block, double* inverse) {
  switch (bs) {
    case 3: return invertBlock<3>(block, inverse);
    case 12: return invertBlock<12>(block, inverse);
    case 30: return invertBlock<30>(block, inverse);
    case 60: return invertBlock<60>(block, inverse);
    default: {
      const Eigen::LLT<Eigen::MatrixXd> llt{Eigen::Map<const Eigen::MatrixXd>(block, bs, bs)};
      if (llt.info() != Eigen::Success) return false;
      Eigen::Map<Eigen::MatrixXd> out(inverse, bs, bs);
      out = llt.solve(Eigen::MatrixXd::Identity(bs, bs));
      return true;
    }
  }
}

/// Inverts the element diagonal blocks of `level`; false if one is not positive definite.
bool invertBlocks(Level& level) {
  const SpMat& a = *level.matrix;
  const int bs = level.bs;
  const Eigen::Index ne = a.cols() / bs;
  level.inverses.resize(static_cast<std::size_t>(ne * bs * bs));
  std::atomic<bool> ok{true};
  tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
    const Eigen::Index base = e * bs;
    double block[kMaxBlock * kMaxBlock];
    std::fill(block, block + bs * bs, 0.0);
    if (level.useBlocks) {  // invert the block as the smoother sees it (single precision)
      std::size_t slot = static_cast<std::size_t>(level.blockStart[static_cast<std::size_t>(e)]);
      while (level.blockElement[slot] != e) ++slot;
      const float* values = level.blockValues.data() + level.slotOffset[slot];
      std::copy(values, values + bs * bs, block);
    } else {
      for (int c = 0; c < bs; ++c)
        for (SpMat::InnerIterator it(a, base + c); it; ++it)
          if (it.row() >= base && it.row() < base + bs) block[c * bs + (it.row() - base)] = it.value();
    }
    if (!invertBlock(bs, block, level.inverses.data() + e * bs * bs)) ok = false;
  });
  return ok;
}

/// Greedy colouring of the element graph of `a` (elements sharing a nonzero block are
/// neighbours): the elements of each colour, in increasing order.
std::vector<std::vector<int>> colourElements(const SpMat& a, int bs) {
  const int ne = static_cast<int>(a.cols() / bs);
  std::vector<int> colour(static_cast<std::size_t>(ne), -1);
  std::vector<int> seenBy;  // seenBy[c] == e: colour c is taken by a neighbour of e
  std::vector<std::vector<int>> classes;
  for (int e = 0; e < ne; ++e) {
    // Column e bs holds a row of every neighbour block (BZ blocks included: component 0).
    for (SpMat::InnerIterator it(a, static_cast<Eigen::Index>(e) * bs); it; ++it) {
      const int c = colour[static_cast<std::size_t>(it.row() / bs)];
      if (c >= 0) seenBy[static_cast<std::size_t>(c)] = e;
    }
    int c = 0;
    while (c < static_cast<int>(seenBy.size()) && seenBy[static_cast<std::size_t>(c)] == e) ++c;
    if (c == static_cast<int>(seenBy.size())) {
      seenBy.push_back(-1);
      classes.emplace_back();
    }
    colour[static_cast<std::size_t>(e)] = c;
    classes[static_cast<std::size_t>(c)].push_back(e);
  }
  return classes;
}

/// Functions per component of degree `degree`: numMonomials, checked against the block size.
int functionsOfBlock(int blockSize, int degree) {
  const int n = numMonomials(degree);
  if (blockSize != 3 * n || blockSize > kMaxBlock)
    throw std::invalid_argument("PMultigrid: block size does not match the degree");
  return n;
}

/// If the level-0 matrix `a` (unknown (e, d) at 3 e + d) is I_3 (x) S, the three
/// displacement components uncoupled and their matrices bitwise equal, fills `scalar` = S (one
/// unknown per element) and returns true. BZ's level 0 always is: its only terms, the penalty
/// mu eta_F [u].[v], treat the components alike. IP's is not (its lifting term adds
/// lambda n n^T per face).
bool separateComponents(const SpMat& a, SpMat& scalar) {
  const Eigen::Index ne = a.cols() / 3;
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  std::atomic<bool> separate{true};
  tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
    const int first = outer[3 * e], count = outer[3 * e + 1] - first;
    for (int d = 0; d < 3 && separate; ++d) {
      const int start = outer[3 * e + d];
      if (outer[3 * e + d + 1] - start != count) {
        separate = false;
        return;
      }
      for (int k = 0; k < count; ++k)
        if (inner[first + k] % 3 != 0 || inner[start + k] != inner[first + k] + d ||
            values[start + k] != values[first + k]) {
          separate = false;
          return;
        }
    }
  });
  if (!separate) return false;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(a.nonZeros() / 3));
  for (Eigen::Index e = 0; e < ne; ++e)
    for (int k = outer[3 * e]; k < outer[3 * e + 1]; ++k)
      entries.emplace_back(inner[k] / 3, static_cast<int>(e), values[k]);
  scalar.resize(ne, ne);
  scalar.setFromTriplets(entries.begin(), entries.end());
  return true;
}

}  // namespace

struct PMultigrid::Impl {
  std::vector<Level> levels;  // levels[q]: degree q
  std::vector<std::vector<int>> colours;
  /// CHOLMOD chooses simplicial (small levels: no BLAS start-up) or supernodal by the fill.
  Eigen::CholmodDecomposition<SpMat, Eigen::Lower> coarse;
  /// Level 0 is I_3 (x) S (separateComponents()): `coarse` factorizes S, and the three
  /// components are solved as three right-hand sides, a third of the unknowns (B2 with BZ:
  /// 1.5 instead of 4.5 ms of factorization).
  bool componentwise = false;
  SpMat scalarCoarse;
  mutable Eigen::MatrixXd coarseRhs, coarseSolution;

  void coarseSolve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
    if (!componentwise) {
      x = coarse.solve(b);
      return;
    }
    const Eigen::Index ne = b.size() / 3;
    // b as an ne x 3 matrix: row e holds element e's components (a transposed view).
    coarseRhs = Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>>(b.data(), 3, ne).transpose();
    coarseSolution = coarse.solve(coarseRhs);
    x.resize(b.size());
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>(x.data(), 3, ne) = coarseSolution.transpose();
  }

  /// Factorizes level 0 (or its scalar part S when it is I_3 (x) S).
  void factorizeCoarse() {
    const SpMat& a = *levels.front().matrix;
    componentwise = separateComponents(a, scalarCoarse);
    const SpMat& factored = componentwise ? scalarCoarse : a;
    coarse.cholmod().print = 0;
    // Small level 0: simplicial. The supernodal solve calls the threaded BLAS twice per
    // V-cycle and its thread hand-offs cost more than the solve (B2, 3000 unknowns: 42
    // instead of 70 ms of CG iterations for p = 1, factorization 4 ms slower); large ones keep
    // the supernodal factorization, whose BLAS speed dominates (the limit is a judgement, not
    // a measurement).
    if (factored.rows() <= kSimplicialCoarseLimit) coarse.setMode(Eigen::CholmodSimplicialLLt);
    // The level-0 matrix is small (3 unknowns per element): AMD alone orders it well, without
    // the METIS trial of CHOLMOD's default strategy.
    coarse.cholmod().nmethods = 1;
    coarse.cholmod().method[0].ordering = CHOLMOD_AMD;
    coarse.compute(factored);
  }

  /// One block Gauss-Seidel sweep on `level` for A x = b, colours in order or reversed.
  void sweep(const Level& level, const Eigen::VectorXd& b, Eigen::VectorXd& x,
             bool reverse) const {
    const int bs = level.bs;
    const std::size_t nc = colours.size();
    for (std::size_t t = 0; t < nc; ++t) {
      const std::vector<int>& cls = colours[reverse ? nc - 1 - t : t];
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cls.size(), 8),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          double s[kMaxBlock];
                          for (std::size_t j = range.begin(); j != range.end(); ++j) {
                            const int e = cls[j];
                            const Eigen::Index base = static_cast<Eigen::Index>(e) * bs;
                            blockResidual(level, e, b, x, s);
                            // x_e += D_e^-1 s, column by column (D_e^-1 is column-major):
                            // a plain loop, where Eigen's dynamic-size GEMV call cost a
                            // tenth of the CG time on B2.
                            const double* inverse = level.inverses.data() + base * bs;
                            double* xe = x.data() + base;
                            for (int d = 0; d < bs; ++d) {
                              const double* column = inverse + d * bs;
                              const double sd = s[d];
                              for (int c = 0; c < bs; ++c) xe[c] += column[c] * sd;
                            }
                          }
                        });
    }
  }

  /// r = b - A x on `level` right after a forward sweep: the rows of the last colour were
  /// just solved with every neighbour final, so their residual is zero and is not computed.
  void residualAfterSweep(const Level& level, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                          Eigen::VectorXd& r) const {
    const int bs = level.bs;
    r.resize(b.size());
    for (std::size_t t = 0; t < colours.size(); ++t) {
      const std::vector<int>& cls = colours[t];
      const bool last = t + 1 == colours.size();
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cls.size(), 16),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t j = range.begin(); j != range.end(); ++j) {
                            const int e = cls[j];
                            double* re = r.data() + static_cast<Eigen::Index>(e) * bs;
                            if (last) std::fill(re, re + bs, 0.0);
                            else blockResidual(level, e, b, x, re);
                          }
                        });
    }
  }

  /// x = V-cycle(q) applied to b, from x = 0.
  void vcycle(int q, const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
    if (q == 0) {
      coarseSolve(b, x);
      return;
    }
    const Level& fine = levels[static_cast<std::size_t>(q)];
    const Level& next = levels[static_cast<std::size_t>(q - 1)];
    x.setZero(b.size());
    sweep(fine, b, x, false);
    residualAfterSweep(fine, b, x, fine.r);
    const int n = fine.n, nc = next.n;
    const Eigen::Index ne = b.size() / fine.bs;
    next.b.resize(ne * next.bs);
    tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
      for (int d = 0; d < 3; ++d)
        next.b.segment(e * next.bs + d * nc, nc) = fine.r.segment(e * fine.bs + d * n, nc);
    });
    vcycle(q - 1, next.b, next.x);
    tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
      for (int d = 0; d < 3; ++d)
        x.segment(e * fine.bs + d * n, nc) += next.x.segment(e * next.bs + d * nc, nc);
    });
    sweep(fine, b, x, true);
  }
};

PMultigrid::PMultigrid() : impl_(std::make_unique<Impl>()) {}
PMultigrid::~PMultigrid() = default;
PMultigrid::PMultigrid(PMultigrid&&) noexcept = default;
PMultigrid& PMultigrid::operator=(PMultigrid&&) noexcept = default;

int PMultigrid::levels() const { return static_cast<int>(impl_->levels.size()); }
int PMultigrid::colours() const { return static_cast<int>(impl_->colours.size()); }

bool PMultigrid::compute(const SpMat& matrix, int degree) {
  Impl& m = *impl_;
  m.levels.assign(static_cast<std::size_t>(degree) + 1, Level{});
  Level& top = m.levels.back();
  top.n = numMonomials(degree);
  top.bs = 3 * top.n;
  functionsOfBlock(top.bs, degree);
  top.matrix = &matrix;
  m.colours = colourElements(matrix, top.bs);
  for (int q = degree - 1; q >= 0; --q) {
    Level& fine = m.levels[static_cast<std::size_t>(q) + 1];
    Level& level = m.levels[static_cast<std::size_t>(q)];
    level.n = numMonomials(q);
    level.bs = 3 * level.n;
    level.owned = restrictMatrix(*fine.matrix, fine.n, level.n);
    level.matrix = &level.owned;
  }
  // Level 0 couples elements through the penalty, mu eta_F [u].[v], which couples equal
  // components only, and (IP) the lifting of the normal jump, which couples components
  // through n n^T. K stores the element blocks whole, so level 0 inherits explicit zeros
  // that would make CHOLMOD factorize a coupled pattern: on B2 (3000 unknowns) 62 MFlop and
  // 30-50 ms, against 7 MFlop and 5 ms once exact zeros are dropped (the three components
  // then separate wherever the normals are axis-aligned, and for BZ everywhere).
  if (degree > 0)
    m.levels.front().owned.prune([](Eigen::Index, Eigen::Index, double v) { return v != 0.0; });
  std::atomic<bool> ok{true};
  // The smoother's blocks and the level-0 factorization (serial in CHOLMOD) side by side.
  tbb::parallel_invoke(
      [&] {
        tbb::parallel_for(std::size_t(1), m.levels.size(), [&](std::size_t q) {
          buildBlockRows(m.levels[q]);
          if (!invertBlocks(m.levels[q])) ok = false;
        });
      },
      [&] { m.factorizeCoarse(); });
  return ok && m.coarse.info() == Eigen::Success;
}

void PMultigrid::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  impl_->vcycle(static_cast<int>(impl_->levels.size()) - 1, r, z);
}

}  // namespace polydg
