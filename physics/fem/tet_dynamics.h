// A moving elastic body on a tet mesh by the tet methods (physics/fem/tet_discretization.h):
// linear (L-FEM, LFS-FEM) or corotational (C-FEM, CS-FEM) forces, lumped mass, Rayleigh damping,
// gravity and clamped nodes, stepped by linearized backward Euler as Zhang et al. 2017 eq. 26
// (Müller and Gross 2004).
#pragma once

#include <memory>
#include <vector>

#include "physics/fem/tet_discretization.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

struct TetDynamicsOptions {
  Material material;
  /// Warp the stiffness by rotations (per tet for FEM: C-FEM; per smoothing domain for FS-FEM:
  /// CS-FEM); false: linear forces (L-FEM, LFS-FEM).
  bool corotational = true;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< acceleration
  double massDamping = 0.0;                           ///< Rayleigh alpha: C = alpha M + beta K
  double stiffnessDamping = 0.0;                      ///< Rayleigh beta
  std::vector<std::uint32_t> clamped;                 ///< nodes held at their rest positions
  SolverOptions solver;
};

class TetDynamics {
 public:
  /// `discretization` must outlive this object.
  TetDynamics(const TetDiscretization& discretization, const TetDynamicsOptions& options);
  ~TetDynamics();

  /// Gives every free node the velocity of a rigid motion: v = linear + angular x (x - centre).
  void setRigidVelocity(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular,
                        const Eigen::Vector3d& centre);
  /// One step of dt: (M + dt C + dt^2 K_R) v' = M v + dt (f(x) + f_ext), x' = x + dt v', with
  /// K_R and the elastic force f(x) = offset - K_R x of the rotations at x (identity if linear).
  /// Throws std::runtime_error if the solve fails.
  void step(double dt);

  double time() const { return time_; }
  const Eigen::VectorXd& positions() const { return x_; }  ///< node-major
  const Eigen::VectorXd& velocities() const { return v_; }
  Eigen::VectorXd displacement() const { return x_ - discretization_.restPositions(); }
  /// The deformed mesh's volume (the sum of its tets' signed volumes).
  double volume() const;
  double kineticEnergy() const;
  /// Seconds of the last step: rotations and assembly, and the solve.
  double assembleSeconds() const { return assembleSeconds_; }
  double solveSeconds() const { return solveSeconds_; }

 private:
  const TetDiscretization& discretization_;
  TetDynamicsOptions options_;
  Eigen::VectorXd mass_, x_, v_, gravityLoad_;
  std::vector<Eigen::Index> freeIndex_;  ///< per DOF: its index among the free DOFs, or -1
  Eigen::Index numFree_ = 0;
  struct Solver;
  /// The step matrix's fixed pattern, where each domain's blocks go in it, and the domains'
  /// stiffness matrices.
  void prepareAssembly();
  std::unique_ptr<Solver> solver_;
  double time_ = 0.0, assembleSeconds_ = 0.0, solveSeconds_ = 0.0;
};

}  // namespace polydg
