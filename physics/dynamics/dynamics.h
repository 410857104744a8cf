// A moving elastic body: M U'' + D U' + f(U) = F(t) for DG elasticity (Kaufmann et al. 2008,
// sections 5 and 7; Kaufmann 2013, sections 4.2.2 and 4.4), with the consistent mass matrix
// from the exact moments (mass_matrix.h), Rayleigh damping D = alpha M + beta K, and the elastic
// force either linear, f = K U, or corotated (stiffness warping generalized to DG:
// corotation.h). DynamicSolver holds the mechanics and the state; a TimeIntegrator
// (time_integrators.h: backward Euler, BDF2, Newmark) advances it. Each step is the paper's
// semi-implicit step: rotations and the warped stiffness K_w of the step's start,
// f(U_{n+1}) ~ f(U_n) + K_w (U_{n+1} - U_n), one linear solve (further ones correct the force
// for the second-order integrators), with the contact terms of physics/contact/ if any.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "physics/contact/contact.h"
#include "physics/dg/assembly.h"
#include "polydg/physics/dg/discretization.h"
#include "polydg/physics/dg/loads.h"
#include "polydg/physics/dynamics/motion.h"

namespace polydg {

/// What acts on a moving body: clamps (u = 0, weakly), tractions and gravity.
struct DynamicLoads {
  std::vector<FaceSelector> clamps;
  std::vector<TimedTraction> tractions;
  Vec3 gravity = Vec3::Zero();
};

struct DynamicsOptions {
  Material material;
  DiscretizationOptions discretization;  ///< method, basis degree, penalty
  /// The step's solver. CG's tolerance is 1e-8 here (relative to the right-hand side, which
  /// the momentum M V dominates: 1e-8 of the velocity per step), not the static 1e-10.
  SolverOptions solver = [] {
    SolverOptions s;
    s.tolerance = 1e-8;
    return s;
  }();
  /// CG: start with the block-Jacobi preconditioner (a step's matrix M + c K is dominated by
  /// the mass for small steps, where its iterations are few and cheap) and switch to the
  /// p-multigrid once a solve needs more than 50 iterations; false: solver.preconditioner.
  bool adaptivePreconditioner = true;
  bool corotational = true;
  Integrator integrator = Integrator::BackwardEuler;
  RayleighDamping damping;  ///< D = alpha M + beta K
  /// CG with corotation: the step's matrix changes with the rotations; the preconditioner of
  /// an earlier matrix is kept until a step needs more than this many times the iterations of
  /// the first step after it was built, then rebuilt (a rebuild costs several iterations).
  double refreshRatio = 1.5;
  /// Corotation: solves per step. 1 is the paper's semi-implicit step (forces linearized once,
  /// at the step's start): right for backward Euler, whose step then keeps a spinning body's
  /// angular momentum, but not for the second-order integrators, whose once-linearized steps
  /// gain energy in fast rotations (B7 in docs/benchmarks.md). Further solves correct the force
  /// at the last solution's state with the same matrix (modified Newton). 0: automatic, the
  /// integrator's (1 for backward Euler; for BDF2 and Newmark as many as it takes for the
  /// relative correction, or the correction times the rate at which corrections shrink,
  /// measured on earlier ones, to fall below correctionTolerance; at most 12).
  int corotationSolves = 0;
  double correctionTolerance = 1e-6;
};

/// A moving elastic body on a fixed mesh. Holds the bases, the split element and face blocks,
/// the mass, the load vectors and the solver; steps the state (U, V, A) in time. One thread at
/// a time, const members included: the rotations and force of the current displacement are
/// kept for the next step.
class DynamicSolver {
 public:
  /// `mesh` and `moments` (up to date, degree >= 2p) must outlive the solver. Throws
  /// std::invalid_argument for bad options and InputError-worthy selections are the caller's.
  DynamicSolver(const PolyMesh& mesh, const MomentCache& moments, const DynamicLoads& loads,
                const DynamicsOptions& options);
  /// The same after an edit of the mesh `before` was made for, `changed[e]` set for every
  /// element of `mesh` the edit made, moved or changed (its id, shape or faces not those of
  /// before). The split element and face blocks of the others are taken over from `before`
  /// (updateSplitLocalMatrices(): those of elements next to a changed one are computed again),
  /// so that the work grows with the edit, not the body; `before` is emptied and must not be
  /// used again. Its state is not carried over (setState()).
  DynamicSolver(const PolyMesh& mesh, const MomentCache& moments, const DynamicLoads& loads,
                const DynamicsOptions& options, DynamicSolver&& before,
                const std::vector<char>& changed);
  ~DynamicSolver();
  DynamicSolver(DynamicSolver&&) noexcept;
  DynamicSolver& operator=(DynamicSolver&&) noexcept;

  const DgBasis& basis() const;
  /// The elements whose blocks the solver computed when it was made: all, or after an edit
  /// those the edit changed and their neighbours.
  std::size_t elementsComputed() const;
  /// The solver the steps use (known after the first step; Auto before).
  SolverKind solverKind() const;
  const DynamicsOptions& options() const;
  std::size_t dofs() const;
  double time() const;
  const Eigen::VectorXd& displacement() const;
  const Eigen::VectorXd& velocity() const;
  /// Boundary faces each clamp and each traction selected.
  const std::vector<std::size_t>& clampFaces() const;
  const std::vector<std::size_t>& tractionFaces() const;
  /// The undeformed body's centre of mass: the origin o of X0 and of angular momenta.
  const Vec3& referencePoint() const;
  double mass() const;

  /// Sets time, displacement and velocity (Newmark's acceleration then follows from the
  /// equation of motion). Throws std::invalid_argument for vectors of the wrong size.
  void setState(double t, const Eigen::VectorXd& displacement, const Eigen::VectorXd& velocity);

  /// Collisions for the following steps (physics/contact/contact.h), or none (null). The model must
  /// outlive its use and have this solver's DOF layout (make it again after a cut).
  void setContact(ContactModel* contact);
  /// The preconditioner CG's steps use now (block-Jacobi first, then the p-multigrid once a
  /// step needs many iterations; DynamicsOptions::adaptivePreconditioner).
  CgPreconditioner preconditioner() const;
  /// Steps start with `preconditioner` if it is the p-multigrid: for the solver of a mesh a cut
  /// edited, whose solver before had switched to it.
  void startWith(CgPreconditioner preconditioner);

  /// Advances one step of length dt (positive: the caller's to check, where it reads it) with
  /// the options' integrator. Throws std::runtime_error if the step's system is not positive
  /// definite or CG does not converge.
  StepReport step(double dt);

  /// Energies, momenta and centre of mass of the current state.
  BodyState state() const;
  /// f(U): the elastic force of the current displacement (warped if corotational).
  Eigen::VectorXd elasticForce() const;
  /// The external force F(t) at time t (gravity and the tractions in force).
  Eigen::VectorXd externalForce(double t) const;
  /// Sum over elements of int_K det(I + grad u): the volume of the deformed body, each element
  /// by its own displacement.
  double deformedVolume() const;
  /// Coefficients of the affine field x -> b + A (x - c) (exact in every element).
  Eigen::VectorXd affineField(const Eigen::Matrix3d& a, const Vec3& b, const Vec3& c) const;
  /// The current rotation R_K of every element (the identity without corotation).
  std::vector<Eigen::Matrix3d> rotations() const;
  /// Von Mises stress of every element from its mean deformation gradient F: of the strain
  /// sym(R^T F) - I in the element's rotated frame with corotation, of sym(F) - I without.
  std::vector<double> vonMises() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace polydg
