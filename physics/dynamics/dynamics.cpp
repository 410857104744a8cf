#include "physics/dynamics/dynamics.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "integrate/quadrature.h"
#include "physics/dg/block_rows.h"
#include "physics/dg/form_coefficients.h"
#include "physics/dynamics/corotation.h"
#include "physics/dynamics/mass_matrix.h"
#include "physics/dynamics/step_solver.h"
#include "physics/dynamics/time_integrators.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// CG leaves the contact terms of at most this many active points out of its preconditioner
/// (each adds an outlying eigenvalue, an iteration or two); more, and the preconditioner is built
/// again with them. The bound is where B9's drop found the two about even (docs/benchmarks.md,
/// "Measurements behind the code's constants").
constexpr std::size_t kContactsOutsidePreconditioner = 16;

/// A first solve that corrections follow stops at this share of the last step's first
/// correction (a relative residual against a relative change: a tenth leaves margin for the
/// difference between the two). B10's beam with BDF2, iterations a step: 74 with a hundredth,
/// 67 with a tenth, 59 with the whole correction, the states the same to 1e-10.
constexpr double kFirstSolveShare = 0.1;

/// The body's loads as vectors: gravity's, and each traction's while it acts.
struct LoadVectors {
  Eigen::VectorXd gravity;
  std::vector<Eigen::VectorXd> tractions;
  std::vector<double> until;
};

}  // namespace

/// The mechanics of the moving body (SecondOrderSystem) and its state.
struct DynamicSolver::Impl final : SecondOrderSystem {
  const PolyMesh* mesh = nullptr;
  const MomentCache* moments = nullptr;
  DynamicsOptions options;
  std::unique_ptr<DgBasis> basis;
  FaceRoles roles;
  ElementPenalties penalties;
  FormCoefficients form;
  std::vector<std::size_t> clampFaces, tractionFaces;
  std::size_t elementsComputed = 0;
  std::optional<MassMatrix> mass;
  std::optional<CorotatedStiffness> stiffness;
  ElementFrames frames;
  std::optional<StepSolver> stepSolver;
  LoadVectors loads;
  /// CG: the step's matrix cM M + cK K_w by block rows, warped straight into them each time it
  /// changes; CG multiplies with them and its preconditioner is built from them. Written by
  /// forceAtU() too, with the force (const: it caches).
  mutable BlockRows<double> rows;
  bool byRows = false;
  LocalMatrices system;  ///< Cholesky: the blocks of the step's matrix, for `matrix`
  /// Cholesky, and a step with contact terms (another pattern): the step's matrix in CSR,
  /// written when needed.
  SpMat matrix;
  bool matrixCurrent = false;
  SpMat contactMatrix;  ///< matrix plus the step's contact terms
  SpMat contactTerms;   ///< the step's contact terms alone, when CG leaves them out of its
                        ///< preconditioner
  ContactModel* contact = nullptr;
  bool assembled = false;  ///< the step's matrix (rows or `system`) was assembled once
  double lastCM = 0.0, lastCK = 0.0;
  /// lastCM and lastCK are a step's (this solver's last, or the one's before an edit).
  bool coefficientsKnown = false;
  /// The rows hold cM M + cK K_w with `current`'s rotations and the coefficients lastCM, lastCK.
  mutable bool rowsAtCurrent = false;
  /// The corrections' last measured contraction, correction k / correction k - 1 (1: unknown),
  /// and the last step's first correction.
  double contractionRate = 1.0, firstCorrection = 0.0;
  MotionState state;
  std::unique_ptr<TimeIntegrator> integrator;
  /// The length of the step under way (or the last one): the tolerance of "t <= until".
  double stepLength = 0.0;

  /// The rotations and the elastic force (with its energy) of the current displacement, kept
  /// until it changes: the report's state() after a step and the next step share them.
  struct ForceAtU {
    std::vector<Eigen::Matrix3d> r;
    Eigen::VectorXd f;
    double energy = 0.0;
    double rotationSeconds = 0.0, forceSeconds = 0.0;
  };
  mutable std::optional<ForceAtU> current;

  void setup(const PolyMesh& m, const MomentCache& mc, const DynamicLoads& l,
             const DynamicsOptions& o, std::unique_ptr<Impl> before = nullptr,
             const std::vector<char>* changed = nullptr);
  /// The split matrices: computed, or updated from those of the solver before an edit.
  SplitLocalMatrices splitParts(std::unique_ptr<Impl> before, const std::vector<char>* changed);
  void classify(const DynamicLoads& l, LoadCase& lc);
  void assembleLoads(const DynamicLoads& l, const LoadCase& lc);
  const ForceAtU& forceAtU() const;
  Eigen::VectorXd elasticForce(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& u,
                               double* energy) const {
    const Eigen::VectorXd x = stiffness->undeformed() + u;
    Eigen::VectorXd f;
    stiffness->product(r, x, &stiffness->undeformed(), f, energy);
    return f;
  }
  bool inForce(std::size_t k, double t) const {
    return t <= loads.until[k] * (1.0 + 1e-12) + 1e-12 * stepLength;
  }
  void stateChanged() { current.reset(); }

  // SecondOrderSystem
  void massTimes(const Eigen::VectorXd& x, Eigen::VectorXd& out) const override {
    mass->times(x, out);
  }
  void stiffnessTimes(const Eigen::VectorXd& x, Eigen::VectorXd& out) const override {
    stiffness->product(forceAtU().r, x, nullptr, out, nullptr);
  }
  Eigen::VectorXd externalForce(double t) const override;
  double massDamping() const override { return options.damping.mass; }
  double stiffnessDamping() const override { return options.damping.stiffness; }
  Eigen::VectorXd acceleration(const MotionState& s) const override;
  void beginStep(StepReport& report) override;
  Eigen::VectorXd solve(const ImplicitStep& step, StepReport& report) override;

  // The parts of solve().
  bool assembleSystem(const ImplicitStep& step, StepReport& report);
  const SpMat& csrMatrix();
  int solvesPerPass(const ImplicitStep& step) const;
  Eigen::VectorXd correct(const ImplicitStep& step, const Eigen::VectorXd& base, Eigen::VectorXd x,
                          int solves, StepReport& report, double& notSolving);
  void stiffnessTimesAssembled(const ImplicitStep& step, const std::vector<Eigen::Matrix3d>& r,
                               const Eigen::VectorXd& y, Eigen::VectorXd& out) const;

  BodyState bodyState() const;
  double deformedVolume() const;
};

void DynamicSolver::Impl::setup(const PolyMesh& m, const MomentCache& mc, const DynamicLoads& l,
                                const DynamicsOptions& o, std::unique_ptr<Impl> before,
                                const std::vector<char>* changed) {
  mesh = &m;
  moments = &mc;
  options = o;
  options.material.check();
  options.discretization.check();
  if (!(o.damping.mass >= 0.0) || !(o.damping.stiffness >= 0.0))
    throw std::invalid_argument("damping coefficients must not be negative");
  const int p = o.discretization.basis.degree;
  if (mc.degree() < 2 * p)
    throw std::invalid_argument("DynamicSolver: the moments must be of degree >= 2p");
  basis = std::make_unique<DgBasis>(m, mc, o.discretization.basis);
  LoadCase lc;
  classify(l, lc);
  double threshold = 0.0;
  form = formCoefficients(m, *basis, mc, roles, options.material, o.discretization, penalties,
                          threshold);
  // The split matrices before the rest, so that the old solver's memory is freed first.
  SplitLocalMatrices parts = splitParts(std::move(before), changed);
  mass.emplace(*basis, mc, options.material.density);
  stiffness.emplace(*basis, mc, std::move(parts), mass->centre(), options.corotational);
  assembleLoads(l, lc);
  frames = elementFrames(*basis, m);
  SolverOptions solver = options.solver;
  // A corotated step's matrix changes every step: Cholesky would factorize it again each time,
  // where CG starts from the last solution (2.1x faster on B9's drop at 672 DOFs, 3.6x at 1,920).
  if (options.corotational) solver.directLimitDofs = 0;
  stepSolver.emplace(
      StepSolverOptions{solver, options.adaptivePreconditioner, options.refreshRatio}, frames,
      3 * basis->size());
  rows = blockRowsLayout(stiffness->layout());
  byRows = chooseSolver(static_cast<std::size_t>(rows.elements()) * rows.bs, rows.entries(),
                        solver) == SolverKind::ConjugateGradient;
  if (!byRows) {
    rows = BlockRows<double>();
    system = stiffness->layout();  // layout; values are written per step
  }
  state.u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.numElements()) * 3 * basis->size());
  state.v = state.u;
  state.a = state.u;
  integrator = makeTimeIntegrator(options.integrator);
}

SplitLocalMatrices DynamicSolver::Impl::splitParts(std::unique_ptr<Impl> before,
                                                   const std::vector<char>* changed) {
  const std::size_t ne = mesh->numElements();
  const DiscretizationOptions& d = options.discretization;
  // Every term changes with the material, a global penalty or the BZ factor; the blocks'
  // size with p.
  const bool reusable =
      before && before->stiffness && changed && changed->size() == ne &&
      before->form.mu == form.mu && before->form.lambda == form.lambda &&
      before->basis->size() == basis->size() && before->options.discretization.method == d.method &&
      before->form.bzFactor == form.bzFactor && (form.elementEta || before->form.eta == form.eta) &&
      !before->form.elementEta == !form.elementEta;
  if (!reusable) {
    before.reset();
    elementsComputed = ne;
    return splitLocalMatrices(*mesh, *basis, *moments, roles, form);
  }
  // Fresh: what the edit changed, and elements whose basis or penalty differ from before.
  std::vector<char> fresh = *changed;
  const std::size_t old = before->basis->numElements();
  const std::size_t n2 = static_cast<std::size_t>(basis->size() * basis->size());
  for (std::size_t i = 0; i < ne; ++i) {
    if (fresh[i] || i >= old) continue;
    const ElementId e(i);
    const auto a = basis->coefficients(e), b = before->basis->coefficients(e);
    fresh[i] = basis->centre(e) != before->basis->centre(e) ||
               basis->scale(e) != before->basis->scale(e) ||
               !std::equal(a.data(), a.data() + n2, b.data()) ||
               (form.elementEta && penalties.eta[e] != before->penalties.eta[e]) ||
               (form.elementFaceArea && penalties.faceArea[e] != before->penalties.faceArea[e]);
  }
  SplitLocalMatrices parts = std::move(*before->stiffness).release();
  before.reset();
  elementsComputed = updateSplitLocalMatrices(parts, *mesh, *basis, *moments, roles, form, fresh);
  return parts;
}

/// The faces each clamp and traction selects (face roles, and the counts per selection).
void DynamicSolver::Impl::classify(const DynamicLoads& l, LoadCase& lc) {
  for (const FaceSelector& c : l.clamps) lc.dirichlet.push_back({c, {}});
  for (const TimedTraction& tr : l.tractions) lc.tractions.push_back({tr.where, tr.traction});
  roles = classifyFaces(*mesh, lc);
  clampFaces.assign(l.clamps.size(), 0);
  tractionFaces.assign(l.tractions.size(), 0);
  for (std::size_t f = 0; f < mesh->numFaces(); ++f) {
    const FaceId id(f);
    if (roles.dirichlet[id] >= 0) ++clampFaces[static_cast<std::size_t>(roles.dirichlet[id])];
    if (roles.traction[id] >= 0) ++tractionFaces[static_cast<std::size_t>(roles.traction[id])];
  }
}

void DynamicSolver::Impl::assembleLoads(const DynamicLoads& l, const LoadCase& lc) {
  const int p = options.discretization.basis.degree;
  const int quadrature = options.discretization.quadratureDegree >= 0
                             ? options.discretization.quadratureDegree
                             : 2 * p + 2;
  LoadCase gravity = lc;
  for (auto& tr : gravity.tractions) tr.traction = Vec3::Zero();
  gravity.gravity = l.gravity;
  loads.gravity =
      assembleLoad(*mesh, *basis, *moments, roles, form, options.material, gravity, quadrature);
  for (std::size_t k = 0; k < l.tractions.size(); ++k) {
    LoadCase one = gravity;
    one.gravity = Vec3::Zero();
    one.tractions[k].traction = l.tractions[k].traction;
    loads.tractions.push_back(
        assembleLoad(*mesh, *basis, *moments, roles, form, options.material, one, quadrature));
    loads.until.push_back(l.tractions[k].until);
  }
}

const DynamicSolver::Impl::ForceAtU& DynamicSolver::Impl::forceAtU() const {
  if (!current) {
    ForceAtU c;
    const Stopwatch tr;
    c.r = stiffness->rotations(state.u);
    c.rotationSeconds = tr.seconds();
    const Stopwatch tf;
    // A corotated CG step's matrix has these rotations too: warped with the force, every split
    // block is read once. The coefficients are the last step's; assembleSystem() assembles
    // again if the next step's differ.
    rowsAtCurrent = byRows && coefficientsKnown && options.corotational;
    if (rowsAtCurrent)
      stiffness->forceAndAssemble(c.r, state.u, c.f, c.energy, mass->blocks(), lastCM, lastCK,
                                  rows);
    else
      c.f = elasticForce(c.r, state.u, &c.energy);
    c.forceSeconds = tf.seconds();
    current = std::move(c);
  }
  return *current;
}

Eigen::VectorXd DynamicSolver::Impl::externalForce(double t) const {
  Eigen::VectorXd f = loads.gravity;
  for (std::size_t k = 0; k < loads.tractions.size(); ++k)
    if (inForce(k, t)) f += loads.tractions[k];
  return f;
}

Eigen::VectorXd DynamicSolver::Impl::acceleration(const MotionState& s) const {
  Eigen::VectorXd rhs = externalForce(s.t) - forceAtU().f;
  if (options.damping.mass > 0.0 || options.damping.stiffness > 0.0) {
    Eigen::VectorXd mv, kv;
    massTimes(s.v, mv);
    stiffnessTimes(s.v, kv);
    rhs -= options.damping.mass * mv + options.damping.stiffness * kv;
  }
  return mass->solve(rhs);
}

void DynamicSolver::Impl::beginStep(StepReport& report) {
  // The rotations and f(U_n): computed by the last step (and counted there), unless the state
  // was set since.
  const bool computedHere = !current;
  const ForceAtU& at = forceAtU();
  if (!computedHere) return;
  report.rotationSeconds += at.rotationSeconds;
  report.assemblySeconds += at.forceSeconds;
}

/// The step's matrix cM M + cK K_w: again with new rotations, and when the integrator's
/// coefficients change (BDF2 after its first step, a new dt). Whether it changed.
bool DynamicSolver::Impl::assembleSystem(const ImplicitStep& step, StepReport& report) {
  const Stopwatch t;
  const bool sameCoefficients = step.cK == lastCK && step.cM == lastCM;
  const bool changed = !assembled || options.corotational || !sameCoefficients;
  if (!sameCoefficients) contractionRate = 1.0;          // another matrix: unknown
  const std::vector<Eigen::Matrix3d>& r = forceAtU().r;  // may write the rows (rowsAtCurrent)
  lastCM = step.cM;
  lastCK = step.cK;
  coefficientsKnown = true;
  if (changed) {
    matrixCurrent = false;
    if (byRows) {
      if (!(rowsAtCurrent && sameCoefficients))
        stiffness->assemble(r, mass->blocks(), step.cM, step.cK, rows);
      rowsAtCurrent = true;
    } else {
      stiffness->assemble(r, mass->blocks(), step.cM, step.cK, system);
      csrMatrix();
    }
    assembled = true;
  }
  report.assemblySeconds += t.seconds();
  return changed;
}

/// The step's matrix in CSR, written from the rows or `system` if it changed since.
const SpMat& DynamicSolver::Impl::csrMatrix() {
  if (matrixCurrent) return matrix;
  if (byRows) {
    SpMat k = rows.toSparse();
    matrix.swap(k);
  } else if (matrix.size() == 0) {
    SpMat k = assembleStiffness(system);
    matrix.swap(k);
  } else {
    refillStiffness(system, matrix);
  }
  matrixCurrent = true;
  return matrix;
}

int DynamicSolver::Impl::solvesPerPass(const ImplicitStep& step) const {
  if (!options.corotational) return 1;
  if (options.corotationSolves > 0) return options.corotationSolves;
  return step.automaticSolves;
}

/// Corotation: corrects the once-linearized force with further solves of the step's matrix
/// (modified Newton), f(U_{n+1}) ~ f(U^k) + K_w (U_{n+1} - U^k) with U^k the last solution's
/// state, until `solves` solves were made or, automatically, until the error left is estimated
/// below the tolerance: the last correction times the rate at which corrections shrink
/// (CVODE's test for its Newton iteration, with its rate carried from step to step; Hindmarsh
/// et al. 2005, section 2.1). A correction then stops one solve early when the next one would
/// change nothing that matters (B10's beam with BDF2: 3.4e-5 and then 4e-8).
Eigen::VectorXd DynamicSolver::Impl::correct(const ImplicitStep& step, const Eigen::VectorXd& base,
                                             Eigen::VectorXd x, int solves, StepReport& report,
                                             double& notSolving) {
  const std::vector<Eigen::Matrix3d>& r = forceAtU().r;
  for (int k = 1; k < solves; ++k) {
    const Stopwatch tc;
    const Eigen::VectorXd uk = step.u0 + step.cU * x;
    const std::vector<Eigen::Matrix3d> rk = stiffness->rotations(uk);
    const double rotating = tc.seconds();
    report.rotationSeconds += rotating;
    notSolving += rotating;
    const Stopwatch tf;
    Eigen::VectorXd kd;
    const Eigen::VectorXd fk = elasticForce(rk, uk, nullptr);
    stiffnessTimesAssembled(step, r, uk - state.u, kd);
    const Eigen::VectorXd rhs = base - step.forceScale * (fk - kd);
    const double forcing = tf.seconds();
    report.assemblySeconds += forcing;
    notSolving += forcing;
    Eigen::VectorXd next = stepSolver->solve(rhs, x, report);
    ++report.solves;
    const double change = (next - x).norm(), size = next.norm();
    x = std::move(next);
    const double previous = report.correction;
    report.correction = size > 0.0 ? change / size : change;
    if (options.corotationSolves > 0) continue;
    if (k == 1) firstCorrection = report.correction;
    if (k > 1 && previous > 0.0) contractionRate = std::min(1.0, report.correction / previous);
    if (report.correction <= options.correctionTolerance) break;
    if (report.correction * contractionRate <= options.correctionTolerance) {
      // Stopped on the estimate: it doubles for each step that relies on it unmeasured, so
      // that a rate grown since is measured again within a few steps.
      contractionRate = std::min(1.0, 2.0 * contractionRate);
      break;
    }
  }
  return x;
}

/// out = K_w y with the step's rotations `r`: from the step's block rows, A = cM M + cK K_w,
/// as (A y - cM M y) / cK, one pass over the rows CG streams anyway, where the product from
/// the split element blocks reads several times their bytes and warps every part (most of a
/// correction's force computation at 87k DOFs). The subtraction costs digits as the mass
/// part outweighs the stiffness part, cM |M y| / (cK |K_w y|); on B10's beam at dt = 0.01 the
/// BDF2 and Newmark states are those of the product from the split blocks to 1e-15.
void DynamicSolver::Impl::stiffnessTimesAssembled(const ImplicitStep& step,
                                                  const std::vector<Eigen::Matrix3d>& r,
                                                  const Eigen::VectorXd& y,
                                                  Eigen::VectorXd& out) const {
  if (!byRows || step.cK == 0.0) {
    stiffness->product(r, y, nullptr, out, nullptr);
    return;
  }
  Eigen::VectorXd my;
  mass->times(y, my);
  out.resize(y.size());
  const int bs = rows.bs;
  tbb::parallel_for(tbb::blocked_range<int>(0, rows.elements(), 64),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int e = range.begin(); e != range.end(); ++e) {
                        const Eigen::Index base = static_cast<Eigen::Index>(e) * bs;
                        rows.rowProduct(e, y.data(), out.data() + base);
                        out.segment(base, bs) =
                            (out.segment(base, bs) - step.cM * my.segment(base, bs)) / step.cK;
                      }
                    });
}

Eigen::VectorXd DynamicSolver::Impl::solve(const ImplicitStep& step, StepReport& report) {
  stepLength = step.dt;
  const bool matrixChanged = assembleSystem(step, report);
  // Contact (physics/contact/contact.h): K_c and the friction damping C_t enter like K and D.
  // With U_{n+1} = u0 + cU x and V_{n+1} = v0 + cV x, the contact force
  // f_c - K_c (U_{n+1} - U_n) - C_t V_{n+1} adds forceScale (cU K_c + cV C_t) to the matrix
  // and forceScale (f_c - K_c (u0 - U_n) - C_t v0) to the right-hand side.
  ContactLinearization terms;
  if (contact) {
    const Stopwatch tq;
    terms = contact->linearize(state.u, state.v, step.time, step.dt);
    report.assemblySeconds += tq.seconds();
  }
  auto contactRhs = [&]() {
    Eigen::VectorXd add = terms.force - terms.stiffness * (step.u0 - state.u);
    if (terms.damping.nonZeros() > 0 && step.v0.size() > 0) add -= terms.damping * step.v0;
    return Eigen::VectorXd(step.forceScale * add);
  };
  const Stopwatch t2;
  stepSolver->beginStep();
  const int solves = solvesPerPass(step);
  const int maxPasses = contact ? contact->options().maxPasses : 1;
  const Eigen::VectorXd& f = forceAtU().f;
  report.solves = 0;
  double notSolving = 0.0;  // rotations and forces of the corrections, contact updates
  Eigen::VectorXd x;
  for (int pass = 1;; ++pass) {
    report.contacts = terms.contacts;
    report.contactPasses = pass;
    const Eigen::VectorXd base =
        terms.empty() ? step.rhs : Eigen::VectorXd(step.rhs + contactRhs());
    if (terms.empty() && byRows) {
      stepSolver->prepare(rows, matrixChanged, report);
    } else if (terms.empty()) {
      stepSolver->prepare(matrix, matrixChanged, report);
    } else if (byRows && terms.contacts <= kContactsOutsidePreconditioner) {
      contactTerms = (step.forceScale * step.cU) * terms.stiffness;
      if (terms.damping.nonZeros() > 0) contactTerms += (step.forceScale * step.cV) * terms.damping;
      stepSolver->prepareWithAddedTerms(rows, contactTerms, matrixChanged, report);
    } else {
      contactMatrix = csrMatrix() + (step.forceScale * step.cU) * terms.stiffness;
      if (terms.damping.nonZeros() > 0)
        contactMatrix += (step.forceScale * step.cV) * terms.damping;
      stepSolver->prepareWithContact(contactMatrix, report);
    }
    // A first solve that corrections will follow needs an error well below the first
    // correction's size only (the last step's is the estimate); the last solve meets the
    // solver's tolerance.
    const double tolerance =
        solves > 1 && contractionRate < 1.0 ? kFirstSolveShare * firstCorrection : 0.0;
    x = stepSolver->solve(base - step.forceScale * f, pass == 1 ? step.guess : x, report,
                          tolerance);
    ++report.solves;
    x = correct(step, base, std::move(x), solves, report, notSolving);
    // The active set: contacts that would pull leave, points that ended inside join.
    if (!contact || pass >= maxPasses) break;
    const Stopwatch tq;
    const bool changed = contact->adjust(step.u0 + step.cU * x);
    if (changed) terms = contact->relinearize();
    const double adjusting = tq.seconds();
    report.assemblySeconds += adjusting;
    notSolving += adjusting;
    if (!changed) break;
  }
  report.solveSeconds = t2.seconds() - notSolving;
  if (contact) report.contactQuerySeconds = contact->takeQuerySeconds();
  stepSolver->endStep(report);
  return x;
}

BodyState DynamicSolver::Impl::bodyState() const {
  BodyState s;
  s.elastic = forceAtU().energy;
  s.gravity = -loads.gravity.dot(state.u);
  for (std::size_t k = 0; k < loads.tractions.size(); ++k)
    if (inForce(k, state.t)) s.tractionPotential -= loads.tractions[k].dot(state.u);
  const Eigen::VectorXd q = stiffness->undeformed() + state.u;  // x - o + u
  Eigen::VectorXd mv;
  massTimes(state.v, mv);
  s.kinetic = 0.5 * state.v.dot(mv);
  const int n = basis->size(), bs = 3 * n;
  Vec3 first = Vec3::Zero();
  for (std::size_t i = 0; i < mesh->numElements(); ++i) {
    const auto one = mass->integrals(i);
    for (int d = 0; d < 3; ++d) {
      const Eigen::Index base = static_cast<Eigen::Index>(i * bs + d * n);
      s.momentum[d] += one.dot(state.v.segment(base, n));
      first[d] += one.dot(q.segment(base, n));
    }
    // int rho q_a v_b = Q_a . (M V_b)
    Eigen::Matrix3d qv;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        qv(a, b) = q.segment(static_cast<Eigen::Index>(i * bs + a * n), n)
                       .dot(mv.segment(static_cast<Eigen::Index>(i * bs + b * n), n));
    s.angularMomentum += Vec3(qv(1, 2) - qv(2, 1), qv(2, 0) - qv(0, 2), qv(0, 1) - qv(1, 0));
  }
  const double total = mass->total();
  s.centreOfMass = mass->centre() + (total > 0.0 ? Vec3(first / total) : Vec3::Zero());
  return s;
}

double DynamicSolver::Impl::deformedVolume() const {
  const int p = basis->degree();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, mesh->numElements(), 64), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const ElementId e(i);
          if (p == 1) {  // constant gradient
            sum += stiffness->deformationGradient(i, state.u).determinant() * moments->volume(e);
            continue;
          }
          for (const QuadraturePoint& qp : elementQuadrature(*mesh, e, 3 * (p - 1)))
            sum += qp.weight * (Eigen::Matrix3d::Identity() +
                                displacementGradientAt(*basis, state.u, e, qp.point))
                                   .determinant();
        }
        return sum;
      },
      std::plus<double>());
}

DynamicSolver::DynamicSolver(const PolyMesh& mesh, const MomentCache& moments,
                             const DynamicLoads& loads, const DynamicsOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->setup(mesh, moments, loads, options);
  impl_->integrator->init(*impl_, impl_->state);
}
DynamicSolver::DynamicSolver(const PolyMesh& mesh, const MomentCache& moments,
                             const DynamicLoads& loads, const DynamicsOptions& options,
                             DynamicSolver&& before, const std::vector<char>& changed)
    : impl_(std::make_unique<Impl>()) {
  // The step's coefficients carried over: the first force after the edit then warps the step's
  // matrix in the same pass (forceAtU()), as every later one does.
  const bool carried = before.impl_ && before.impl_->coefficientsKnown;
  const double cM = carried ? before.impl_->lastCM : 0.0, cK = carried ? before.impl_->lastCK : 0.0;
  impl_->setup(mesh, moments, loads, options, std::move(before.impl_), &changed);
  impl_->integrator->init(*impl_, impl_->state);
  impl_->lastCM = cM;
  impl_->lastCK = cK;
  impl_->coefficientsKnown = carried;
}
DynamicSolver::~DynamicSolver() = default;
DynamicSolver::DynamicSolver(DynamicSolver&&) noexcept = default;
DynamicSolver& DynamicSolver::operator=(DynamicSolver&&) noexcept = default;

const DgBasis& DynamicSolver::basis() const { return *impl_->basis; }
std::size_t DynamicSolver::elementsComputed() const { return impl_->elementsComputed; }
SolverKind DynamicSolver::solverKind() const { return impl_->stepSolver->kind(); }
const DynamicsOptions& DynamicSolver::options() const { return impl_->options; }
std::size_t DynamicSolver::dofs() const { return static_cast<std::size_t>(impl_->state.u.size()); }
double DynamicSolver::time() const { return impl_->state.t; }
const Eigen::VectorXd& DynamicSolver::displacement() const { return impl_->state.u; }
const Eigen::VectorXd& DynamicSolver::velocity() const { return impl_->state.v; }
const std::vector<std::size_t>& DynamicSolver::clampFaces() const { return impl_->clampFaces; }
const std::vector<std::size_t>& DynamicSolver::tractionFaces() const {
  return impl_->tractionFaces;
}
const Vec3& DynamicSolver::referencePoint() const { return impl_->mass->centre(); }
double DynamicSolver::mass() const { return impl_->mass->total(); }

void DynamicSolver::setState(double t, const Eigen::VectorXd& displacement,
                             const Eigen::VectorXd& velocity) {
  Impl& m = *impl_;
  if (displacement.size() != m.state.u.size() || velocity.size() != m.state.v.size())
    throw std::invalid_argument("DynamicSolver::setState: vectors of the wrong size");
  m.state.t = t;
  m.state.u = displacement;
  m.state.v = velocity;
  m.stateChanged();
  m.contractionRate = 1.0;         // the corrections' rate was measured on another motion
  m.integrator->init(m, m.state);  // BDF2 starts again with a backward Euler step
}

StepReport DynamicSolver::step(double dt) {
  Impl& m = *impl_;
  StepReport report = m.integrator->step(m, m.state, dt);
  m.stateChanged();  // the rotations and the force belong to the old displacement
  // Those of the new one, which the next step and the state's energy both need: counted here.
  const Impl::ForceAtU& at = m.forceAtU();
  report.rotationSeconds += at.rotationSeconds;
  report.assemblySeconds += at.forceSeconds;
  return report;
}

void DynamicSolver::setContact(ContactModel* contact) {
  impl_->contact = contact;
  impl_->stepSolver->reset();
}
CgPreconditioner DynamicSolver::preconditioner() const {
  return impl_->stepSolver->preconditioner();
}
void DynamicSolver::startWith(CgPreconditioner preconditioner) {
  impl_->stepSolver->startWith(preconditioner);
}

BodyState DynamicSolver::state() const { return impl_->bodyState(); }

Eigen::VectorXd DynamicSolver::elasticForce() const { return impl_->forceAtU().f; }
Eigen::VectorXd DynamicSolver::externalForce(double t) const { return impl_->externalForce(t); }
double DynamicSolver::deformedVolume() const { return impl_->deformedVolume(); }

Eigen::VectorXd DynamicSolver::affineField(const Eigen::Matrix3d& a, const Vec3& b,
                                           const Vec3& c) const {
  const Impl& m = *impl_;
  const std::size_t ne = m.mesh->numElements();
  const int n = m.basis->size(), bs = 3 * n;
  Eigen::VectorXd out(static_cast<Eigen::Index>(ne) * bs);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    for (int d = 0; d < 3; ++d)
      out.segment(static_cast<Eigen::Index>(i * bs + d * n), n) =
          affineCoefficients(*m.basis, ElementId(i), b[d], a.row(d).transpose(), c);
  });
  return out;
}

std::vector<double> DynamicSolver::vonMises() const {
  const Impl& m = *impl_;
  std::vector<double> out(m.mesh->numElements());
  const double mu = m.options.material.mu(), lambda = m.options.material.lambda();
  tbb::parallel_for(std::size_t(0), out.size(), [&](std::size_t i) {
    const Eigen::Matrix3d f = m.stiffness->deformationGradient(i, m.state.u);
    const Eigen::Matrix3d local =
        m.options.corotational ? Eigen::Matrix3d(polarRotation(f).transpose() * f) : f;
    const Eigen::Matrix3d eps = 0.5 * (local + local.transpose()) - Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d sigma = 2 * mu * eps + lambda * eps.trace() * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d dev = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
    out[i] = std::sqrt(1.5 * dev.squaredNorm());
  });
  return out;
}

std::vector<Eigen::Matrix3d> DynamicSolver::rotations() const { return impl_->forceAtU().r; }

}  // namespace polydg
