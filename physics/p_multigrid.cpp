#include "physics/p_multigrid.h"

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include "integrate/monomials.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Level-0 unknowns up to which CHOLMOD factorizes it simplicially (see compute()).
constexpr Eigen::Index kSimplicialCoarseLimit = 30000;

/// Largest element block handled (3 numMonomials(3)).
constexpr int kMaxBlock = 60;
using BlockVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBlock, 1>;

/// One degree q: its matrix (the top level borrows K), functions per component and the
/// inverses of its element diagonal blocks (bs x bs each, column-major).
struct Level {
  const SpMat* matrix = nullptr;
  SpMat owned;
  int n = 0, bs = 0;
  std::vector<double> inverses;
  /// The smoother's copy of the matrix in single precision, by element block rows: element
  /// e's blocks are slots blockStart[e] .. blockStart[e + 1] - 1, slot k the bs x bs block
  /// (column-major) against element blockElement[k]. Half the bytes of the CSR values and no
  /// index per entry: the smoother is bound by memory bandwidth. Symmetric like the matrix,
  /// so the V-cycle stays symmetric (it is the V-cycle of the rounded matrix).
  /// Used when the blocks are mostly nonzero (IP); BZ's neighbour blocks couple equal
  /// components only (a third nonzero) and its smoother reads the CSR matrix instead.
  bool useBlocks = false;
  std::vector<int> blockStart, blockElement;
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
  auto coarseIndex = [&](int dof) -> int {
    const int e = dof / bs, local = dof % bs, d = local / n, i = local % n;
    return i < nc ? e * bsc + d * nc + i : -1;
  };
  auto fineColumn = [&](Eigen::Index c) -> Eigen::Index {
    const Eigen::Index e = c / bsc, local = c % bsc;
    return e * bs + (local / nc) * n + local % nc;
  };
  const int* outer = fine.outerIndexPtr();
  const int* inner = fine.innerIndexPtr();
  const double* values = fine.valuePtr();
  std::vector<int> counts(static_cast<std::size_t>(ncols) + 1, 0);
  tbb::parallel_for(Eigen::Index(0), ncols, [&](Eigen::Index c) {
    const Eigen::Index fc = fineColumn(c);
    int count = 0;
    for (int k = outer[fc]; k < outer[fc + 1]; ++k) count += coarseIndex(inner[k]) >= 0;
    counts[static_cast<std::size_t>(c) + 1] = count;
  });
  for (std::size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
  SpMat coarse(ncols, ncols);
  coarse.resizeNonZeros(counts.back());
  std::copy(counts.begin(), counts.end(), coarse.outerIndexPtr());
  int* cinner = coarse.innerIndexPtr();
  double* cvalues = coarse.valuePtr();
  tbb::parallel_for(Eigen::Index(0), ncols, [&](Eigen::Index c) {
    const Eigen::Index fc = fineColumn(c);
    int pos = counts[static_cast<std::size_t>(c)];
    // Fine rows are sorted and the renumbering is monotone: coarse rows come out sorted.
    for (int k = outer[fc]; k < outer[fc + 1]; ++k) {
      const int row = coarseIndex(inner[k]);
      if (row < 0) continue;
      cinner[pos] = row;
      cvalues[pos++] = values[k];
    }
  });
  return coarse;
}

/// Fills the single-precision block rows of `level` from its matrix.
void buildBlockRows(Level& level) {
  const SpMat& a = *level.matrix;
  const int bs = level.bs;
  const int ne = static_cast<int>(a.cols() / bs);
  // Column e bs holds a row of every neighbour block (BZ blocks included: component 0).
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(ne));
  tbb::parallel_for(0, ne, [&](int e) {
    std::vector<int>& nb = neighbours[static_cast<std::size_t>(e)];
    for (SpMat::InnerIterator it(a, static_cast<Eigen::Index>(e) * bs); it; ++it) {
      const int f = static_cast<int>(it.row() / bs);
      if (nb.empty() || nb.back() != f) nb.push_back(f);  // rows are sorted
    }
  });
  level.blockStart.assign(static_cast<std::size_t>(ne) + 1, 0);
  for (int e = 0; e < ne; ++e)
    level.blockStart[static_cast<std::size_t>(e) + 1] =
        level.blockStart[static_cast<std::size_t>(e)] +
        static_cast<int>(neighbours[static_cast<std::size_t>(e)].size());
  const std::size_t slots = static_cast<std::size_t>(level.blockStart.back());
  level.useBlocks = 2 * static_cast<std::size_t>(a.nonZeros()) >= slots * bs * bs;
  if (!level.useBlocks) return;
  level.blockElement.resize(slots);
  level.blockValues.assign(slots * static_cast<std::size_t>(bs * bs), 0.0f);
  tbb::parallel_for(0, ne, [&](int e) {
    const std::vector<int>& nb = neighbours[static_cast<std::size_t>(e)];
    const std::size_t first = static_cast<std::size_t>(level.blockStart[static_cast<std::size_t>(e)]);
    std::copy(nb.begin(), nb.end(), level.blockElement.begin() + static_cast<std::ptrdiff_t>(first));
    for (int c = 0; c < bs; ++c) {
      std::size_t slot = first;
      for (SpMat::InnerIterator it(a, static_cast<Eigen::Index>(e) * bs + c); it; ++it) {
        const int f = static_cast<int>(it.row() / bs);
        while (level.blockElement[slot] != f) ++slot;  // both sorted
        // Entry (c, row % bs) of block (e, f), stored column-major.
        level.blockValues[(slot * bs + static_cast<std::size_t>(it.row() % bs)) * bs +
                          static_cast<std::size_t>(c)] = static_cast<float>(it.value());
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
  for (int c = 0; c < bs; ++c) s[c] = b[base + c];
  for (int k = level.blockStart[static_cast<std::size_t>(e)];
       k < level.blockStart[static_cast<std::size_t>(e) + 1]; ++k) {
    const float* block = level.blockValues.data() + static_cast<std::size_t>(k) * bs * bs;
    const double* xf =
        x.data() + static_cast<Eigen::Index>(level.blockElement[static_cast<std::size_t>(k)]) * bs;
    // Column by column: the inner loop has no reduction and vectorizes.
    for (int d = 0; d < bs; ++d) {
      const float* column = block + d * bs;
      const double xd = xf[d];
      for (int c = 0; c < bs; ++c) s[c] -= static_cast<double>(column[c]) * xd;
    }
  }
}

/// Inverts the element diagonal blocks of `level`; false if one is not positive definite.
bool invertBlocks(Level& level) {
  const SpMat& a = *level.matrix;
  const int bs = level.bs;
  const Eigen::Index ne = a.cols() / bs;
  level.inverses.assign(static_cast<std::size_t>(ne * bs * bs), 0.0);
  std::atomic<bool> ok{true};
  tbb::parallel_for(Eigen::Index(0), ne, [&](Eigen::Index e) {
    const Eigen::Index base = e * bs;
    Eigen::MatrixXd block = Eigen::MatrixXd::Zero(bs, bs);
    for (int c = 0; c < bs; ++c)
      for (SpMat::InnerIterator it(a, base + c); it; ++it)
        if (it.row() >= base && it.row() < base + bs)
          block(it.row() - base, c) = level.useBlocks ? static_cast<float>(it.value())  // as the
                                                      : it.value();  // smoother sees it
    Eigen::LLT<Eigen::MatrixXd> llt(block);
    if (llt.info() != Eigen::Success) {
      ok = false;
      return;
    }
    Eigen::Map<Eigen::MatrixXd>(level.inverses.data() + e * bs * bs, bs, bs) =
        llt.solve(Eigen::MatrixXd::Identity(bs, bs));
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

}  // namespace

struct PMultigrid::Impl {
  std::vector<Level> levels;  // levels[q]: degree q
  std::vector<std::vector<int>> colours;
  /// CHOLMOD chooses simplicial (small levels: no BLAS start-up) or supernodal by the fill.
  Eigen::CholmodDecomposition<SpMat, Eigen::Lower> coarse;

  /// One block Gauss-Seidel sweep on `level` for A x = b, colours in order or reversed.
  void sweep(const Level& level, const Eigen::VectorXd& b, Eigen::VectorXd& x,
             bool reverse) const {
    const int bs = level.bs;
    const std::size_t nc = colours.size();
    for (std::size_t t = 0; t < nc; ++t) {
      const std::vector<int>& cls = colours[reverse ? nc - 1 - t : t];
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cls.size(), 8),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          BlockVector s(bs);
                          for (std::size_t j = range.begin(); j != range.end(); ++j) {
                            const int e = cls[j];
                            const Eigen::Index base = static_cast<Eigen::Index>(e) * bs;
                            blockResidual(level, e, b, x, s.data());
                            x.segment(base, bs).noalias() +=
                                Eigen::Map<const Eigen::MatrixXd>(
                                    level.inverses.data() + base * bs, bs, bs) *
                                s;
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
      x = coarse.solve(b);
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
  std::atomic<bool> ok{true};
  tbb::parallel_for(std::size_t(1), m.levels.size(), [&](std::size_t q) {
    buildBlockRows(m.levels[q]);
    if (!invertBlocks(m.levels[q])) ok = false;
  });
  m.coarse.cholmod().print = 0;
  // Small level 0: simplicial. The supernodal solve calls the threaded BLAS twice per V-cycle
  // and its thread hand-offs cost more than the solve (B2, 3000 unknowns: 42 instead of 70 ms
  // of CG iterations for p = 1, factorization 4 ms slower); large ones keep the supernodal
  // factorization, whose BLAS speed dominates (the limit is a judgement, not a measurement).
  if (m.levels.front().matrix->rows() <= kSimplicialCoarseLimit)
    m.coarse.setMode(Eigen::CholmodSimplicialLLt);
  // The level-0 matrix is small (3 unknowns per element): AMD alone orders it well, without
  // the METIS trial of CHOLMOD's default strategy.
  m.coarse.cholmod().nmethods = 1;
  m.coarse.cholmod().method[0].ordering = CHOLMOD_AMD;
  m.coarse.compute(*m.levels.front().matrix);
  return ok && m.coarse.info() == Eigen::Success;
}

void PMultigrid::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  impl_->vcycle(static_cast<int>(impl_->levels.size()) - 1, r, z);
}

}  // namespace polydg
