// Static linear elasticity on a tet mesh (linear FEM or FS-FEM, physics/fem/tet_discretization.h):
// clamped nodes with prescribed displacements, a body force and nodal forces, solved with the
// DG solves' linear solver (CHOLMOD, or CG on large systems).
#pragma once

#include <vector>

#include "physics/fem/tet_discretization.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

struct TetStaticProblem {
  Material material;
  /// Body force per volume (density times gravity, say).
  Eigen::Vector3d bodyForce = Eigen::Vector3d::Zero();
  /// Node-major nodal forces (empty: none).
  Eigen::VectorXd nodalForces;
  /// Nodes held, and the displacements they are given (node-major, read at the held nodes;
  /// empty: zero).
  std::vector<std::uint32_t> clamped;
  Eigen::VectorXd prescribed;
};

struct TetStaticSolution {
  Eigen::VectorXd displacement;  ///< node-major
  double strainEnergy = 0.0;     ///< u^T K u / 2
  std::size_t nonzeros = 0;      ///< stored entries of the free DOFs' matrix
  LinearSolveReport solve;
};

/// Solves K u = f on the free nodes, u given on the clamped ones. Throws std::invalid_argument
/// if no node is clamped (the rigid motions would be free) and std::runtime_error if the solve
/// fails.
TetStaticSolution solveTetStatic(const TetDiscretization& discretization,
                                 const TetStaticProblem& problem,
                                 const SolverOptions& options = {});

}  // namespace polydg
