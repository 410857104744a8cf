// A moving elastic body on a tet mesh by the tet methods (physics/fem/tet_discretization.h):
// linear (L-FEM, LFS-FEM) or corotational (C-FEM, CS-FEM) forces, lumped mass, Rayleigh damping,
// gravity, nodal loads in time and clamped nodes. The mechanics are a SecondOrderSystem, so the
// DG body's time integrators (physics/dynamics/time_integrators.h: backward Euler, BDF2,
// Newmark) step it unchanged; backward Euler with one solve per step is Zhang et al. 2017
// eq. 26 (Müller and Gross 2004).
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include "physics/fem/tet_discretization.h"
#include "polydg/physics/dynamics/motion.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

/// Nodal forces (node-major, the length of the DOFs) in force while t <= until.
struct TetLoad {
  Eigen::VectorXd force;
  double until = std::numeric_limits<double>::infinity();
};

struct TetDynamicsOptions {
  Material material;
  /// Warp the stiffness by rotations (per tet for FEM: C-FEM; per smoothing domain for FS-FEM:
  /// CS-FEM); false: linear forces (L-FEM, LFS-FEM).
  bool corotational = true;
  Integrator integrator = Integrator::BackwardEuler;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< acceleration
  double massDamping = 0.0;                           ///< Rayleigh alpha: C = alpha M + beta K
  double stiffnessDamping = 0.0;                      ///< Rayleigh beta
  std::vector<std::uint32_t> clamped;                 ///< nodes held at their rest positions
  std::vector<TetLoad> loads;
  /// Corotated steps of BDF2 and Newmark correct the once-linearized force (modified Newton
  /// at the step's matrix) until the relative change of the solution is below this; backward
  /// Euler solves once, as the paper.
  double correctionTolerance = 1e-6;
  /// The step's solver; CG's tolerance 1e-8 of the right-hand side (which the momentum M v
  /// dominates), as for the DG body (DynamicsOptions::solver), not the static 1e-10.
  SolverOptions solver = [] {
    SolverOptions s;
    s.tolerance = 1e-8;
    return s;
  }();
};

class TetDynamics {
 public:
  /// `discretization` must outlive this object. Throws std::invalid_argument for a clamped
  /// node that is not a node or a load of the wrong length.
  TetDynamics(const TetDiscretization& discretization, const TetDynamicsOptions& options);
  ~TetDynamics();

  /// Gives every free node the velocity of a rigid motion: v = linear + angular x (x - centre).
  void setRigidVelocity(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular,
                        const Eigen::Vector3d& centre);
  /// One step of dt with the options' integrator. For backward Euler: (M + dt C + dt^2 K_R) v'
  /// = M v + dt (f(x) + f_ext), x' = x + dt v', with K_R and the elastic force f(x) = offset -
  /// K_R x of the rotations at x (identity if linear). Throws std::runtime_error if the solve
  /// fails.
  StepReport step(double dt);

  double time() const;
  Eigen::VectorXd positions() const;  ///< node-major
  const Eigen::VectorXd& velocities() const;
  const Eigen::VectorXd& displacement() const;
  /// The deformed mesh's volume (the sum of its tets' signed volumes).
  double volume() const;
  double kineticEnergy() const;
  /// Energies (the elastic one of the warped form) and momenta of the current state, as the DG
  /// body reports them; the angular momentum about the rest centre of mass.
  BodyState state() const;
  double mass() const;
  /// The rest centre of mass.
  const Eigen::Vector3d& referencePoint() const;
  /// The solver the steps use (Cholesky or CG, once Auto has chosen at the first step).
  SolverKind solverKind() const;
  /// Seconds of the last step: rotations and assembly, and the solve.
  double assembleSeconds() const { return last_.rotationSeconds + last_.assemblySeconds; }
  double solveSeconds() const { return last_.solveSeconds; }

 private:
  class System;
  std::unique_ptr<System> system_;
  StepReport last_;
};

}  // namespace polydg
