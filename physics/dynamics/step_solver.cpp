#include "physics/dynamics/step_solver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "util/stopwatch.h"

namespace polydg {

namespace {

/// Block-Jacobi CG until a solve needs more than this many iterations, then the p-multigrid:
/// on B10's beam a block-Jacobi iteration costs a fifth of a V-cycle (1.75 against 7.7 ms at
/// 87k DOFs, 23.5 against 115 ms at 960k), and a solve takes 7-15 V-cycles; with 80, Newmark's
/// 68 block-Jacobi iterations a solve at 960k DOFs cost 3.67 s a step where BDF2's V-cycles
/// took 2.34 (docs/benchmarks.md). The solve that reaches the limit goes on from its iterate
/// with the p-multigrid: the sliced bunny's first step took 506 block-Jacobi iterations.
constexpr int kBlockJacobiLimit = 50;

/// Adds the seconds from its making to its end to the report's preconditioner time (a prepare()
/// that kept everything adds its few microseconds).
class PreconditionerTimer {
 public:
  explicit PreconditionerTimer(StepReport& report) : report_(report) {}
  ~PreconditionerTimer() { report_.preconditionerSeconds += watch_.seconds(); }
  PreconditionerTimer(const PreconditionerTimer&) = delete;
  PreconditionerTimer& operator=(const PreconditionerTimer&) = delete;

 private:
  StepReport& report_;
  Stopwatch watch_;
};

/// The iterations CG would still need to bring the residual of `report` to `target` at the rate
/// it reduced it so far (a large number if it did not).
int iterationsLeft(const LinearSolveReport& report, double target) {
  constexpr int kMany = 1 << 30;
  if (report.iterations == 0 || !(report.residual < report.initialResidual)) return kMany;
  if (report.residual <= target) return 0;
  const double rate = std::log(report.residual / report.initialResidual) / report.iterations;
  return static_cast<int>(
      std::min(std::ceil(std::log(target / report.residual) / rate), static_cast<double>(kMany)));
}

/// A step's matrix that is not positive definite: a smaller step is what helps.
[[noreturn]] void throwNotDefinite(const std::string& matrix, const std::string& why) {
  throw std::runtime_error("the time step's " + matrix + " is not positive definite" + why +
                           "; try a smaller dt");
}

}  // namespace

StepSolver::StepSolver(const StepSolverOptions& options, const ElementFrames& frames, int blockSize)
    : options_(options), frames_(&frames), blockSize_(blockSize), active_(options.solver) {
  if (options_.adaptivePreconditioner) active_.preconditioner = CgPreconditioner::BlockJacobi;
  makeSolver();
}

void StepSolver::makeSolver() {
  solver_ = LinearSolver(active_, MatrixTerms::StiffnessAndMass);
  ready_ = false;
}

bool StepSolver::blockJacobiFirst() const {
  return options_.adaptivePreconditioner && active_.preconditioner == CgPreconditioner::BlockJacobi;
}

void StepSolver::startWith(CgPreconditioner preconditioner) {
  if (!options_.adaptivePreconditioner || preconditioner != CgPreconditioner::PMultigrid ||
      active_.preconditioner == preconditioner)
    return;
  active_.preconditioner = preconditioner;
  makeSolver();
}

void StepSolver::beginStep() {
  blockJacobiIterations_ = 0;
  iterationsBeforeSwitch_ = 0;
}

void StepSolver::prepare(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                         bool changed, StepReport& report) {
  const PreconditionerTimer timer(report);
  prepared_ = {&matrix, nullptr, nullptr, false};
  if (!ready_) {
    const bool direct = chooseSolver(matrix, active_) == SolverKind::Cholesky;
    if (!solver_.compute(matrix, blockSize_, direct ? nullptr : frames_) && direct)
      throwNotDefinite("system matrix", " (a corotated element turned inside out?)");
    report.refactorized = direct;
    report.preconditionerRebuilt = !direct;
    ready_ = true;
    baselineIterations_ = -1;
  } else if (changed) {
    const bool direct = solver_.kind() == SolverKind::Cholesky;
    const bool refresh = !direct && refreshDue();
    if (!solver_.update(matrix, refresh, frames_) && direct)
      throwNotDefinite("system matrix", " (a corotated element turned inside out?)");
    report.refactorized = direct;
    report.preconditionerRebuilt = refresh;
    if (refresh) baselineIterations_ = -1;
  }
}

/// The refresh rule: the last step needed more than refreshRatio times the iterations of the
/// first step after the preconditioner was built.
bool StepSolver::refreshDue() const {
  return baselineIterations_ >= 0 &&
         lastIterations_ > options_.refreshRatio * std::max(baselineIterations_, 1);
}

void StepSolver::prepare(const BlockRows<double>& rows, bool changed, StepReport& report) {
  const PreconditionerTimer timer(report);
  prepared_ = {nullptr, &rows, nullptr, false};
  if (!ready_) {
    solver_.computeForUpdates(rows, frames_);
    report.preconditionerRebuilt = true;
    ready_ = true;
    baselineIterations_ = -1;
  } else if (changed) {
    const bool refresh = refreshDue();
    solver_.update(rows, refresh, frames_);
    report.preconditionerRebuilt = refresh;
    if (refresh) baselineIterations_ = -1;
  }
  solver_.setAddedTerms(nullptr);
}

void StepSolver::prepareWithAddedTerms(
    const BlockRows<double>& rows, const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& terms,
    bool changed, StepReport& report) {
  prepare(rows, changed, report);
  solver_.setAddedTerms(&terms);
  prepared_.terms = &terms;
  addedTerms_ = true;
}

void StepSolver::prepareWithContact(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                                    StepReport& report) {
  const PreconditionerTimer timer(report);
  prepared_ = {&matrix, nullptr, nullptr, true};
  const bool direct = chooseSolver(matrix, active_) == SolverKind::Cholesky;
  if (!solver_.compute(matrix, blockSize_, direct ? nullptr : frames_) && direct)
    throwNotDefinite("system matrix with contacts", "");
  report.refactorized = direct;
  report.preconditionerRebuilt = !direct;
  ready_ = false;
  baselineIterations_ = -1;
}

Eigen::VectorXd StepSolver::solve(const Eigen::VectorXd& rhs, const Eigen::VectorXd& guess,
                                  StepReport& report, double tolerance) {
  // CG's residual target is relative to |rhs|: an overflowing norm would stop it at once.
  if (!std::isfinite(rhs.squaredNorm()))
    throw std::runtime_error(
        "the time step's right-hand side overflows double precision (an initial velocity or a "
        "load too large for the body); scale the scene's values or units down");
  LinearSolveReport lr;
  const double target = std::max(tolerance, options_.solver.tolerance);
  const bool cg = solver_.kind() == SolverKind::ConjugateGradient;
  // Block-Jacobi's iterations of a step: kBlockJacobiLimit a solve, the step's solves so far
  // and this one (a corrected step's first solve, from the older start, may take more).
  const int budget = kBlockJacobiLimit * (report.solves + 1) - blockJacobiIterations_;
  if (cg && blockJacobiFirst() && budget <= 0) switchToMultigrid(report);
  Eigen::VectorXd x = solver_.solve(rhs, lr, &guess, target, blockJacobiFirst() ? budget : 0);
  if (cg && blockJacobiFirst()) {
    blockJacobiIterations_ += lr.iterations;
    // Block-Jacobi a few iterations short of the target at its rate so far (a tenth of the
    // limit, less than the p-multigrid's build costs) goes on: Newmark's first step on B10's
    // beam stopped at 1.1e-8 for 1e-8, and then took block-Jacobi's 65 iterations a step in two
    // solves, cheaper than 20 V-cycles.
    constexpr int kFewLeft = kBlockJacobiLimit / 10;
    if (!lr.success && iterationsLeft(lr, target) <= kFewLeft) {
      report.iterations += lr.iterations;
      x = solver_.solve(rhs, lr, &x, target, kFewLeft);
      blockJacobiIterations_ += lr.iterations;
    }
    if (!lr.success) {
      report.iterations += lr.iterations;
      switchToMultigrid(report);
      x = solver_.solve(rhs, lr, &x, target);
    }
  }
  if (!lr.success)
    throw std::runtime_error("the time step's solve failed (CG did not converge in " +
                             std::to_string(lr.iterations) + " iterations, residual " +
                             std::to_string(lr.residual) +
                             "); try the scene's \"solver\": \"cholesky\" or a smaller dt");
  report.iterations += lr.iterations;
  report.residual = lr.residual;
  return x;
}

/// The p-multigrid of the matrix the last prepare() was given, in place of block-Jacobi, with
/// the same added terms; timed as the preconditioner's build.
void StepSolver::switchToMultigrid(StepReport& report) {
  const PreconditionerTimer timer(report);
  active_.preconditioner = CgPreconditioner::PMultigrid;
  makeSolver();
  if (prepared_.rows)
    solver_.computeForUpdates(*prepared_.rows, frames_);
  else
    solver_.compute(*prepared_.matrix, blockSize_, frames_);
  solver_.setAddedTerms(prepared_.terms);
  // A matrix with contacts has another pattern: the next prepare() builds again without them.
  ready_ = !prepared_.contacts;
  baselineIterations_ = -1;
  iterationsBeforeSwitch_ = report.iterations;
  report.preconditionerRebuilt = true;
  report.preconditionerSwitched = true;
}

void StepSolver::endStep(StepReport& report) {
  // Contact terms outside the preconditioner add iterations that a new one would not save. A
  // step that switched counts its V-cycles only: the baseline may then be low (they started
  // from block-Jacobi's iterate), which costs one early rebuild, where a high one would keep a
  // preconditioner of the first step's rotations for steps that take five times its V-cycles
  // (B10's beam at dt = 2).
  if (!addedTerms_) {
    lastIterations_ = report.iterations - iterationsBeforeSwitch_;
    if (baselineIterations_ < 0) baselineIterations_ = lastIterations_;
  }
  addedTerms_ = false;
  report.preconditioner = active_.preconditioner;
}

}  // namespace polydg
