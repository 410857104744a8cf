#include "physics/solvers/static_solver.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <Eigen/Geometry>

#include "physics/dg/block_rows.h"
#include "physics/solvers/agglomeration.h"
#include "util/format.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {
using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
/// Doubling gives up after this many factorizations (eta grows by 2^kMaxDoublings).
constexpr int kMaxDoublings = 40;
}  // namespace

StaticSolver::StaticSolver(const PolyMesh& mesh, const Material& material,
                           const StaticOptions& options, const MomentCache* moments)
    : mesh_(&mesh),
      material_(material),
      options_(options),
      moments_(moments),
      solver_(options.solver) {
  material_.check();
  const int needed = 2 * options.discretization.basis.degree;
  if (moments_ && moments_->degree() < needed)
    throw std::invalid_argument("StaticSolver: the moments are of degree " +
                                std::to_string(moments_->degree()) + ", the basis needs " +
                                std::to_string(needed));
}

void StaticSolver::integrate() {
  const Stopwatch t0;
  const int p = options_.discretization.basis.degree;
  if (moments_ == nullptr || ownMoments_) {
    ownMoments_ = std::make_unique<MomentCache>(*mesh_, 2 * p);
    report_.facesIntegrated = ownMoments_->update();
    moments_ = ownMoments_.get();
  }
  basis_ = std::make_unique<DgBasis>(*mesh_, *moments_, options_.discretization.basis);
  momentsSeconds_ = t0.seconds();
  report_.integrateSeconds = momentsSeconds_;
  report_.elements = mesh_->numElements();
  report_.basisFallbacks = basis_->fallbackElements();
}

void StaticSolver::assemble(const LoadCase& loads) {
  if (!basis_) integrate();
  const Stopwatch t0;
  const DiscretizationOptions& disc = options_.discretization;
  roles_ = classifyFaces(*mesh_, loads);
  report_.dirichletFaces = roles_.dirichletFaces;
  report_.tractionFaces = roles_.tractionFaces;
  penalties_ = std::make_unique<ElementPenalties>();
  form_ = formCoefficients(*mesh_, *basis_, *moments_, roles_, material_, disc, *penalties_,
                           report_.etaThreshold);
  const int quadrature =
      disc.quadratureDegree >= 0 ? disc.quadratureDegree : 2 * basis_->degree() + 2;
  system_.blockSize = 3 * basis_->size();
  factorized_ = false;
  report_.penaltyAttempts = 1;
  // The thesis's phases (Table 4.1): "integration" computes the element and face matrices,
  // "assembly" accumulates them into K and F. Without a penalty search, each element's rows
  // go straight into K by block rows (assembleBlockRows()): the two phases are one, timed as
  // integration, and K is kept once, 8 bytes per nonzero. A system small enough for Cholesky
  // is then converted to CSR (assembly); a larger one stays in blocks for CG.
  double localSeconds = 0.0;
  std::optional<Stopwatch> tAssemble;
  rows_.reset();
  system_.matrix = SpMat();
  if (disc.penalty.rule != PenaltyRule::Doubling) {
    rows_ = std::make_unique<BlockRows<double>>(
        assembleBlockRows(*mesh_, *basis_, *moments_, roles_, form_));
    localSeconds = t0.seconds();
    tAssemble.emplace();
    const std::size_t dofs = static_cast<std::size_t>(rows_->elements()) * rows_->bs;
    if (chooseSolver(dofs, rows_->entries(), options_.solver) == SolverKind::Cholesky) {
      SpMat matrix = rows_->toSparse();  // swapped in: Eigen 3.4's SpMat has no move assignment
      system_.matrix.swap(matrix);
      rows_.reset();
    }
  } else {
    LocalMatrices local = localMatrices(*mesh_, *basis_, *moments_, roles_, form_);
    localSeconds = t0.seconds();
    tAssemble.emplace();
    assembleInto(local, system_.matrix);
  }

  double searchSeconds = 0.0;
  if (disc.penalty.rule == PenaltyRule::Doubling) {
    SolverOptions direct = options_.solver;
    direct.kind = SolverKind::Cholesky;
    for (int attempt = 1;; ++attempt) {
      const Stopwatch ts;
      solver_ = LinearSolver(direct);
      const bool ok = solver_.compute(system_.matrix, system_.blockSize);
      searchSeconds += ts.seconds();
      report_.penaltyAttempts = attempt;
      if (ok) {
        factorized_ = true;
        break;
      }
      if (attempt == kMaxDoublings)
        throw std::runtime_error(
            "penalty doubling: the stiffness matrix is not positive "
            "definite even at eta = " +
            std::to_string(form_.eta) + "; is a Dirichlet condition missing?");
      form_.eta *= 2.0;
      assembleInto(localMatrices(*mesh_, *basis_, *moments_, roles_, form_), system_.matrix);
    }
  }
  report_.eta = form_.eta;
  report_.bzFactor = form_.bzFactor;
  system_.rhs =
      assembleLoad(*mesh_, *basis_, *moments_, roles_, form_, material_, loads, quadrature);
  report_.dofs = rows_ ? static_cast<std::size_t>(rows_->elements()) * rows_->bs
                       : static_cast<std::size_t>(system_.matrix.rows());
  report_.nonzeros = rows_ ? rows_->entries() : static_cast<std::size_t>(system_.matrix.nonZeros());
  // Trial factorizations belong to the solve phase; the one that succeeded is reused.
  report_.integrateSeconds = momentsSeconds_ + localSeconds;
  report_.assembleSeconds = tAssemble->seconds() - searchSeconds;
  report_.solveSeconds = searchSeconds;
}

void StaticSolver::assembleInto(const LocalMatrices& local,
                                Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix) const {
  // Eigen 3.4's SparseMatrix has no move assignment: assigning the returned matrix would copy
  // every nonzero (a third of the assembly time for p = 2); swap instead.
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> k = assembleStiffness(local);
  matrix.swap(k);
}

const Eigen::VectorXd& StaticSolver::solve() {
  if (!rows_ && system_.matrix.rows() == 0 && mesh_->numElements() > 0)
    throw std::logic_error("StaticSolver::solve: call assemble() first");
  const Stopwatch t0;
  if (!factorized_) {
    solver_ = LinearSolver(options_.solver);
    const bool direct =
        !rows_ && chooseSolver(system_.matrix, options_.solver) == SolverKind::Cholesky;
    // Cholesky and the p-multigrid's coarsest factorization detect an indefinite K; the
    // block-Jacobi preconditioner falls back to diagonals and lets CG report the failure.
    const bool definiteCheck =
        direct || options_.solver.preconditioner == CgPreconditioner::PMultigrid;
    // The element frames let the p-multigrid coarsen by agglomerating elements (the linear or
    // quadratic displacements of groups of elements, rotations included).
    const ElementFrames frames = direct ? ElementFrames{} : elementFrames(*basis_, *mesh_);
    const bool computed =
        rows_ ? solver_.compute(*rows_, &frames)
              : solver_.compute(system_.matrix, system_.blockSize, direct ? nullptr : &frames);
    if (!computed && definiteCheck) {
      // A fixed penalty below the coercivity bound is the likelier cause than a loose body.
      const PenaltyOptions& penalty = options_.discretization.penalty;
      if (penalty.rule == PenaltyRule::Fixed && penalty.eta && *penalty.eta < report_.etaThreshold)
        throw std::runtime_error(
            "the stiffness matrix is not positive definite: the fixed penalty eta = " +
            formatNumber(*penalty.eta) + " is below the bound " +
            formatNumber(report_.etaThreshold) +
            " that guarantees it; raise --eta or use --penalty bound");
      throw std::runtime_error(
          "the stiffness matrix is not positive definite: is every piece of the body held by a "
          "Dirichlet condition (e.g. --clamp)?");
    }
    factorized_ = true;
  }
  coefficients_ = solver_.solve(system_.rhs, report_.solver);
  report_.solveSeconds += t0.seconds();
  report_.energy = 0.5 * coefficients_.dot(system_.rhs);
  return coefficients_;
}

const LinearSystem& StaticSolver::system() const {
  if (rows_ && system_.matrix.rows() == 0) {
    SpMat matrix = rows_->toSparse();
    system_.matrix.swap(matrix);
  }
  return system_;
}

Eigen::VectorXd StaticSolver::stiffnessTimes(const Eigen::VectorXd& u) const {
  Eigen::VectorXd y;
  if (!rows_) {
    symmetricProduct(system_.matrix, u, y);
    return y;
  }
  y.resize(u.size());
  const int bs = rows_->bs;
  tbb::parallel_for(0, rows_->elements(), [&](int e) {
    rows_->rowProduct(e, u.data(), y.data() + static_cast<Eigen::Index>(e) * bs);
  });
  return y;
}

StaticSolution StaticSolver::release() {
  StaticSolution s;
  s.moments = std::move(ownMoments_);
  moments_ = nullptr;
  s.basis = std::move(basis_);
  s.coefficients = std::move(coefficients_);
  s.report = report_;
  return s;
}

StaticSolution solveStatic(const PolyMesh& mesh, const Material& material, const LoadCase& loads,
                           const StaticOptions& options, const MomentCache* moments) {
  StaticSolver solver(mesh, material, options, moments);
  solver.integrate();
  solver.assemble(loads);
  solver.solve();
  return solver.release();
}

}  // namespace polydg
