#include "physics/solvers/linear_solver.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Dense>

#include "physics/dg/block_rows.h"
#include "physics/solvers/p_multigrid.h"
#include "polydg/integrate/monomials.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Quiet CHOLMOD: "not positive definite" is an expected outcome of a penalty search.
template <class Solver>
void silence(Solver& solver) {
  solver.cholmod().print = 0;
}

template <class Solver>
void setOrdering(Solver& solver, CholeskyOrdering ordering) {
  cholmod_common& c = solver.cholmod();
  switch (ordering) {
    case CholeskyOrdering::Cholmod: return;
    case CholeskyOrdering::Amd:
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_AMD;
      return;
    case CholeskyOrdering::Metis:
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_METIS;
      return;
  }
}

/// a.b, summed in the same order on every run (parallel_deterministic_reduce): a solve
/// repeated on the same system takes the same iterations to the same bits.
double parallelDot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<Eigen::Index>(0, a.size(), 8192), 0.0,
      [&](const tbb::blocked_range<Eigen::Index>& r, double s) {
        return s + a.segment(r.begin(), r.size()).dot(b.segment(r.begin(), r.size()));
      },
      std::plus<double>());
}

}  // namespace

void symmetricProduct(const SpMat& matrix, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  y.resize(matrix.rows());
  const int* outer = matrix.outerIndexPtr();
  const int* inner = matrix.innerIndexPtr();
  const double* values = matrix.valuePtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, matrix.cols(), 512),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index c = r.begin(); c != r.end(); ++c) {
                        double s = 0.0;
                        for (int k = outer[c]; k < outer[c + 1]; ++k) s += values[k] * x[inner[k]];
                        y[c] = s;
                      }
                    });
}

SolverKind chooseSolver(std::size_t dofs, std::size_t nonzeros, const SolverOptions& options) {
  if (options.kind != SolverKind::Auto) return options.kind;
  const bool small = dofs <= options.directLimitDofs && nonzeros <= options.directLimitNonzeros;
  return small ? SolverKind::Cholesky : SolverKind::ConjugateGradient;
}

SolverKind chooseSolver(const SpMat& matrix, const SolverOptions& options) {
  return chooseSolver(static_cast<std::size_t>(matrix.rows()),
                      static_cast<std::size_t>(matrix.nonZeros()), options);
}

struct LinearSolver::Impl {
  SolverOptions options;
  SolverKind kind = SolverKind::Auto;
  const SpMat* matrix = nullptr;
  int blockSize = 0;
  double factorSeconds = 0.0;
  std::unique_ptr<Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower>> cholesky;
  /// Block-Jacobi: the inverse of element b's diagonal block at b bs^2, column-major, in one
  /// array (no allocation per element), applied by addDenseProduct() like the smoother's.
  std::vector<double> blockInverses;
  CgPreconditioner preconditioner = CgPreconditioner::BlockJacobi;
  PMultigrid multigrid;
  /// K by element block rows in double precision for CG's product: two thirds of the CSR
  /// matrix's bytes (no index per entry), when the blocks hold no more values than it has
  /// nonzeros.
  BlockRows<double> productBlocks;
  bool useProductBlocks = false;
  /// K given by block rows alone (compute(const BlockRows<double>&)): the caller's, the one
  /// copy of K, read by the product and the smoother; `matrix` is then null.
  const BlockRows<double>* rows = nullptr;
  bool rowsRewritten = false;  ///< computeForUpdates(): the preconditioner keeps its own copy

  const BlockRows<double>* productRows() const {
    return rows ? rows : useProductBlocks ? &productBlocks : nullptr;
  }

  /// setAddedTerms(): added to the product.
  const SpMat* added = nullptr;

  /// y = K x (+ T x); returns x.y.
  double productDot(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    double dot = matrixProductDot(x, y);
    if (added) {
      const Eigen::VectorXd t = *added * x;
      y += t;
      dot += x.dot(t);
    }
    return dot;
  }

  /// y = K x; returns x.y. One pass (and one hand-off between threads) with the block rows.
  double matrixProductDot(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    const BlockRows<double>* blocks = productRows();
    if (!blocks) {
      symmetricProduct(*matrix, x, y);
      return parallelDot(x, y);
    }
    y.resize(x.size());
    const int ne = static_cast<int>(x.size() / blockSize);
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<int>(0, ne, 64), 0.0,
        [&](const tbb::blocked_range<int>& r, double sum) {
          for (int e = r.begin(); e != r.end(); ++e) {
            const Eigen::Index base = static_cast<Eigen::Index>(e) * blockSize;
            blocks->rowProduct(e, x.data(), y.data() + base);
            sum += x.segment(base, blockSize).dot(y.segment(base, blockSize));
          }
          return sum;
        },
        std::plus<double>());
  }

  /// The basis degree p with blockSize = 3 numMonomials(p), or -1.
  int degreeOfBlock() const {
    for (int p = 0; p <= 3; ++p)
      if (blockSize == 3 * numMonomials(p)) return p;
    return -1;
  }

  bool buildPreconditioner(const ElementFrames* frames) {
    useProductBlocks = blockSize % 3 == 0 && productBlocks.build(*matrix, blockSize / 3, 1.0);
    preconditioner = options.preconditioner;
    const int degree = degreeOfBlock();
    if (preconditioner == CgPreconditioner::PMultigrid && degree >= 0)
      return multigrid.compute(*matrix, degree, useProductBlocks ? &productBlocks : nullptr,
                               frames);
    preconditioner = CgPreconditioner::BlockJacobi;
    return buildBlockJacobi();
  }

  bool computeFromRows(const BlockRows<double>& rows, const ElementFrames* frames);

  bool buildBlockJacobi() {
    const Eigen::Index nb = rows ? rows->elements() : matrix->rows() / blockSize;
    const auto bb = static_cast<std::size_t>(blockSize) * static_cast<std::size_t>(blockSize);
    blockInverses.resize(static_cast<std::size_t>(nb) * bb);
    std::atomic<bool> ok{true};
    tbb::parallel_for(Eigen::Index(0), nb, [&](Eigen::Index b) {
      const Eigen::Index base = b * blockSize;
      Eigen::MatrixXd block = Eigen::MatrixXd::Zero(blockSize, blockSize);
      if (rows)
        block = Eigen::Map<const Eigen::MatrixXd>(rows->diagonalBlock(static_cast<int>(b)),
                                                  blockSize, blockSize);
      else
        for (int c = 0; c < blockSize; ++c)
          for (SpMat::InnerIterator it(*matrix, base + c); it; ++it)
            if (it.row() >= base && it.row() < base + blockSize)
              block(it.row() - base, c) = it.value();
      Eigen::LLT<Eigen::MatrixXd> llt(block);
      if (llt.info() != Eigen::Success) {
        ok = false;
        block = block.diagonal().cwiseAbs().cwiseMax(1e-300).cwiseInverse().asDiagonal();
      } else {
        block = llt.solve(Eigen::MatrixXd::Identity(blockSize, blockSize));
      }
      std::copy(
          block.data(), block.data() + bb,
          blockInverses.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(b) * bb));
    });
    return ok;
  }

  void precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
    if (preconditioner == CgPreconditioner::PMultigrid) {
      multigrid.apply(r, z);
      return;
    }
    z.resize(r.size());
    const auto bb = static_cast<std::size_t>(blockSize) * static_cast<std::size_t>(blockSize);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blockInverses.size() / bb, 64),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t b = range.begin(); b != range.end(); ++b) {
                          const Eigen::Index base = static_cast<Eigen::Index>(b) * blockSize;
                          z.segment(base, blockSize).setZero();
                          addDenseProduct(blockSize, blockInverses.data() + b * bb, r.data() + base,
                                          z.data() + base);
                        }
                      });
  }

  Eigen::VectorXd conjugateGradient(const Eigen::VectorXd& f, LinearSolveReport& report,
                                    const Eigen::VectorXd* guess, double tolerance,
                                    int maxIterations) const {
    const double fNorm = std::sqrt(parallelDot(f, f));
    Eigen::VectorXd u = Eigen::VectorXd::Zero(f.size());
    if (!std::isfinite(fNorm)) {  // else an infinite target would pass u = 0 as converged
      report.success = false;
      return u;
    }
    if (fNorm == 0.0) {
      report.success = true;
      return u;
    }
    Eigen::VectorXd r = f, z, p, q;
    if (guess && guess->size() == f.size()) {  // warm start: r = f - K u0
      u = *guess;
      productDot(u, q);
      r -= q;
    }
    precondition(r, z);
    p = z;
    double rz = parallelDot(r, z);
    const double target = tolerance * fNorm;
    int it = 0;
    double rNorm = std::sqrt(parallelDot(r, r));
    report.initialResidual = rNorm / fNorm;
    while (it < maxIterations && rNorm > target) {
      ++it;
      const double alpha = rz / productDot(p, q);
      // u += alpha p, r -= alpha q and |r|^2 in one pass.
      rNorm = std::sqrt(tbb::parallel_deterministic_reduce(
          tbb::blocked_range<Eigen::Index>(0, u.size(), 8192), 0.0,
          [&](const tbb::blocked_range<Eigen::Index>& range, double sum) {
            const Eigen::Index first = range.begin(), size = range.size();
            u.segment(first, size) += alpha * p.segment(first, size);
            r.segment(first, size) -= alpha * q.segment(first, size);
            return sum + r.segment(first, size).squaredNorm();
          },
          std::plus<double>()));
      if (rNorm <= target) break;  // converged: no preconditioner for a next step
      precondition(r, z);
      const double rzNew = parallelDot(r, z);
      p = z + (rzNew / rz) * p;
      rz = rzNew;
    }
    report.iterations = it;
    report.success = rNorm <= target;
    return u;
  }
};

LinearSolver::LinearSolver(const SolverOptions& options, MatrixTerms terms)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->multigrid = PMultigrid(terms);
}
LinearSolver::~LinearSolver() = default;
LinearSolver::LinearSolver(LinearSolver&&) noexcept = default;
LinearSolver& LinearSolver::operator=(LinearSolver&&) noexcept = default;

SolverKind LinearSolver::kind() const { return impl_->kind; }

const PMultigrid* LinearSolver::multigrid() const {
  const Impl& m = *impl_;
  return m.kind == SolverKind::ConjugateGradient &&
                 m.preconditioner == CgPreconditioner::PMultigrid && m.multigrid.levels() > 0
             ? &m.multigrid
             : nullptr;
}

bool LinearSolver::compute(const SpMat& matrix, int blockSize, const ElementFrames* frames) {
  Impl& m = *impl_;
  m.added = nullptr;
  m.matrix = &matrix;
  m.rows = nullptr;
  m.blockSize = blockSize;
  m.kind = chooseSolver(matrix, m.options);
  const Stopwatch t0;
  bool ok = true;
  if (m.kind == SolverKind::Cholesky) {
    m.cholesky = std::make_unique<Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower>>();
    silence(*m.cholesky);
    setOrdering(*m.cholesky, m.options.ordering);
    m.cholesky->compute(matrix);
    ok = m.cholesky->info() == Eigen::Success;
  } else {
    ok = m.buildPreconditioner(frames);
  }
  m.factorSeconds = t0.seconds();
  return ok;
}

bool LinearSolver::compute(const BlockRows<double>& rows, const ElementFrames* frames) {
  impl_->rowsRewritten = false;
  return impl_->computeFromRows(rows, frames);
}

bool LinearSolver::computeForUpdates(const BlockRows<double>& rows, const ElementFrames* frames) {
  impl_->rowsRewritten = true;
  return impl_->computeFromRows(rows, frames);
}

bool LinearSolver::Impl::computeFromRows(const BlockRows<double>& rows,
                                         const ElementFrames* frames) {
  Impl& m = *this;
  m.added = nullptr;
  if (m.options.kind == SolverKind::Cholesky)
    throw std::invalid_argument(
        "LinearSolver::compute: block rows are for conjugate gradients; Cholesky needs the "
        "CSR matrix");
  m.matrix = nullptr;
  m.rows = &rows;
  m.useProductBlocks = false;
  m.productBlocks = BlockRows<double>{};
  m.blockSize = rows.bs;
  m.kind = SolverKind::ConjugateGradient;
  m.preconditioner = m.options.preconditioner;
  const Stopwatch t0;
  bool ok = true;
  const int degree = m.degreeOfBlock();
  if (m.preconditioner == CgPreconditioner::PMultigrid && degree >= 0) {
    ok = m.rowsRewritten ? m.multigrid.computeCopy(rows, degree, frames)
                         : m.multigrid.compute(rows, degree, frames);
  } else {
    m.preconditioner = CgPreconditioner::BlockJacobi;
    ok = m.buildBlockJacobi();
  }
  m.factorSeconds = t0.seconds();
  return ok;
}

bool LinearSolver::update(const SpMat& matrix, bool refreshPreconditioner,
                          const ElementFrames* frames) {
  Impl& m = *impl_;
  if (m.rows)
    throw std::invalid_argument("LinearSolver::update: the solver was computed from block rows");
  if (!m.matrix) return compute(matrix, m.blockSize, frames);
  if (matrix.rows() != m.matrix->rows() || matrix.nonZeros() != m.matrix->nonZeros())
    throw std::invalid_argument("LinearSolver::update: the matrix has another pattern");
  m.matrix = &matrix;
  const Stopwatch t0;
  bool ok = true;
  if (m.kind == SolverKind::Cholesky) {
    m.cholesky->factorize(matrix);  // the symbolic analysis (ordering, supernodes) is kept
    ok = m.cholesky->info() == Eigen::Success;
  } else if (refreshPreconditioner) {
    ok = m.buildPreconditioner(frames);
  } else if (m.useProductBlocks) {
    m.useProductBlocks = m.productBlocks.build(matrix, m.blockSize / 3, 1.0);
  }
  m.factorSeconds = t0.seconds();
  return ok;
}

bool LinearSolver::update(const BlockRows<double>& rows, bool refreshPreconditioner,
                          const ElementFrames* frames) {
  Impl& m = *impl_;
  if (m.rows != &rows || !m.rowsRewritten)
    throw std::invalid_argument("LinearSolver::update: not the rows given to computeForUpdates()");
  if (!refreshPreconditioner) {
    m.factorSeconds = 0.0;
    return true;
  }
  return m.computeFromRows(rows, frames);
}

void LinearSolver::setAddedTerms(const SpMat* terms) {
  if (terms && impl_->kind == SolverKind::Cholesky)
    throw std::invalid_argument(
        "LinearSolver::setAddedTerms: Cholesky factorized the matrix alone");
  impl_->added = terms;
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& rhs, LinearSolveReport& report) {
  return solve(rhs, report, nullptr);
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& rhs, LinearSolveReport& report,
                                    const Eigen::VectorXd* guess, double tolerance,
                                    int maxIterations) {
  Impl& m = *impl_;
  report = LinearSolveReport{};
  report.used = m.kind;
  report.preconditioner = m.preconditioner;
  report.factorSeconds = m.factorSeconds;
  const Stopwatch t0;
  Eigen::VectorXd u;
  if (m.kind == SolverKind::Cholesky) {
    report.success = m.cholesky && m.cholesky->info() == Eigen::Success;
    u = report.success ? Eigen::VectorXd(m.cholesky->solve(rhs))
                       : Eigen::VectorXd::Zero(rhs.size());
  } else {
    u = m.conjugateGradient(rhs, report, guess, tolerance > 0.0 ? tolerance : m.options.tolerance,
                            maxIterations > 0 ? std::min(maxIterations, m.options.maxIterations)
                                              : m.options.maxIterations);
  }
  report.solveSeconds = t0.seconds();
  if (!u.allFinite()) report.success = false;  // overflowed: loads too large for the matrix
  Eigen::VectorXd ku;
  m.productDot(u, ku);
  const double fNorm = rhs.norm();
  report.residual = fNorm > 0.0 ? (rhs - ku).norm() / fNorm : (ku).norm();
  return u;
}

Eigen::VectorXd solveLinearSystem(const SpMat& matrix, const Eigen::VectorXd& rhs, int blockSize,
                                  const SolverOptions& options, LinearSolveReport& report) {
  LinearSolver solver(options);
  solver.compute(matrix, blockSize);
  return solver.solve(rhs, report);
}

bool isPositiveDefinite(const SpMat& matrix) {
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> llt;
  silence(llt);
  llt.compute(matrix);
  return llt.info() == Eigen::Success;
}

}  // namespace polydg
