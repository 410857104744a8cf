// What a moving body's run is made of and reports: the time integrator, tractions in time,
// the figures of one step and of the body's state (physics/dynamics/dynamics.h steps it).
#pragma once

#include <cstddef>
#include <limits>

#include "polydg/physics/dg/loads.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

/// The time integrator of a moving body (physics/dynamics/time_integrators.h has the classes).
enum class Integrator {
  BackwardEuler,  ///< first order, dissipative: the paper's semi-implicit Euler
  /// Second-order backward differences (the first step is backward Euler): damps only the
  /// highest frequencies, so stays stable with the once-linearized corotated forces.
  Bdf2,
  /// Average acceleration (beta = 1/4, gamma = 1/2): second order, no numerical damping;
  /// conserves the energy of the linear model exactly. With corotation, whose forces are
  /// linearized once per step, fast rotations gain energy: prefer BDF2 there.
  Newmark,
};

/// Rayleigh damping D = mass M + stiffness K.
struct RayleighDamping {
  double mass = 0.0;
  double stiffness = 0.0;
};

/// A constant traction on a region of the boundary that acts while t <= until.
struct TimedTraction {
  FaceSelector where;
  Vec3 traction = Vec3::Zero();
  double until = std::numeric_limits<double>::infinity();
};

/// One time step. Times are wall seconds.
struct StepReport {
  double t = 0.0;                      ///< time at the step's end
  int iterations = 0;                  ///< CG iterations of all solves (0 with Cholesky)
  int solves = 1;                      ///< linear solves (corotation's corrections)
  double correction = 0.0;             ///< relative size of the last correction (0 if none)
  double residual = 0.0;               ///< relative residual of the step's solve
  bool refactorized = false;           ///< Cholesky: the matrix was factorized (numerically) again
  bool preconditionerRebuilt = false;  ///< CG: the preconditioner was rebuilt for this step
  /// CG: block-Jacobi reached its limit in this step and the p-multigrid went on
  bool preconditionerSwitched = false;
  CgPreconditioner preconditioner = CgPreconditioner::BlockJacobi;  ///< CG: the one used
  /// Polar decompositions. The rotations and the force of the step's start count here and in
  /// assemblySeconds also when state() computed them after the last step.
  double rotationSeconds = 0.0;
  double assemblySeconds = 0.0;  ///< warping the blocks, the system matrix, the forces
  double solveSeconds = 0.0;     ///< factorization or preconditioner, and the solve
  /// Of solveSeconds: the factorization (Cholesky) or the preconditioner's build (CG);
  /// microseconds for a step that kept them.
  double preconditionerSeconds = 0.0;
  /// Contact (setContact()): points in contact at the step's last pass, passes of the active
  /// set (solves of the step's matrix, each with its corrections), and the seconds spent in
  /// obstacle queries and point positions (also counted in assemblySeconds).
  std::size_t contacts = 0;
  int contactPasses = 0;
  double contactQuerySeconds = 0.0;
};

/// Energies and momenta of the current state. Energies are relative to the undeformed body at
/// rest: the elastic energy of the (warped) form, the gravitational -F_g . U, the work the
/// tractions in force did not yet count (-F_t . U).
struct BodyState {
  double kinetic = 0.0;
  double elastic = 0.0;
  double gravity = 0.0;
  double tractionPotential = 0.0;
  Vec3 momentum = Vec3::Zero();
  Vec3 angularMomentum = Vec3::Zero();  ///< about DynamicSolver::referencePoint()
  Vec3 centreOfMass = Vec3::Zero();     ///< of the deformed body
};

}  // namespace polydg
