#include "physics/dynamics/time_integrators.h"

#include <algorithm>

#include "util/stopwatch.h"

namespace polydg {

namespace {

constexpr double kNewmarkBeta = 0.25, kNewmarkGamma = 0.5;
/// Solves of a corotated step of a second-order integrator at most: their once-linearized
/// steps gain energy in fast rotations, and the corrections of SecondOrderSystem::solve() gain
/// one to two digits each (B7's spinning cube).
constexpr int kSecondOrderSolves = 12;

/// The coefficients of a step whose unknown x is the velocity at its end, V_{n+1}: U_{n+1} =
/// u0 + c x and (M + c D + c^2 K_w) x = rhs - c f(U_n), the form of backward Euler (c = dt) and
/// BDF2 (c = 2 dt / 3).
ImplicitStep velocityStep(const SecondOrderSystem& system, const MotionState& s, double dt,
                          double c) {
  ImplicitStep p;
  p.time = s.t + dt;
  p.dt = dt;
  p.cM = 1.0 + c * system.massDamping();
  p.cK = c * system.stiffnessDamping() + c * c;
  p.forceScale = c;
  p.cU = c;
  p.cV = 1.0;
  return p;
}

/// Backward Euler's right-hand side M V_n + dt F(t_{n+1}) and u0 = U_n.
void poseEuler(const SecondOrderSystem& system, const MotionState& s, ImplicitStep& p) {
  system.massTimes(s.v, p.rhs);
  p.rhs += p.dt * system.externalForce(p.time);
  p.u0 = s.u;
}

}  // namespace

Eigen::VectorXd TimeIntegrator::guess(const Eigen::VectorXd& last) const {
  if (remembered_ == 2) return Eigen::VectorXd(3.0 * (last - previous_) + beforePrevious_);
  return remembered_ == 1 ? Eigen::VectorXd(2.0 * last - previous_) : last;
}

void TimeIntegrator::remember(const Eigen::VectorXd& last) {
  beforePrevious_.swap(previous_);
  previous_ = last;
  remembered_ = std::min(remembered_ + 1, 2);
}

std::unique_ptr<TimeIntegrator> makeTimeIntegrator(Integrator kind) {
  switch (kind) {
    case Integrator::Bdf2: return std::make_unique<Bdf2>();
    case Integrator::Newmark: return std::make_unique<Newmark>();
    case Integrator::BackwardEuler: break;
  }
  return std::make_unique<BackwardEuler>();
}

// --- backward Euler ----------------------------------------------------------------------

void BackwardEuler::init(const SecondOrderSystem&, MotionState&) { forget(); }

StepReport BackwardEuler::step(SecondOrderSystem& system, MotionState& s, double dt) {
  StepReport report;
  system.beginStep(report);
  const Stopwatch posing;
  ImplicitStep p = velocityStep(system, s, dt, dt);
  poseEuler(system, s, p);
  p.guess = guess(s.v);
  report.assemblySeconds += posing.seconds();
  Eigen::VectorXd x = system.solve(p, report);
  remember(s.v);
  s.u = p.u0 + dt * x;
  s.v = std::move(x);
  s.t = p.time;
  report.t = s.t;
  return report;
}

// --- BDF2 --------------------------------------------------------------------------------

void Bdf2::init(const SecondOrderSystem&, MotionState&) {
  forget();
  hasPrevious_ = false;
}

StepReport Bdf2::step(SecondOrderSystem& system, MotionState& s, double dt) {
  StepReport report;
  system.beginStep(report);
  const Stopwatch posing;
  // BDF2 needs the last step, of the same length; the first step (and one after a change of
  // dt) is backward Euler's.
  const bool bdf2 = hasPrevious_ && dt == previousDt_;
  const double c = bdf2 ? 2.0 * dt / 3.0 : dt;
  ImplicitStep p = velocityStep(system, s, dt, c);
  p.automaticSolves = kSecondOrderSolves;
  if (bdf2) {
    Eigen::VectorXd kd, mv;
    system.stiffnessTimes((s.u - uPrevious_) / 3.0, kd);
    system.massTimes((4.0 * s.v - vPrevious_) / 3.0, mv);
    p.rhs = mv + c * (system.externalForce(p.time) - kd);
    p.u0 = (4.0 * s.u - uPrevious_) / 3.0;
  } else {
    poseEuler(system, s, p);
  }
  p.guess = guess(s.v);
  report.assemblySeconds += posing.seconds();
  Eigen::VectorXd x = system.solve(p, report);
  remember(s.v);
  Eigen::VectorXd u = p.u0 + c * x;
  uPrevious_ = std::move(s.u);
  vPrevious_ = std::move(s.v);
  hasPrevious_ = true;
  previousDt_ = dt;
  s.u = std::move(u);
  s.v = std::move(x);
  s.t = p.time;
  report.t = s.t;
  return report;
}

// --- Newmark -----------------------------------------------------------------------------

void Newmark::init(const SecondOrderSystem& system, MotionState& s) {
  forget();
  s.a = system.acceleration(s);
}

StepReport Newmark::step(SecondOrderSystem& system, MotionState& s, double dt) {
  StepReport report;
  system.beginStep(report);
  const Stopwatch posing;
  const double alpha = system.massDamping(), beta = system.stiffnessDamping();
  ImplicitStep p;
  p.time = s.t + dt;
  p.dt = dt;
  p.cM = 1.0 + kNewmarkGamma * dt * alpha;
  p.cK = kNewmarkGamma * dt * beta + kNewmarkBeta * dt * dt;
  p.forceScale = 1.0;
  p.automaticSolves = kSecondOrderSolves;
  // The step's start without the new acceleration: V0 = V_n + (1 - gamma) dt A_n, and the part
  // of U_{n+1} - U_n it gives, dt V_n + (1/2 - beta) dt^2 A_n; the right-hand side is
  // F_{n+1} - f(U_n) - D V0 - K_w (U0 - U_n).
  p.v0 = s.v + (1.0 - kNewmarkGamma) * dt * s.a;
  const Eigen::VectorXd w2 = beta * p.v0 + dt * s.v + (0.5 - kNewmarkBeta) * dt * dt * s.a;
  Eigen::VectorXd kw;
  system.stiffnessTimes(w2, kw);
  p.rhs = system.externalForce(p.time) - kw;
  if (alpha > 0.0) {
    Eigen::VectorXd mv;
    system.massTimes(p.v0, mv);
    p.rhs -= alpha * mv;
  }
  p.u0 = s.u + dt * s.v + (0.5 - kNewmarkBeta) * dt * dt * s.a;
  p.cU = kNewmarkBeta * dt * dt;
  p.cV = kNewmarkGamma * dt;
  p.guess = guess(s.a);
  report.assemblySeconds += posing.seconds();
  Eigen::VectorXd x = system.solve(p, report);
  remember(s.a);
  Eigen::VectorXd u = s.u + dt * s.v + dt * dt * ((0.5 - kNewmarkBeta) * s.a + kNewmarkBeta * x);
  s.v = s.v + dt * ((1.0 - kNewmarkGamma) * s.a + kNewmarkGamma * x);
  s.u = std::move(u);
  s.a = std::move(x);
  s.t = p.time;
  report.t = s.t;
  return report;
}

}  // namespace polydg
