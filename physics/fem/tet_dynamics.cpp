#include "physics/fem/tet_dynamics.h"

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
  explicit Solver(const SolverOptions& options) : linear(options) {}
};

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
  if (!options.corotational) linearK_ = discretization.stiffness(options.material);
  // The nodes' 3 x 3 blocks for CG (the p-multigrid needs the DG layout).
  options_.solver.preconditioner = CgPreconditioner::BlockJacobi;
  solver_ = std::make_unique<Solver>(options_.solver);
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
  // K_R and the elastic force offset - K_R x at the current positions.
  Eigen::SparseMatrix<double> k;
  Eigen::VectorXd offset;
  if (options_.corotational) {
    discretization_.corotatedStiffness(
        options_.material, discretization_.domainRotations(discretization_.tetRotations(x_)), k,
        offset);
  } else {
    k = linearK_;
    offset = linearK_ * discretization_.restPositions();
  }
  const double alpha = options_.massDamping, beta = options_.stiffnessDamping;
  const double kScale = dt * dt + dt * beta, mScale = 1.0 + dt * alpha;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(k.nonZeros() + numFree_));
  for (Eigen::Index col = 0; col < k.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it)
      if (freeIndex_[it.row()] >= 0 && freeIndex_[col] >= 0)
        triplets.emplace_back(static_cast<int>(freeIndex_[it.row()]),
                              static_cast<int>(freeIndex_[col]), kScale * it.value());
  for (Eigen::Index i = 0; i < x_.size(); ++i)
    if (freeIndex_[i] >= 0)
      triplets.emplace_back(static_cast<int>(freeIndex_[i]), static_cast<int>(freeIndex_[i]),
                            mScale * mass_[i]);
  Solver& s = *solver_;
  s.matrix.resize(numFree_, numFree_);
  s.matrix.setFromTriplets(triplets.begin(), triplets.end());
  // M v + dt (f(x) + f_ext - beta K v): the stiffness damping's force at the old velocity moves
  // to the left-hand side through dt beta K v'.
  const Eigen::VectorXd full = mass_.cwiseProduct(v_) + dt * (offset - k * x_ + gravityLoad_);
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
