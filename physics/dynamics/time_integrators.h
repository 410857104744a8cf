// Time integrators for M U'' + D U' + f(U) = F(t), each a small class behind one interface
// (as MFEM's ODESolver steps a TimeDependentOperator): init() with the starting state, then
// step(state, dt). The mechanics (mass, the corotated stiffness, forces, contact, the implicit
// solve) are the SecondOrderSystem's; an integrator only says which linear problem a step
// poses and how its solution advances the state.
#pragma once

#include <memory>

#include <Eigen/Core>

#include "polydg/physics/dynamics/motion.h"

namespace polydg {

/// A body's state at time t: the DG coefficients of its displacement, velocity and
/// acceleration (the acceleration is kept by integrators that need it: Newmark).
struct MotionState {
  double t = 0.0;
  Eigen::VectorXd u, v, a;
};

/// The linear problem of one implicit step, as an integrator poses it for its unknown x (the
/// velocity or the acceleration at the step's end t_{n+1} = `time`). The state x gives is
///   U_{n+1} = u0 + cU x,  V_{n+1} = v0 + cV x   (v0 empty: zero),
/// and x solves the equation of motion at t_{n+1}, scaled by forceScale, with the elastic force
/// linearized at U_n with the warped stiffness K_w of the step's start:
///   (cM M + cK K_w) x = rhs - forceScale f(U_n).
/// cM and cK include the Rayleigh damping D = alpha M + beta K_w; rhs holds everything but the
/// elastic (and contact) force.
struct ImplicitStep {
  double time = 0.0;
  double dt = 0.0;  ///< the step's length
  double cM = 1.0, cK = 0.0;
  double forceScale = 1.0;
  Eigen::VectorXd rhs;
  Eigen::VectorXd u0, v0;
  double cU = 0.0, cV = 0.0;
  Eigen::VectorXd guess;  ///< where the solve starts (warm start)
  /// With corotation, the solves of the step when DynamicsOptions::corotationSolves is 0: 1
  /// keeps the once-linearized force (the paper's semi-implicit step); more correct it at the
  /// last solution's state until the correction is small.
  int automaticSolves = 1;
};

/// The mechanics a time integrator steps: M U'' + D U' + f(U) = F(t).
class SecondOrderSystem {
 public:
  virtual ~SecondOrderSystem() = default;
  /// out = M x (the consistent mass matrix, block diagonal).
  virtual void massTimes(const Eigen::VectorXd& x, Eigen::VectorXd& out) const = 0;
  /// out = K_w x, the stiffness warped with the rotations of the current displacement.
  virtual void stiffnessTimes(const Eigen::VectorXd& x, Eigen::VectorXd& out) const = 0;
  /// F(t): gravity and the tractions in force at time t.
  virtual Eigen::VectorXd externalForce(double t) const = 0;
  /// Rayleigh damping D = alpha M + beta K_w: alpha and beta.
  virtual double massDamping() const = 0;
  virtual double stiffnessDamping() const = 0;
  /// M^-1 (F(t) - D V - f(U)) of `state`, the system's current state (the acceleration the
  /// equation of motion gives).
  virtual Eigen::VectorXd acceleration(const MotionState& state) const = 0;
  /// A step begins: the rotations and the elastic force f(U_n) of its start (which K_w and the
  /// right-hand side use), timed into `report`.
  virtual void beginStep(StepReport& report) = 0;
  /// Solves `step` (with the corrections of the corotated force and the passes of the contact
  /// active set) and returns x; adds its iterations, solves and times to `report`. Throws
  /// std::runtime_error if the step's matrix is not positive definite or CG fails.
  virtual Eigen::VectorXd solve(const ImplicitStep& step, StepReport& report) = 0;
};

/// Advances a SecondOrderSystem in time, one step of length dt at a time.
class TimeIntegrator {
 public:
  virtual ~TimeIntegrator() = default;
  /// Starts from `state` (again after a cut or a refinement: history is forgotten).
  virtual void init(const SecondOrderSystem& system, MotionState& state) = 0;
  /// Advances `state` from t to t + dt (dt > 0, the caller's to check).
  virtual StepReport step(SecondOrderSystem& system, MotionState& state, double dt) = 0;

 protected:
  /// The warm start of a step's unknown, extrapolated from its last values: quadratically from
  /// three (a ninth fewer CG iterations than linearly on B10's beam, a sixth on B9's drop at
  /// 10x its elements), linearly from two, the last one alone after init(); remember()
  /// records the value before a step.
  Eigen::VectorXd guess(const Eigen::VectorXd& last) const;
  void remember(const Eigen::VectorXd& last);
  void forget() { remembered_ = 0; }

 private:
  Eigen::VectorXd previous_, beforePrevious_;
  int remembered_ = 0;  ///< of previous_ and beforePrevious_, those that hold a value
};

/// The integrator `kind` names.
std::unique_ptr<TimeIntegrator> makeTimeIntegrator(Integrator kind);

/// Backward Euler, eq. (4.12) of the thesis: (M + dt D + dt^2 K_w) V_{n+1} = M V_n +
/// dt (F_{n+1} - f(U_n)), U_{n+1} = U_n + dt V_{n+1}. First order, dissipative.
class BackwardEuler final : public TimeIntegrator {
 public:
  void init(const SecondOrderSystem& system, MotionState& state) override;
  StepReport step(SecondOrderSystem& system, MotionState& state, double dt) override;
};

/// BDF2 with c = 2 dt / 3: (M + c D + c^2 K_w) V_{n+1} = M (4 V_n - V_{n-1}) / 3 +
/// c (F_{n+1} - f(U_n) - K_w (U_n - U_{n-1}) / 3), U_{n+1} = (4 U_n - U_{n-1}) / 3 + c V_{n+1}.
/// Its first step (and the first after init() or a change of dt) is backward Euler.
class Bdf2 final : public TimeIntegrator {
 public:
  void init(const SecondOrderSystem& system, MotionState& state) override;
  StepReport step(SecondOrderSystem& system, MotionState& state, double dt) override;

 private:
  Eigen::VectorXd uPrevious_, vPrevious_;  ///< the state one step back
  double previousDt_ = 0.0;                ///< that step's length
  bool hasPrevious_ = false;
};

/// Newmark's average acceleration (beta = 1/4, gamma = 1/2): (M + dt/2 D + dt^2/4 K_w) A_{n+1} =
/// F_{n+1} - f(U_n) - D (V_n + dt/2 A_n) - K_w (dt V_n + dt^2/4 A_n). Second order, no numerical
/// damping: conserves the energy of the linear model.
class Newmark final : public TimeIntegrator {
 public:
  void init(const SecondOrderSystem& system, MotionState& state) override;
  StepReport step(SecondOrderSystem& system, MotionState& state, double dt) override;
};

}  // namespace polydg
