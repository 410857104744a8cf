#include "physics/fem/tet_dynamics.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "physics/dynamics/time_integrators.h"
#include "physics/solvers/linear_solver.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// The place of entry (row, col) in a compressed column-major matrix, which must hold it.
int entryAt(const Eigen::SparseMatrix<double>& m, Eigen::Index row, Eigen::Index col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(begin, end, static_cast<int>(row));
  return static_cast<int>(at - m.innerIndexPtr());
}

}  // namespace

/// The body's mechanics, M U'' + D U' + f(U) = F(t) on the nodes' displacements U, for the
/// time integrators; and the step's matrix, whose pattern is the same every step, with the
/// solver that keeps its symbolic factorization or preconditioner layout.
class TetDynamics::System final : public SecondOrderSystem {
 public:
  System(const TetDiscretization& discretization, const TetDynamicsOptions& options);

  void massTimes(const Eigen::VectorXd& x, Eigen::VectorXd& out) const override {
    out = mass.cwiseProduct(x);
  }
  void stiffnessTimes(const Eigen::VectorXd& x, Eigen::VectorXd& out) const override {
    warpedProduct(rotationsAtState(), x, out);
  }
  Eigen::VectorXd externalForce(double t) const override;
  double massDamping() const override { return options.massDamping; }
  double stiffnessDamping() const override { return options.stiffnessDamping; }
  Eigen::VectorXd acceleration(const MotionState& s) const override;
  void beginStep(StepReport& report) override;
  Eigen::VectorXd solve(const ImplicitStep& step, StepReport& report) override;

  /// Each domain's rotation at displacement u (identities for linear forces).
  std::vector<Eigen::Matrix3d> rotationsAt(const Eigen::VectorXd& u) const;
  /// The rotations of the current state, computed once per state.
  const std::vector<Eigen::Matrix3d>& rotationsAtState() const;
  /// The elastic force f(u) = sum_d R_d K_d (R_d^T x - X) (x = X + u) and, if asked, the energy
  /// sum_d (R_d^T x - X)^T K_d (R_d^T x - X) / 2.
  Eigen::VectorXd elasticForce(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& u,
                               double* energy) const;
  /// out = K_R y = sum_d R_d K_d R_d^T y.
  void warpedProduct(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& y,
                     Eigen::VectorXd& out) const;
  /// The step's matrix cM M + cK K_R on the free DOFs, written into its fixed pattern.
  void assemble(const std::vector<Eigen::Matrix3d>& r, double cM, double cK);
  /// Solves the step's matrix for a full-length right-hand side (held DOFs ignored) and
  /// returns the full-length solution (zero at held DOFs).
  Eigen::VectorXd solveFree(const Eigen::VectorXd& rhs, const Eigen::VectorXd& guess,
                            StepReport& report);
  void prepareAssembly();

  const TetDiscretization& discretization;
  TetDynamicsOptions options;
  Eigen::VectorXd mass, gravityLoad;
  std::vector<Eigen::Index> freeIndex;  ///< per DOF: its index among the free DOFs, or -1
  Eigen::Index numFree = 0;
  MotionState state;
  std::unique_ptr<TimeIntegrator> integrator;
  bool started = false;
  /// Each domain's stiffness for the material: constant, only its rotation changes (Zhang et
  /// al. section 4.3: computed once, in preprocessing).
  std::vector<Eigen::MatrixXd> domainStiffness;
  /// Per domain, per node pair (a, b) and column c of the pair's 3 x 3 block: where the block's
  /// first row lies in the matrix's values (its 3 rows follow), or -1 when a node is held.
  std::vector<std::vector<int>> blockAt;
  std::vector<int> diagonalAt;  ///< per free DOF: its diagonal entry's place in the values
  Eigen::SparseMatrix<double> matrix;
  LinearSolver linear;
  bool computed = false;
  /// The current state's rotations (empty: not computed yet), and the step start's force.
  mutable std::vector<Eigen::Matrix3d> rotations;
  Eigen::VectorXd startForce;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double totalMass = 0.0;
};

TetDynamics::System::System(const TetDiscretization& d, const TetDynamicsOptions& o)
    : discretization(d), options(o), linear([&] {
        SolverOptions s = o.solver;
        s.preconditioner = CgPreconditioner::BlockJacobi;  // the nodes' 3 x 3 blocks
        return s;
      }()) {
  options.material.check();
  const auto n = static_cast<Eigen::Index>(d.numDofs());
  mass = d.lumpedMass(o.material.density);
  gravityLoad = d.bodyForceLoad(o.material.density * o.gravity);
  state.u = Eigen::VectorXd::Zero(n);
  state.v = Eigen::VectorXd::Zero(n);
  std::vector<char> held(static_cast<std::size_t>(n), 0);
  for (std::uint32_t node : o.clamped) {
    if (3 * static_cast<Eigen::Index>(node) + 2 >= n)
      throw std::invalid_argument("a clamped node is not a node of the mesh");
    for (int c = 0; c < 3; ++c) held[3 * node + c] = 1;
  }
  for (const TetLoad& load : o.loads)
    if (load.force.size() != n) throw std::invalid_argument("a load's length is not the DOFs'");
  freeIndex.assign(static_cast<std::size_t>(n), -1);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!held[i]) freeIndex[i] = numFree++;
  const Eigen::VectorXd& rest = d.restPositions();
  for (Eigen::Index v = 0; v < n / 3; ++v) {
    totalMass += mass[3 * v];
    centre += mass[3 * v] * rest.segment<3>(3 * v);
  }
  if (totalMass > 0.0) centre /= totalMass;
  integrator = makeTimeIntegrator(o.integrator);
  prepareAssembly();
}

void TetDynamics::System::prepareAssembly() {
  const auto& domains = discretization.domains();
  // The pattern: every free node pair of a domain as a 3 x 3 block, and the diagonal.
  std::vector<Eigen::Triplet<double>> pattern;
  auto freeNode = [&](std::uint32_t v) { return freeIndex[3 * v] >= 0 ? freeIndex[3 * v] : -1; };
  for (const StrainDomain& d : domains)
    for (int a = 0; a < d.numNodes; ++a)
      for (int b = 0; b < d.numNodes; ++b) {
        const Eigen::Index fa = freeNode(d.nodes[a]), fb = freeNode(d.nodes[b]);
        if (fa < 0 || fb < 0) continue;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            pattern.emplace_back(static_cast<int>(fa + i), static_cast<int>(fb + j), 0.0);
      }
  for (Eigen::Index i = 0; i < numFree; ++i)
    pattern.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.0);
  matrix.resize(numFree, numFree);
  matrix.setFromTriplets(pattern.begin(), pattern.end());
  matrix.makeCompressed();
  diagonalAt.resize(static_cast<std::size_t>(numFree));
  for (Eigen::Index i = 0; i < numFree; ++i) diagonalAt[i] = entryAt(matrix, i, i);
  domainStiffness.reserve(domains.size());
  blockAt.resize(domains.size());
  for (std::size_t i = 0; i < domains.size(); ++i) {
    const StrainDomain& d = domains[i];
    domainStiffness.push_back(discretization.domainStiffness(d, options.material));
    std::vector<int>& at = blockAt[i];
    at.assign(static_cast<std::size_t>(3 * d.numNodes * d.numNodes), -1);
    for (int a = 0; a < d.numNodes; ++a)
      for (int b = 0; b < d.numNodes; ++b) {
        const Eigen::Index fa = freeNode(d.nodes[a]), fb = freeNode(d.nodes[b]);
        if (fa < 0 || fb < 0) continue;
        for (int c = 0; c < 3; ++c)
          at[static_cast<std::size_t>(3 * (a * d.numNodes + b) + c)] = entryAt(matrix, fa, fb + c);
      }
  }
}

std::vector<Eigen::Matrix3d> TetDynamics::System::rotationsAt(const Eigen::VectorXd& u) const {
  if (!options.corotational)
    return std::vector<Eigen::Matrix3d>(discretization.domains().size(),
                                        Eigen::Matrix3d::Identity());
  return discretization.domainRotations(
      discretization.tetRotations(discretization.restPositions() + u));
}

const std::vector<Eigen::Matrix3d>& TetDynamics::System::rotationsAtState() const {
  if (rotations.empty()) rotations = rotationsAt(state.u);
  return rotations;
}

Eigen::VectorXd TetDynamics::System::elasticForce(const std::vector<Eigen::Matrix3d>& r,
                                                  const Eigen::VectorXd& u, double* energy) const {
  const auto& domains = discretization.domains();
  const Eigen::VectorXd& rest = discretization.restPositions();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
  double twice = 0.0;
  for (std::size_t i = 0; i < domains.size(); ++i) {
    const StrainDomain& d = domains[i];
    const Eigen::MatrixXd& kd = domainStiffness[i];
    Eigen::Matrix<double, 15, 1> local;  // R^T x_b - X_b
    for (int b = 0; b < d.numNodes; ++b) {
      const auto v = static_cast<Eigen::Index>(3 * d.nodes[b]);
      local.segment<3>(3 * b) =
          r[i].transpose() * (rest.segment<3>(v) + u.segment<3>(v)) - rest.segment<3>(v);
    }
    const Eigen::Index m = 3 * d.numNodes;
    const Eigen::VectorXd k = kd * local.head(m);
    twice += local.head(m).dot(k);
    for (int a = 0; a < d.numNodes; ++a) f.segment<3>(3 * d.nodes[a]) += r[i] * k.segment<3>(3 * a);
  }
  if (energy) *energy = 0.5 * twice;
  return f;
}

void TetDynamics::System::warpedProduct(const std::vector<Eigen::Matrix3d>& r,
                                        const Eigen::VectorXd& y, Eigen::VectorXd& out) const {
  const auto& domains = discretization.domains();
  out = Eigen::VectorXd::Zero(y.size());
  for (std::size_t i = 0; i < domains.size(); ++i) {
    const StrainDomain& d = domains[i];
    Eigen::Matrix<double, 15, 1> local;  // R^T y_b
    for (int b = 0; b < d.numNodes; ++b)
      local.segment<3>(3 * b) = r[i].transpose() * y.segment<3>(3 * d.nodes[b]);
    const Eigen::Index m = 3 * d.numNodes;
    const Eigen::VectorXd k = domainStiffness[i] * local.head(m);
    for (int a = 0; a < d.numNodes; ++a)
      out.segment<3>(3 * d.nodes[a]) += r[i] * k.segment<3>(3 * a);
  }
}

void TetDynamics::System::assemble(const std::vector<Eigen::Matrix3d>& r, double cM, double cK) {
  double* values = matrix.valuePtr();
  std::fill(values, values + matrix.nonZeros(), 0.0);
  for (Eigen::Index i = 0; i < mass.size(); ++i)
    if (freeIndex[i] >= 0) values[diagonalAt[freeIndex[i]]] = cM * mass[i];
  const auto& domains = discretization.domains();
  for (std::size_t i = 0; i < domains.size(); ++i) {
    const StrainDomain& d = domains[i];
    const Eigen::MatrixXd& kd = domainStiffness[i];
    const std::vector<int>& at = blockAt[i];
    for (int a = 0; a < d.numNodes; ++a)
      for (int b = 0; b < d.numNodes; ++b) {
        const int* place = &at[static_cast<std::size_t>(3 * (a * d.numNodes + b))];
        if (place[0] < 0) continue;
        const Eigen::Matrix3d block = cK * (r[i] * kd.block<3, 3>(3 * a, 3 * b) * r[i].transpose());
        for (int c = 0; c < 3; ++c)
          for (int row = 0; row < 3; ++row) values[place[c] + row] += block(row, c);
      }
  }
}

Eigen::VectorXd TetDynamics::System::externalForce(double t) const {
  Eigen::VectorXd f = gravityLoad;
  for (const TetLoad& load : options.loads)
    if (t <= load.until) f += load.force;
  return f;
}

Eigen::VectorXd TetDynamics::System::acceleration(const MotionState& s) const {
  const std::vector<Eigen::Matrix3d> r = rotationsAt(s.u);
  Eigen::VectorXd force = externalForce(s.t) - elasticForce(r, s.u, nullptr) -
                          options.massDamping * mass.cwiseProduct(s.v);
  if (options.stiffnessDamping > 0.0) {
    Eigen::VectorXd kv;
    warpedProduct(r, s.v, kv);
    force -= options.stiffnessDamping * kv;
  }
  Eigen::VectorXd a = Eigen::VectorXd::Zero(s.u.size());
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (freeIndex[i] >= 0) a[i] = force[i] / mass[i];
  return a;
}

void TetDynamics::System::beginStep(StepReport& report) {
  const Stopwatch rotating;
  const std::vector<Eigen::Matrix3d>& r = rotationsAtState();
  report.rotationSeconds += rotating.seconds();
  const Stopwatch forcing;
  startForce = elasticForce(r, state.u, nullptr);
  report.assemblySeconds += forcing.seconds();
}

Eigen::VectorXd TetDynamics::System::solveFree(const Eigen::VectorXd& rhs,
                                               const Eigen::VectorXd& guess, StepReport& report) {
  Eigen::VectorXd b(numFree), start(numFree);
  for (Eigen::Index i = 0; i < rhs.size(); ++i)
    if (freeIndex[i] >= 0) {
      b[freeIndex[i]] = rhs[i];
      start[freeIndex[i]] = guess.size() == rhs.size() ? guess[i] : 0.0;
    }
  LinearSolveReport solved;
  const Eigen::VectorXd x = linear.solve(b, solved, &start);
  if (!solved.success)
    throw std::runtime_error("the tet time step's solve failed; try a smaller dt");
  report.iterations += solved.iterations;
  report.residual = solved.residual;
  Eigen::VectorXd full = Eigen::VectorXd::Zero(rhs.size());
  for (Eigen::Index i = 0; i < rhs.size(); ++i)
    if (freeIndex[i] >= 0) full[i] = x[freeIndex[i]];
  return full;
}

Eigen::VectorXd TetDynamics::System::solve(const ImplicitStep& step, StepReport& report) {
  const Stopwatch assembling;
  const std::vector<Eigen::Matrix3d>& r = rotationsAtState();
  assemble(r, step.cM, step.cK);
  report.assemblySeconds += assembling.seconds();
  const Stopwatch solving;
  // The rotations change a little each step: CG keeps its block-Jacobi preconditioner fresh
  // (cheap), Cholesky keeps its symbolic analysis.
  const bool ok = computed ? linear.update(matrix, true) : linear.compute(matrix, 3);
  computed = true;
  report.refactorized = linear.kind() == SolverKind::Cholesky;
  report.preconditionerRebuilt = !report.refactorized;
  if (!ok) throw std::runtime_error("the tet time step's matrix is not positive definite");
  report.solves = 1;
  Eigen::VectorXd x = solveFree(step.rhs - step.forceScale * startForce, step.guess, report);
  double notSolving = 0.0;
  // Corotation, second-order integrators: f(U_{n+1}) ~ f(U^k) + K_R (U_{n+1} - U^k) at the
  // last solution's state U^k, solved again with the step's matrix (modified Newton).
  const int solves = options.corotational ? step.automaticSolves : 1;
  for (int k = 1; k < solves; ++k) {
    const Stopwatch correcting;
    const Eigen::VectorXd uk = step.u0 + step.cU * x;
    const std::vector<Eigen::Matrix3d> rk = rotationsAt(uk);
    Eigen::VectorXd kd;
    warpedProduct(r, uk - state.u, kd);
    const Eigen::VectorXd rhs = step.rhs - step.forceScale * (elasticForce(rk, uk, nullptr) - kd);
    notSolving += correcting.seconds();
    Eigen::VectorXd next = solveFree(rhs, x, report);
    ++report.solves;
    const double change = (next - x).norm(), size = next.norm();
    x = std::move(next);
    report.correction = size > 0.0 ? change / size : change;
    if (report.correction <= options.correctionTolerance) break;
  }
  report.assemblySeconds += notSolving;
  report.solveSeconds += solving.seconds() - notSolving;
  return x;
}

TetDynamics::TetDynamics(const TetDiscretization& discretization, const TetDynamicsOptions& options)
    : system_(std::make_unique<System>(discretization, options)) {}

TetDynamics::~TetDynamics() = default;

void TetDynamics::setRigidVelocity(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular,
                                   const Eigen::Vector3d& centre) {
  System& s = *system_;
  const Eigen::VectorXd x = positions();
  for (Eigen::Index v = 0; v < x.size() / 3; ++v)
    if (s.freeIndex[3 * v] >= 0)
      s.state.v.segment<3>(3 * v) =
          linear + angular.cross(Eigen::Vector3d(x.segment<3>(3 * v)) - centre);
  s.started = false;  // Newmark's acceleration follows the new velocity
}

StepReport TetDynamics::step(double dt) {
  if (!(dt > 0.0)) throw std::invalid_argument("the time step must be positive");
  System& s = *system_;
  if (!s.started) {
    s.integrator->init(s, s.state);
    s.started = true;
  }
  last_ = s.integrator->step(s, s.state, dt);
  // The new state's rotations, which state() and the next step use, count in this step.
  s.rotations.clear();
  const Stopwatch rotating;
  s.rotationsAtState();
  last_.rotationSeconds += rotating.seconds();
  return last_;
}

double TetDynamics::time() const { return system_->state.t; }
Eigen::VectorXd TetDynamics::positions() const {
  return system_->discretization.restPositions() + system_->state.u;
}
const Eigen::VectorXd& TetDynamics::velocities() const { return system_->state.v; }
const Eigen::VectorXd& TetDynamics::displacement() const { return system_->state.u; }
double TetDynamics::volume() const { return system_->discretization.volume(positions()); }
SolverKind TetDynamics::solverKind() const { return system_->linear.kind(); }
double TetDynamics::mass() const { return system_->totalMass; }
const Eigen::Vector3d& TetDynamics::referencePoint() const { return system_->centre; }

double TetDynamics::kineticEnergy() const {
  const System& s = *system_;
  return 0.5 * s.state.v.dot(s.mass.cwiseProduct(s.state.v));
}

BodyState TetDynamics::state() const {
  const System& s = *system_;
  BodyState b;
  b.kinetic = kineticEnergy();
  s.elasticForce(s.rotationsAtState(), s.state.u, &b.elastic);
  b.gravity = -s.gravityLoad.dot(s.state.u);
  for (const TetLoad& load : s.options.loads)
    if (s.state.t <= load.until) b.tractionPotential -= load.force.dot(s.state.u);
  const Eigen::VectorXd x = positions();
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) {
    const double m = s.mass[3 * v];
    const Eigen::Vector3d p = x.segment<3>(3 * v), vel = s.state.v.segment<3>(3 * v);
    b.momentum += m * vel;
    b.angularMomentum += m * (p - s.centre).cross(vel);
    first += m * p;
  }
  b.centreOfMass = s.totalMass > 0.0 ? Eigen::Vector3d(first / s.totalMass) : s.centre;
  return b;
}

}  // namespace polydg
