// Time integration of DG elasticity (Kaufmann et al. 2008, sections 5 and 7; Kaufmann 2013,
// sections 4.2.2 and 4.4): M U'' + D U' + f(U) = F(t) with the consistent mass matrix from the
// exact moments, Rayleigh damping D = alpha M + beta K, and the elastic force f either linear,
// f = K U, or corotated (stiffness warping generalized to DG, section 7).
//
// Corotation. Every element K gets the rotation R_K of the polar decomposition of its mean
// deformation gradient I + (1/|K|) int_K grad u (for the non-nodal bases the linear part of the
// displacement). The stiffness is split by the element whose strain each term holds
// (splitLocalMatrices(): K_K and K_f1, K_f2 split by side, the penalty K_f3 apart); a block B of
// rows A, columns C with strain of element S acts as R_S B (R_S^T X_C - X0_C), the penalty as
// B (X_C - X0_C), where X = X0 + U are the coefficients of the deformed positions and X0 those of
// the undeformed ones (x - o, o the body's reference point: the identity map, exact in every
// element's linear functions). A rigid motion of the whole body thus gives no elastic force.
//
// Time stepping, one linear solve per step (the paper's semi-implicit scheme: rotations and the
// warped stiffness K_w of the step's start, f(U_{n+1}) ~ f(U_n) + K_w (U_{n+1} - U_n)):
//   backward Euler, eq. (4.12) of the thesis:
//     (M + dt D + dt^2 K_w) V_{n+1} = M V_n + dt (F_{n+1} - f(U_n)),  U_{n+1} = U_n + dt V_{n+1};
//   BDF2, c = 2 dt / 3:
//     (M + c D + c^2 K_w) V_{n+1} = M (4 V_n - V_{n-1}) / 3
//                                   + c (F_{n+1} - f(U_n) - K_w (U_n - U_{n-1}) / 3),
//     U_{n+1} = (4 U_n - U_{n-1}) / 3 + c V_{n+1};
//   Newmark, beta = 1/4, gamma = 1/2 (the trapezoidal rule: second order, no numerical damping,
//   energy conserving for the linear model):
//     (M + dt/2 D + dt^2/4 K_w) A_{n+1} = F_{n+1} - f(U_n) - D (V_n + dt/2 A_n)
//                                        - K_w (dt V_n + dt^2/4 A_n).
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "physics/contact/contact.h"
#include "physics/solvers/static_solver.h"
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
  /// p-multigrid once a solve needs more than 80 iterations; false: solver.preconditioner.
  bool adaptivePreconditioner = true;
  bool corotational = true;
  TimeIntegrator integrator = TimeIntegrator::BackwardEuler;
  double dt = 0.01;
  double massDamping = 0.0;       ///< Rayleigh alpha: D = alpha M + beta K
  double stiffnessDamping = 0.0;  ///< Rayleigh beta
  /// CG with corotation: the step's matrix changes with the rotations; the preconditioner of
  /// an earlier matrix is kept until a step needs more than this many times the iterations of
  /// the first step after it was built, then rebuilt (a rebuild costs several iterations).
  double refreshRatio = 1.5;
  /// Corotation: solves per step. 1 is the paper's semi-implicit step (forces linearized once,
  /// at the step's start): right for backward Euler, whose step then keeps a spinning body's
  /// angular momentum (B7: 1e-5 in a turn), but not for the second-order integrators, whose
  /// once-linearized steps gain energy with fast rotations (B7: +28% angular momentum in a
  /// turn). Further solves correct the force at the last solution's state with the same matrix
  /// (modified Newton). 0: automatic, 1 for backward Euler, and for BDF2 and Newmark as many as
  /// it takes for the relative correction to fall below correctionTolerance (at most 12; B7:
  /// angular momentum kept to 4e-4 with Newmark).
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
  ~DynamicSolver();
  DynamicSolver(DynamicSolver&&) noexcept;
  DynamicSolver& operator=(DynamicSolver&&) noexcept;

  const DgBasis& basis() const;
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

  /// Advances one step of options().dt. Throws std::runtime_error if the step's system is not
  /// positive definite or CG does not converge.
  StepReport step();

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

/// The rotation of the polar decomposition F = R S (det R = +1; for det F <= 0 the closest
/// rotation, flipping the direction of the smallest singular value).
Eigen::Matrix3d polarRotation(const Eigen::Matrix3d& f);

}  // namespace polydg
