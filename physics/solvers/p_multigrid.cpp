// The p-multigrid preconditioner (physics/solvers/p_multigrid.h): its levels built and the
// symmetric V-cycle over them. A level, its smoother and the coarse matrices of the degree levels
// are in multigrid_level.h, multigrid_smoother.h and multigrid_coarsening.h.
#include "physics/solvers/p_multigrid.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Dense>

#include "physics/dg/block_rows.h"
#include "physics/solvers/agglomeration.h"
#include "physics/solvers/multigrid_coarsening.h"
#include "physics/solvers/multigrid_level.h"
#include "physics/solvers/multigrid_smoother.h"
#include "physics/solvers/strong_coupling.h"
#include "polydg/integrate/monomials.h"

namespace polydg {

namespace {

using multigrid::blockResidual;
using multigrid::colourGroups;
using multigrid::invertGroups;
using multigrid::kMaxBlock;
using multigrid::Level;
using multigrid::restrictBlocks;
using multigrid::restrictMatrix;
using multigrid::singleBlocks;
using multigrid::splitComponents;
using multigrid::SpMat;
using multigrid::sweepOrder;
using multigrid::Transfer;

/// Unknowns up to which CHOLMOD factorizes the coarsest level simplicially (see
/// factorizeCoarse()): a degree-0 level, and an agglomeration level (denser: 12 x 12 or 30 x 30
/// blocks).
constexpr Eigen::Index kSimplicialCoarseLimit = 30000;
constexpr Eigen::Index kSimplicialAggregateLimit = 1000;

/// Smoother groups join blocks whose coupling strength gamma (couplingStrengths(), the cosine of
/// the angle between their unknowns in the energy inner product) is at least
/// smootherStrongCoupling(p) = sqrt(3)/2, or 3/4 for p = 1 (physics/solvers/strong_coupling.h). On
/// hex grids no pair is that strong, so their smoother is unchanged; across faces of elements
/// clipped by the surface gamma comes close to 1. A lower threshold would join elements of hex
/// grids too, which costs them iterations.
///
/// Most blocks in one smoother group, and so most unknowns. Strong couplings chain along a
/// clipped surface layer; 16 blocks take in such chains, and larger caps saved no iterations.
/// Most groups are pairs.
constexpr int kMaxGroupBlocks = 16;
constexpr int kMaxGroupUnknowns = kMaxGroupBlocks * kMaxBlock;

/// When agglomeration stops. The coarsest level is factorized once and solved once per
/// V-cycle; its factorization should cost about one V-cycle on K. A coarse matrix with 12 x 12
/// blocks on a 3D mesh factorizes in about 13 N^2 flops for N unknowns, about what a V-cycle
/// costs at 13 flops per nonzero of K when N^2 = nnz(K). So agglomeration continues while
/// N^2 > nnz(K), and at least down to kCoarseUnknowns. Denser 30 x 30 blocks cost more flops
/// per N^2, but a bound scaled to them (N^2 <= 0.4 nnz(K)) cost iterations and saved neither
/// memory nor time, so the rule stays.
constexpr Eigen::Index kCoarseUnknowns = 600;

/// Functions per component of degree `degree`: numMonomials, checked against the block size.
int functionsOfBlock(int blockSize, int degree) {
  const int n = numMonomials(degree);
  if (blockSize != 3 * n || blockSize > kMaxBlock)
    throw std::invalid_argument("PMultigrid: block size does not match the degree");
  return n;
}

}  // namespace

struct PMultigrid::Impl {
  explicit Impl(MatrixTerms t) : terms(t) {}

  MatrixTerms terms;
  std::vector<Level> levels;  ///< levels[0] is K (degree p), each next one coarser
  /// The coupling strength from which the smoothers join blocks (smootherStrongCoupling(p)).
  double strongCoupling = kSmootherStrongCoupling;
  /// The coarsest level's factorization: of the whole matrix, or, for a degree-0 level whose
  /// displacement components are uncoupled (splitComponents()), of each component's matrix,
  /// factorized side by side, or of the one matrix S of all three (a = I_3 (x) S: three
  /// right-hand sides, a third of the unknowns).
  using Cholesky = Eigen::CholmodDecomposition<SpMat, Eigen::Lower>;
  std::vector<std::unique_ptr<Cholesky>> coarse;
  std::vector<SpMat> coarseParts;
  mutable Eigen::MatrixXd coarseRhs, coarseSolution;

  const Level& coarsest() const { return levels.back(); }

  /// PMultigrid::compute() from the CSR matrix or (matrix null) from block rows.
  bool build(const SpMat* matrix, const BlockRows<double>* rows, int degree,
             const BlockRows<double>* matrixBlocks, const ElementFrames* frames);

  void coarseSolve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
    if (coarseParts.empty()) {
      x = coarse.front()->solve(b);
      return;
    }
    const Eigen::Index ne = b.size() / 3;
    // b as an ne x 3 matrix: row e holds element e's components (a transposed view).
    coarseRhs =
        Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>>(b.data(), 3, ne).transpose();
    if (coarse.size() == 1) {
      coarseSolution = coarse.front()->solve(coarseRhs);
    } else {
      coarseSolution.resize(ne, 3);
      for (int d = 0; d < 3; ++d)
        coarseSolution.col(d) = coarse[static_cast<std::size_t>(d)]->solve(coarseRhs.col(d));
    }
    x.resize(b.size());
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>(x.data(), 3, ne) =
        coarseSolution.transpose();
  }

  /// Factorizes the coarsest level (or its components' matrices). False if one is not
  /// positive definite.
  bool factorizeCoarse() {
    const Level& level = coarsest();
    const SpMat& a = *level.matrix;
    coarseParts.clear();
    if (level.bs == 3) splitComponents(a, coarseParts);
    const std::size_t count = coarseParts.empty() ? 1 : coarseParts.size();
    coarse.clear();
    for (std::size_t i = 0; i < count; ++i) coarse.push_back(std::make_unique<Cholesky>());
    std::atomic<bool> ok{true};
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) {
      const SpMat& factored = coarseParts.empty() ? a : coarseParts[i];
      Cholesky& c = *coarse[i];
      c.cholmod().print = 0;
      // Small coarse levels: simplicial. The supernodal solve calls the threaded BLAS twice
      // per V-cycle and its thread hand-offs cost more than the solve. Agglomeration levels
      // have dense 12 x 12 (or 30 x 30) blocks, where the supernodal factorization wins sooner.
      const Eigen::Index simplicialLimit =
          level.bs == 3 ? kSimplicialCoarseLimit : kSimplicialAggregateLimit;
      if (factored.rows() <= simplicialLimit) c.setMode(Eigen::CholmodSimplicialLLt);
      // The coarse level is small: AMD alone orders it well, without the METIS trial of
      // CHOLMOD's default strategy.
      c.cholmod().nmethods = 1;
      c.cholmod().method[0].ordering = CHOLMOD_AMD;
      c.compute(factored);
      if (c.info() != Eigen::Success) ok = false;
    });
    return ok;
  }

  /// The colours of `level`'s smoother groups, and the blocks of the last one.
  static void colour(Level& level) {
    level.colours = colourGroups(level);
    level.inLastColour.assign(static_cast<std::size_t>(level.blockCount()), 0);
    if (!level.colours.empty())
      for (int g : level.colours.back())
        for (int e : level.smootherGroups.of(g))
          level.inLastColour[static_cast<std::size_t>(e)] = 1;
  }

  /// Colours, smoother groups and their inverses of a level that is smoothed; its groups
  /// `groups` if given (moved from), else found from its matrix.
  bool prepareSmoother(Level& level, const BlockRows<double>* matrixBlocks,
                       BlockGroups* groups = nullptr) {
    auto groupsOf = [&](const auto& blocks) {
      return groups != nullptr ? std::move(*groups)
                               : groupStrongCouplings(blocks, strongCoupling, kMaxGroupBlocks);
    };
    // The top level given by rows: the smoother reads the caller's rows; a level converted
    // already: keepSmootherCopyOnly().
    if (!level.rows && !level.useBlocks) {
      if (matrixBlocks == nullptr) matrixBlocks = level.source;
      if (matrixBlocks != nullptr && !matrixBlocks->values.empty()) {
        // Groups and colours from the rows in double precision, then their single-precision
        // copy converted straight into the order the sweeps visit (one pass, one allocation).
        level.smootherGroups = groupsOf(*matrixBlocks);
        level.blocks.copyPattern(*matrixBlocks);
        level.useBlocks = true;
        colour(level);
        level.blocks.convertInOrder(*matrixBlocks, sweepOrder(level));
        return invertGroups(level);
      } else {
        level.useBlocks = level.blocks.build(*level.matrix, level.n, 2.0);
      }
    }
    if (level.rows)
      level.smootherGroups = groupsOf(*level.rows);
    else if (level.useBlocks)
      level.smootherGroups = groupsOf(level.blocks);
    else  // a pattern too sparse for blocks (BlockRows::build)
      level.smootherGroups = singleBlocks(static_cast<int>(level.blockCount()));
    colour(level);
    if (level.useBlocks) level.blocks.layOutInOrder(sweepOrder(level));
    return invertGroups(level);
  }

  /// Appends the agglomeration level of levels.back() with functions of `degree`: groups of
  /// its elements (`frames`) or, without frames, of the groups of the level before.
  void addAggregateLevel(const ElementFrames* frames, int degree) {
    Level& fine = levels.back();
    fine.transfer = Transfer::Aggregate;
    if (fine.source == nullptr) {
      fine.exact.build(*fine.matrix, fine.n, std::numeric_limits<double>::infinity());
      fine.source = &fine.exact;
    }
    if (frames != nullptr) {
      const std::vector<Eigen::Vector3i> noCells;
      const bool lattice = frames->cells.size() == frames->centres.size();
      fine.groups = agglomerate(*fine.source, frames->centres, frames->scales, frames->bases,
                                lattice ? frames->cells : noCells, degree);
    } else {
      // The groups of the level before are read before the levels grow.
      fine.groups = agglomerate(*fine.source, levels[levels.size() - 2].groups, degree);
    }
    Level level;
    level.n = numMonomials(degree);
    level.bs = 3 * level.n;
    // By block rows: what the next grouping, the next Galerkin product and the smoother read;
    // the coarsest level alone is converted to CSR, for CHOLMOD (finishAggregation()).
    level.exact = galerkinBlocks(fine.groups, *fine.source);
    push(std::move(level));
  }

  /// The coarsest level's matrix in CSR, for its factorization, from its block rows (an
  /// agglomeration level), which are then freed.
  void finishAggregation() {
    Level& last = levels.back();
    if (last.exact.start.empty() || last.owned.size() > 0) return;
    SpMat matrix = last.exact.toSparse();
    last.owned.swap(matrix);
    last.matrix = &last.owned;
    last.exact = BlockRows<double>();
    last.source = nullptr;
  }

  /// Keeps of an agglomeration level that is smoothed (not the coarsest) only what its
  /// smoother reads: its matrix by block rows in single precision, converted from the double
  /// ones that served the grouping and the Galerkin product of the next level, which are
  /// freed: held (with, then, a CSR matrix) at levels 1 and 2, they would raise the peak memory
  /// of a large solve.
  void keepSmootherCopyOnly(Level& level) {
    level.blocks.convertFrom(level.exact);
    level.useBlocks = true;
    level.exact = BlockRows<double>();
    level.source = nullptr;
  }

  /// Appends a coarser level that owns `matrix`. Re-points every owned matrix: the vector
  /// may have moved the levels. Eigen 3.4's SparseMatrix has no move constructor or
  /// assignment: a Level moved with its matrix, or a returned matrix assigned, copies every
  /// nonzero; the matrix is swapped in.
  void push(Level&& level, SpMat matrix = SpMat()) {
    levels.push_back(std::move(level));
    levels.back().owned.swap(matrix);
    for (std::size_t k = 0; k < levels.size(); ++k) {
      if (k > 0 || levels[k].owned.size() > 0) levels[k].matrix = &levels[k].owned;
      if (!levels[k].exact.values.empty()) levels[k].source = &levels[k].exact;
    }
  }

  /// One block Gauss-Seidel sweep on `level` for A x = b, colours in order or reversed, one
  /// smoother group at a time. With `fromZero` (x = 0 on entry, forward sweep) the first
  /// colour's residual is b itself and is not computed: a sixth less smoother work per
  /// V-cycle with two colours.
  void sweep(const Level& level, const Eigen::VectorXd& b, Eigen::VectorXd& x, bool reverse,
             bool fromZero = false) const {
    const int bs = level.bs;
    const BlockGroups& groups = level.smootherGroups;
    const std::vector<std::vector<int>>& colours = level.colours;
    const std::size_t nc = colours.size();
    for (std::size_t t = 0; t < nc; ++t) {
      const std::vector<int>& cls = colours[reverse ? nc - 1 - t : t];
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cls.size(), 8),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          double s[kMaxGroupUnknowns], y[kMaxGroupUnknowns];
                          for (std::size_t j = range.begin(); j != range.end(); ++j) {
                            const int g = cls[j];
                            const std::span<const int> group = groups.of(g);
                            const int m = static_cast<int>(group.size()), size = m * bs;
                            // s = the residual of the group's rows.
                            for (int i = 0; i < m; ++i) {
                              const Eigen::Index base = static_cast<Eigen::Index>(group[i]) * bs;
                              if (fromZero && t == 0)
                                std::copy(b.data() + base, b.data() + base + bs, s + i * bs);
                              else
                                blockResidual(level, group[i], b, x, s + i * bs);
                            }
                            // x_g += D_g^-1 s (D_g^-1 column-major): a plain loop, cheaper than
                            // Eigen's dynamic-size GEMV call for blocks this small.
                            const double* inverse =
                                level.inverses.data() +
                                level.inverseOffset[static_cast<std::size_t>(g)];
                            if (m == 1) {
                              addDenseProduct(bs, inverse, s,
                                              x.data() + static_cast<Eigen::Index>(group[0]) * bs);
                              continue;
                            }
                            std::fill(y, y + size, 0.0);
                            addDenseProduct(size, inverse, s, y);
                            for (int i = 0; i < m; ++i) {
                              double* xe = x.data() + static_cast<Eigen::Index>(group[i]) * bs;
                              for (int c = 0; c < bs; ++c) xe[c] += y[i * bs + c];
                            }
                          }
                        });
    }
  }

  /// The coarse right-hand side right after a forward sweep on `fine`: the residual
  /// b - A x restricted to `next`, in one pass. The rows of the last colour were just solved
  /// with every neighbour final, so their residual is zero and is not computed.
  void restrictedResidual(const Level& fine, const Level& next, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& x) const {
    const int n = fine.n, nc = next.n;
    const Eigen::Index coarseBlocks = next.blockCount();
    next.b.resize(coarseBlocks * next.bs);
    if (fine.transfer == Transfer::Degree) {
      tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, coarseBlocks, 16),
                        [&](const tbb::blocked_range<Eigen::Index>& range) {
                          double s[kMaxBlock];
                          for (Eigen::Index e = range.begin(); e != range.end(); ++e) {
                            double* coarse = next.b.data() + e * next.bs;
                            if (fine.inLastColour[static_cast<std::size_t>(e)]) {
                              std::fill(coarse, coarse + next.bs, 0.0);
                              continue;
                            }
                            blockResidual(fine, static_cast<int>(e), b, x, s);
                            for (int d = 0; d < 3; ++d)
                              std::copy(s + d * n, s + d * n + nc, coarse + d * nc);
                          }
                        });
      return;
    }
    // Aggregate: coarse block c gathers W_e^T (residual of e) over its blocks e.
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, coarseBlocks, 4),
                      [&](const tbb::blocked_range<Eigen::Index>& range) {
                        double s[kMaxBlock];
                        for (Eigen::Index c = range.begin(); c != range.end(); ++c) {
                          double* coarse = next.b.data() + c * next.bs;
                          std::fill(coarse, coarse + next.bs, 0.0);
                          const Agglomeration& groups = fine.groups;
                          for (int k = groups.childStart[static_cast<std::size_t>(c)];
                               k < groups.childStart[static_cast<std::size_t>(c) + 1]; ++k) {
                            const int e = groups.children[static_cast<std::size_t>(k)];
                            if (fine.inLastColour[static_cast<std::size_t>(e)]) continue;
                            blockResidual(fine, e, b, x, s);
                            const double* w =
                                groups.weights.data() +
                                static_cast<std::size_t>(n * nc) * static_cast<std::size_t>(e);
                            for (int d = 0; d < 3; ++d)
                              for (int j = 0; j < nc; ++j) {
                                double sum = 0.0;
                                for (int i = 0; i < n; ++i) sum += w[i + n * j] * s[d * n + i];
                                coarse[d * nc + j] += sum;
                              }
                          }
                        }
                      });
  }

  /// x += P (next.x): the coarse correction in `fine`'s unknowns.
  void prolongate(const Level& fine, const Level& next, Eigen::VectorXd& x) const {
    const int n = fine.n, nc = next.n;
    const Eigen::Index nb = x.size() / fine.bs;
    tbb::parallel_for(Eigen::Index(0), nb, [&](Eigen::Index e) {
      double* xe = x.data() + e * fine.bs;
      if (fine.transfer == Transfer::Degree) {
        const double* xc = next.x.data() + e * next.bs;
        for (int d = 0; d < 3; ++d)
          for (int i = 0; i < nc; ++i) xe[d * n + i] += xc[d * nc + i];
        return;
      }
      const double* xc =
          next.x.data() +
          static_cast<Eigen::Index>(fine.groups.parent[static_cast<std::size_t>(e)]) * next.bs;
      const double* w = fine.groups.weights.data() + static_cast<Eigen::Index>(n * nc) * e;
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < nc; ++j) {
          const double v = xc[d * nc + j];
          for (int i = 0; i < n; ++i) xe[d * n + i] += w[i + n * j] * v;
        }
    });
  }

  /// x = V-cycle from level k applied to b, from x = 0.
  void vcycle(std::size_t k, const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
    if (k + 1 == levels.size()) {
      coarseSolve(b, x);
      return;
    }
    const Level& fine = levels[k];
    const Level& next = levels[k + 1];
    x.setZero(b.size());
    for (int s = 0; s < fine.sweeps; ++s) sweep(fine, b, x, false, s == 0);
    restrictedResidual(fine, next, b, x);
    vcycle(k + 1, next.b, next.x);
    prolongate(fine, next, x);
    for (int s = 0; s < fine.sweeps; ++s) sweep(fine, b, x, true);
  }
};

PMultigrid::PMultigrid(MatrixTerms terms) : impl_(std::make_unique<Impl>(terms)) {}
PMultigrid::~PMultigrid() = default;
PMultigrid::PMultigrid(PMultigrid&&) noexcept = default;
PMultigrid& PMultigrid::operator=(PMultigrid&&) noexcept = default;

int PMultigrid::sweeps(int level) const {
  return level + 1 == levels() ? 0 : impl_->levels[static_cast<std::size_t>(level)].sweeps;
}
int PMultigrid::levels() const { return static_cast<int>(impl_->levels.size()); }
int PMultigrid::groupedBlocks() const {
  if (impl_->levels.empty()) return 0;
  const BlockGroups& groups = impl_->levels.front().smootherGroups;
  int count = 0;
  for (int g = 0; g < groups.groups(); ++g)
    if (groups.size(g) > 1) count += groups.size(g);
  return count;
}
int PMultigrid::colours() const {
  return impl_->levels.empty() ? 0 : static_cast<int>(impl_->levels.front().colours.size());
}
Eigen::Index PMultigrid::coarseUnknowns() const {
  return impl_->levels.empty() ? 0 : impl_->levels.back().matrix->rows();
}

bool PMultigrid::compute(const SpMat& matrix, int degree, const BlockRows<double>* matrixBlocks,
                         const ElementFrames* frames) {
  return impl_->build(&matrix, nullptr, degree, matrixBlocks, frames);
}

bool PMultigrid::compute(const BlockRows<double>& rows, int degree, const ElementFrames* frames) {
  return impl_->build(nullptr, &rows, degree, nullptr, frames);
}

bool PMultigrid::computeCopy(const BlockRows<double>& rows, int degree,
                             const ElementFrames* frames) {
  return impl_->build(nullptr, &rows, degree, &rows, frames);
}

bool PMultigrid::Impl::build(const SpMat* matrix, const BlockRows<double>* rows, int degree,
                             const BlockRows<double>* matrixBlocks, const ElementFrames* frames) {
  Impl& m = *this;
  m.strongCoupling = smootherStrongCoupling(degree);
  m.levels.clear();
  // Room for every level: growing the vector would copy the levels (Eigen's sparse matrices
  // move without noexcept), each matrix twice at once.
  m.levels.reserve(32);
  m.levels.emplace_back();
  Level& top = m.levels.back();
  top.n = numMonomials(degree);
  top.bs = 3 * top.n;
  functionsOfBlock(top.bs, degree);
  top.matrix = matrix;
  top.rows = rows;
  if (rows) {
    if (rows->bs != top.bs)
      throw std::invalid_argument("PMultigrid: block size does not match the degree");
    top.source = rows;
  }
  const Eigen::Index ne = top.blockCount();
  const double nonzeros =
      rows ? static_cast<double>(rows->entries()) : static_cast<double>(matrix->nonZeros());
  const bool agglomerate = frames != nullptr && degree >= 1 &&
                           frames->centres.size() == static_cast<std::size_t>(ne) &&
                           frames->scales.size() == static_cast<std::size_t>(ne) &&
                           frames->bases.size() == static_cast<std::size_t>(ne);
  // The top level's smoother groups from its rows in double precision (the caller's, or the
  // CSR matrix's copy by blocks) while the levels below are built: their strengths are the
  // larger part of the build, and neither task writes what the other reads.
  const BlockRows<double>* topRows = rows ? rows
                                     : matrixBlocks != nullptr && !matrixBlocks->values.empty()
                                         ? matrixBlocks
                                         : nullptr;
  const bool topSmoothed = agglomerate || degree > 0;
  BlockGroups topGroups;
  auto buildLevels = [&] {
    // Degree levels down to min(p, 2) with frames (then agglomerates of that degree), else down
    // to 0.
    const int groupDegree = std::min(degree, 2);
    for (int q = degree - 1; q >= (agglomerate ? groupDegree : 0); --q) {
      Level& fine = m.levels.back();
      Level level;
      level.n = numMonomials(q);
      level.bs = 3 * level.n;
      m.push(std::move(level), fine.rows ? restrictBlocks(*fine.rows, level.n)
                                         : restrictMatrix(*fine.matrix, fine.n, level.n));
    }
    if (m.levels.size() == 1 && !agglomerate && top.rows) {
      // The top level is the coarsest, factorized: it needs the CSR matrix.
      SpMat matrix = top.rows->toSparse();
      top.owned.swap(matrix);
      top.matrix = &top.owned;
      top.rows = nullptr;
    }
    if (agglomerate) {
      Level& elements = m.levels.back();
      if (m.levels.size() == 1 && matrixBlocks != nullptr && !matrixBlocks->values.empty())
        elements.source = matrixBlocks;
      m.addAggregateLevel(frames, groupDegree);
      // Further levels while the coarsest is large and grouping still shrinks it, all with
      // quadratic functions: groups of 4 x 4 x 4 cells and more span the thin parts of a real
      // model (the bunny's ears), which bend within a group (for p = 1, linear groups take the
      // Taylor parts of their parent's quadratics). They have an eighth of the blocks of the
      // level before each, so they sweep twice: a V-cycle with two agglomeration levels then
      // needs about as many iterations as one with an exact first agglomeration level on B2.
      // Once with a mass term (MatrixTerms::StiffnessAndMass).
      const double limit = std::max(static_cast<double>(kCoarseUnknowns), std::sqrt(nonzeros));
      while (static_cast<double>(m.levels.back().unknowns()) > limit) {
        const Eigen::Index before = m.levels.back().unknowns();
        m.levels.back().sweeps = m.terms == MatrixTerms::StiffnessAndMass ? 1 : 2;
        // The blocks of the last level are the groups of the one before.
        m.addAggregateLevel(nullptr, 2);
        const Eigen::Index after = m.levels.back().unknowns();
        if (after >= before) {  // quadratic groups of groups on a line: no fewer unknowns
          m.levels.pop_back();
          break;
        }
        m.keepSmootherCopyOnly(m.levels[m.levels.size() - 2]);
        if (after * 4 > before * 3) break;  // grouping stalled
      }
      m.finishAggregation();
    } else if (degree > 0) {
      // Level 0 couples elements through the penalty, mu eta_F [u].[v], which couples equal
      // components only, and (IP) the lifting of the normal jump, which couples components
      // through n n^T. K stores the element blocks whole, so level 0 inherits explicit zeros
      // that would make CHOLMOD factorize a coupled pattern, several times the work of the
      // pattern without them (the three components then separate wherever the normals are
      // axis-aligned, and for BZ everywhere).
      m.levels.back().owned.prune([](Eigen::Index, Eigen::Index, double v) { return v != 0.0; });
    }
  };
  if (topRows != nullptr && topSmoothed)
    tbb::parallel_invoke(
        [&] { topGroups = groupStrongCouplings(*topRows, m.strongCoupling, kMaxGroupBlocks); },
        buildLevels);
  else
    buildLevels();
  // Rows given to be copied (computeCopy()): read for the levels below, then converted for the
  // top level's smoother like a CSR matrix's (prepareSmoother()).
  if (rows != nullptr && matrixBlocks == rows && m.levels.size() > 1)
    m.levels.front().rows = nullptr;
  std::atomic<bool> ok{true};
  // The smoothers' blocks and the coarsest level's factorization (serial in CHOLMOD) side by
  // side.
  tbb::parallel_invoke(
      [&] {
        tbb::parallel_for(std::size_t(0), m.levels.size() - 1, [&](std::size_t k) {
          if (!m.prepareSmoother(m.levels[k], k == 0 ? matrixBlocks : nullptr,
                                 k == 0 && topGroups.groups() > 0 ? &topGroups : nullptr))
            ok = false;
        });
      },
      [&] {
        if (!m.factorizeCoarse()) ok = false;
      });
  return ok;
}

void PMultigrid::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  impl_->vcycle(0, r, z);
}

}  // namespace polydg
