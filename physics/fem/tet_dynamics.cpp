#include "physics/fem/tet_dynamics.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "physics/solvers/linear_solver.h"
#include "util/stopwatch.h"

namespace polydg {

/// The step's matrix on the free DOFs (its pattern is the same every step) and the solver that
/// keeps its symbolic factorization or preconditioner layout.
struct TetDynamics::Solver {
  Eigen::SparseMatrix<double> matrix;
  LinearSolver linear;
  bool computed = false;
  /// Each domain's stiffness for the material: constant, only its rotation changes (Zhang et
  /// al. section 4.3: computed once, in preprocessing).
  std::vector<Eigen::MatrixXd> domainStiffness;
  /// Per domain, per node pair (a, b) and column c of the pair's 3 x 3 block: where the block's
  /// first row lies in the matrix's values (its 3 rows follow), or -1 when a node is held.
  std::vector<std::vector<int>> blockAt;
  std::vector<int> diagonalAt;  ///< per free DOF: its diagonal entry's place in the values
  explicit Solver(const SolverOptions& options) : linear(options) {}
};

namespace {

/// The place of entry (row, col) in a compressed column-major matrix, which must hold it.
int entryAt(const Eigen::SparseMatrix<double>& m, Eigen::Index row, Eigen::Index col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(begin, end, static_cast<int>(row));
  return static_cast<int>(at - m.innerIndexPtr());
}

}  // namespace

void TetDynamics::prepareAssembly() {
  Solver& s = *solver_;
  const auto& domains = discretization_.domains();
  // The pattern: every free node pair of a domain as a 3 x 3 block, and the diagonal.
  std::vector<Eigen::Triplet<double>> pattern;
  auto freeNode = [&](std::uint32_t v) { return freeIndex_[3 * v] >= 0 ? freeIndex_[3 * v] : -1; };
  for (const StrainDomain& d : domains)
    for (int a = 0; a < d.numNodes; ++a)
      for (int b = 0; b < d.numNodes; ++b) {
        const Eigen::Index fa = freeNode(d.nodes[a]), fb = freeNode(d.nodes[b]);
        if (fa < 0 || fb < 0) continue;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            pattern.emplace_back(static_cast<int>(fa + i), static_cast<int>(fb + j), 0.0);
      }
  for (Eigen::Index i = 0; i < numFree_; ++i)
    pattern.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.0);
  s.matrix.resize(numFree_, numFree_);
  s.matrix.setFromTriplets(pattern.begin(), pattern.end());
  s.matrix.makeCompressed();
  s.diagonalAt.resize(static_cast<std::size_t>(numFree_));
  for (Eigen::Index i = 0; i < numFree_; ++i) s.diagonalAt[i] = entryAt(s.matrix, i, i);
  s.domainStiffness.reserve(domains.size());
  s.blockAt.resize(domains.size());
  for (std::size_t i = 0; i < domains.size(); ++i) {
    const StrainDomain& d = domains[i];
    s.domainStiffness.push_back(discretization_.domainStiffness(d, options_.material));
    std::vector<int>& at = s.blockAt[i];
    at.assign(static_cast<std::size_t>(3 * d.numNodes * d.numNodes), -1);
    for (int a = 0; a < d.numNodes; ++a)
      for (int b = 0; b < d.numNodes; ++b) {
        const Eigen::Index fa = freeNode(d.nodes[a]), fb = freeNode(d.nodes[b]);
        if (fa < 0 || fb < 0) continue;
        for (int c = 0; c < 3; ++c)
          at[static_cast<std::size_t>(3 * (a * d.numNodes + b) + c)] =
              entryAt(s.matrix, fa, fb + c);
      }
  }
}

TetDynamics::TetDynamics(const TetDiscretization& discretization, const TetDynamicsOptions& options)
    : discretization_(discretization), options_(options) {
  options_.material.check();
  const auto n = static_cast<Eigen::Index>(discretization.numDofs());
  mass_ = discretization.lumpedMass(options.material.density);
  x_ = discretization.restPositions();
  v_ = Eigen::VectorXd::Zero(n);
  gravityLoad_ = discretization.bodyForceLoad(options.material.density * options.gravity);
  std::vector<char> held(static_cast<std::size_t>(n), 0);
  for (std::uint32_t node : options.clamped) {
    if (3 * static_cast<Eigen::Index>(node) + 2 >= n)
      throw std::invalid_argument("a clamped node is not a node of the mesh");
    for (int c = 0; c < 3; ++c) held[3 * node + c] = 1;
  }
  freeIndex_.assign(static_cast<std::size_t>(n), -1);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!held[i]) freeIndex_[i] = numFree_++;
  // The nodes' 3 x 3 blocks for CG (the p-multigrid needs the DG layout).
  options_.solver.preconditioner = CgPreconditioner::BlockJacobi;
  solver_ = std::make_unique<Solver>(options_.solver);
  prepareAssembly();
}

TetDynamics::~TetDynamics() = default;

void TetDynamics::setRigidVelocity(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular,
                                   const Eigen::Vector3d& centre) {
  for (Eigen::Index v = 0; v < x_.size() / 3; ++v)
    if (freeIndex_[3 * v] >= 0)
      v_.segment<3>(3 * v) = linear + angular.cross(Eigen::Vector3d(x_.segment<3>(3 * v)) - centre);
}

void TetDynamics::step(double dt) {
  if (!(dt > 0.0)) throw std::invalid_argument("the time step must be positive");
  const Stopwatch assemble;
  Solver& s = *solver_;
  const auto& domains = discretization_.domains();
  const std::vector<Eigen::Matrix3d> rotations =
      options_.corotational
          ? discretization_.domainRotations(discretization_.tetRotations(x_))
          : std::vector<Eigen::Matrix3d>(domains.size(), Eigen::Matrix3d::Identity());
  // The matrix (M (1 + dt alpha) + (dt^2 + dt beta) K_R on the free DOFs) and the elastic
  // force f(x) = offset - K_R x, domain by domain: with R its rotation, f_a = R sum_b K_ab
  // (X_b - R^T x_b) and the block of K_R is R K_ab R^T.
  const double alpha = options_.massDamping, beta = options_.stiffnessDamping;
  const double kScale = dt * dt + dt * beta, mScale = 1.0 + dt * alpha;
  double* values = s.matrix.valuePtr();
  std::fill(values, values + s.matrix.nonZeros(), 0.0);
  for (Eigen::Index i = 0; i < x_.size(); ++i)
    if (freeIndex_[i] >= 0) values[s.diagonalAt[freeIndex_[i]]] = mScale * mass_[i];
  const Eigen::VectorXd& rest = discretization_.restPositions();
  Eigen::VectorXd force = gravityLoad_;
  for (std::size_t i = 0; i < domains.size(); ++i) {
    const StrainDomain& d = domains[i];
    const Eigen::Matrix3d& r = rotations[i];
    const Eigen::MatrixXd& kd = s.domainStiffness[i];
    const std::vector<int>& at = s.blockAt[i];
    std::array<Eigen::Vector3d, 5> local;  // X_b - R^T x_b
    for (int b = 0; b < d.numNodes; ++b)
      local[b] = rest.segment<3>(3 * d.nodes[b]) - r.transpose() * x_.segment<3>(3 * d.nodes[b]);
    for (int a = 0; a < d.numNodes; ++a) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int b = 0; b < d.numNodes; ++b) {
        const Eigen::Matrix3d kab = kd.block<3, 3>(3 * a, 3 * b);
        sum += kab * local[b];
        const int* place = &at[static_cast<std::size_t>(3 * (a * d.numNodes + b))];
        if (place[0] < 0) continue;
        const Eigen::Matrix3d block = kScale * (r * kab * r.transpose());
        for (int c = 0; c < 3; ++c)
          for (int row = 0; row < 3; ++row) values[place[c] + row] += block(row, c);
      }
      force.segment<3>(3 * d.nodes[a]) += r * sum;
    }
  }
  // M v + dt (f(x) + f_ext): the stiffness damping's force at the new velocity is in the
  // matrix (dt beta K v').
  const Eigen::VectorXd full = mass_.cwiseProduct(v_) + dt * force;
  Eigen::VectorXd rhs(numFree_);
  for (Eigen::Index i = 0; i < x_.size(); ++i)
    if (freeIndex_[i] >= 0) rhs[freeIndex_[i]] = full[i];
  assembleSeconds_ = assemble.seconds();

  const Stopwatch solve;
  // The rotations change a little each step: CG keeps its block-Jacobi preconditioner fresh
  // (cheap), Cholesky keeps its symbolic analysis.
  const bool ok = s.computed ? s.linear.update(s.matrix, true) : s.linear.compute(s.matrix, 3);
  s.computed = true;
  LinearSolveReport report;
  Eigen::VectorXd free;
  if (ok) free = s.linear.solve(rhs, report);
  if (!ok || !report.success)
    throw std::runtime_error("the tet time step's solve failed; try a smaller dt");
  for (Eigen::Index i = 0; i < x_.size(); ++i)
    v_[i] = freeIndex_[i] >= 0 ? free[freeIndex_[i]] : 0.0;
  x_ += dt * v_;
  time_ += dt;
  solveSeconds_ = solve.seconds();
}

double TetDynamics::volume() const { return discretization_.volume(x_); }

double TetDynamics::kineticEnergy() const { return 0.5 * v_.dot(mass_.cwiseProduct(v_)); }

}  // namespace polydg
