#include "physics/fem/tet_static.h"

#include <stdexcept>

#include "physics/solvers/linear_solver.h"

namespace polydg {

TetStaticSolution solveTetStatic(const TetDiscretization& discretization,
                                 const TetStaticProblem& problem, const SolverOptions& options) {
  if (problem.clamped.empty())
    throw std::invalid_argument("a static solve needs clamped nodes; none are");
  const auto n = static_cast<Eigen::Index>(discretization.numDofs());
  const Eigen::SparseMatrix<double> k = discretization.stiffness(problem.material);
  Eigen::VectorXd f = discretization.bodyForceLoad(problem.bodyForce);
  if (problem.nodalForces.size() == n) f += problem.nodalForces;

  // Prescribed displacements on the clamped nodes; the free DOFs numbered in order.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  std::vector<char> held(static_cast<std::size_t>(n), 0);
  if (problem.prescribed.size() != 0 && problem.prescribed.size() != n)
    throw std::invalid_argument("prescribed displacements must be given for every node");
  for (std::uint32_t v : problem.clamped) {
    if (3 * static_cast<Eigen::Index>(v) + 2 >= n)
      throw std::invalid_argument("a clamped node is not a node of the mesh");
    for (int c = 0; c < 3; ++c) held[3 * v + c] = 1;
    if (problem.prescribed.size() == n) u.segment<3>(3 * v) = problem.prescribed.segment<3>(3 * v);
  }
  std::vector<Eigen::Index> freeIndex(static_cast<std::size_t>(n), -1);
  Eigen::Index free = 0;
  for (Eigen::Index i = 0; i < n; ++i)
    if (!held[i]) freeIndex[i] = free++;
  const Eigen::VectorXd load = f - k * u;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(k.nonZeros()));
  for (Eigen::Index col = 0; col < k.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it)
      if (freeIndex[it.row()] >= 0 && freeIndex[col] >= 0)
        triplets.emplace_back(static_cast<int>(freeIndex[it.row()]),
                              static_cast<int>(freeIndex[col]), it.value());
  Eigen::SparseMatrix<double> kf(free, free);
  kf.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd rhs(free);
  for (Eigen::Index i = 0; i < n; ++i)
    if (freeIndex[i] >= 0) rhs[freeIndex[i]] = load[i];

  TetStaticSolution out;
  out.nonzeros = static_cast<std::size_t>(kf.nonZeros());
  // The p-multigrid needs the DG basis's layout: CG on nodes takes block Jacobi on the nodes'
  // 3 x 3 blocks (a node is held or free as a whole).
  SolverOptions solver = options;
  solver.preconditioner = CgPreconditioner::BlockJacobi;
  const Eigen::VectorXd uf = solveLinearSystem(kf, rhs, 3, solver, out.solve);
  if (!out.solve.success)
    throw std::runtime_error(
        "the tet static solve failed (the stiffness is not positive "
        "definite on the free nodes); clamp enough nodes");
  for (Eigen::Index i = 0; i < n; ++i)
    if (freeIndex[i] >= 0) u[i] = uf[freeIndex[i]];
  out.strainEnergy = 0.5 * u.dot(k * u);
  out.displacement = std::move(u);
  return out;
}

}  // namespace polydg
