#include "model/simulation.h"

#include "model/tet_simulation.h"

#include <cmath>
#include <unordered_set>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/names.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

Eigen::Matrix3d skew(const Vec3& w) {
  Eigen::Matrix3d s;
  s << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return s;
}

DynamicsOptions dynamicsOptions(const Scene& scene) {
  DynamicsOptions o;
  o.material = scene.material;
  o.discretization = scene.discretization;
  o.solver.kind = scene.solver;
  o.corotational = scene.corotational;
  o.integrator = scene.integrator;
  o.damping = scene.damping;
  return o;
}

/// Each vertex's share of the surface area: a third of its triangles' areas.
std::vector<double> vertexAreas(const TriangleSurface& surface) {
  std::vector<double> areas(surface.vertices.size(), 0.0);
  for (const auto& t : surface.triangles) {
    const Vec3 &a = surface.vertices[t[0]], &b = surface.vertices[t[1]],
               &c = surface.vertices[t[2]];
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (std::uint32_t v : t) areas[v] += third;
  }
  return areas;
}

/// The scene's obstacles; `diagonal` is the body's bounding-box diagonal.
std::vector<Obstacle> makeObstacles(const Scene& scene, double diagonal,
                                    SimulationEmbedding& info) {
  std::vector<Obstacle> obstacles;
  for (std::size_t k = 0; k < scene.obstacles.size(); ++k) {
    const SceneObstacle& o = scene.obstacles[k];
    const std::string name = "obstacles[" + std::to_string(k) + "]";
    try {
      if (o.below) {
        obstacles.push_back(Obstacle::halfSpace(*o.below, o.velocity));
      } else {
        TriangleSurface surface;
        try {
          surface = readSurface(o.mesh);
        } catch (const std::runtime_error& e) {
          throw InputError(name + ": " + e.what());
        }
        DistanceFieldOptions field;
        field.voxel =
            o.voxel > 0.0 ? o.voxel : std::min(bounds(surface).diagonal().norm(), diagonal) / 100.0;
        field.exteriorBand = 3.0 * field.voxel;
        // Deep enough for any penetration worth simulating: a quarter of the body.
        field.interiorBand = std::max(3.0 * field.voxel, 0.25 * diagonal);
        obstacles.push_back(Obstacle::fromSurface(surface, field, o.velocity));
      }
    } catch (const std::invalid_argument& e) {
      throw InputError(name + (o.mesh.empty() ? "" : " (" + o.mesh + ")") + ": " + e.what());
    }
    info.obstacleSetupSeconds.push_back(obstacles.back().setupSeconds());
    info.obstacleVoxels.push_back(obstacles.back().activeVoxels());
  }
  return obstacles;
}

}  // namespace

std::string solverAction(const StepReport& r, SolverKind kind, bool first) {
  if (kind == SolverKind::Cholesky)
    return first            ? "cholesky: factorized"
           : r.refactorized ? "cholesky: refactorized"
                            : "cholesky: factorization reused";
  const std::string cg =
      "cg (" +
      (r.preconditionerSwitched ? toString(CgPreconditioner::BlockJacobi) + ", then " : "") +
      toString(r.preconditioner) + "): ";
  return cg + (first || r.preconditionerRebuilt ? "preconditioner built" : "preconditioner reused");
}

namespace {

/// Stops the run at an edit whose checks failed (the model is then broken, as after cut()).
void requirePassed(const OperationCheck& check, const char* what, double time) {
  if (!check.passed)
    throw CheckFailure(std::string(what) + " at t = " + std::to_string(time) + " failed (" +
                       check.failure + "); the simulation stops there");
}

/// Relative change from a to b.
double relativeChange(double a, double b) {
  return std::abs(a - b) / std::max(std::abs(a), 1e-300);
}

}  // namespace

SimulationReport Model::simulate(const Scene& scene, const SimulateOptions& options) {
  if (scene.tetMethod) {
    state_->requireUsable();
    const TetMesh tets = toTetMesh(mesh());
    Eigen::VectorXd u;
    SimulationReport report = simulateOnTets(tets, scene, options, &u);
    // The final displacement as the model's solution.
    const Stopwatch finish;
    state_->adoptTetSolution(tets, u, scene.material, moments(2));
    report.finishSeconds = finish.seconds();
    report.wallSeconds += report.finishSeconds;
    return report;
  }
  return Simulation(*this, *state_, scene, options).run();
}

// --- setup -----------------------------------------------------------------------------------

Simulation::Simulation(Model& model, Model::State& state, const Scene& scene,
                       const SimulateOptions& options)
    : model_(model),
      state_(state),
      scene_(scene),
      options_(options),
      dynamics_(dynamicsOptions(scene)),
      loads_{scene.fixed, scene.loads, scene.gravity},
      families_(0) {
  state_.requireUsable();
  refuseInvalid([&] { checkScene(scene_); });
  state_.requireValid();
  report_.scene = scene_;
  std::vector<const FaceSelector*> loadRegions;
  for (const TimedTraction& t : scene_.loads) loadRegions.push_back(&t.where);
  state_.checkSelections(scene_.fixed, loadRegions, report_.fixedFaces, report_.loadFaces,
                         "the fixed region", "the load on");
  if (!options_.outputDir.empty()) {
    series_ = std::make_unique<TimeSeries>(options_.outputDir, options_.encoding);
    report_.pvd = series_->pvd();
  }
  integratedBefore_ = model_.facesIntegrated();
  solver_.emplace(makeSolver());
  report_.elements = model_.mesh().numElements();
  report_.dofs = solver_->dofs();
  families_ = RefinementFamilies(model_.mesh().numElements());
  setInitialVelocity();
  report_.initial = solver_->state();
  embedSurface();
  setUpContact();
  report_.setupSeconds = wall_.seconds();  // the checks, the solver, the embedding and contact
}

DynamicSolver Simulation::makeSolver() {
  return DynamicSolver(model_.mesh(), model_.moments(2 * scene_.discretization.basis.degree),
                       loads_, dynamics_);
}

/// The solver of the mesh `edit` changed: it takes over the old one's blocks of the elements
/// the edit left alone, and the old one's other memory is freed before the new one allocates
/// its own (fresh pages faulted in and zeroed took most of a new solver's time on this
/// machine). The new one starts with the preconditioner the old one had come to (the edit
/// changes a few elements, not the conditioning of the body). Returns the elements whose
/// blocks were computed.
std::size_t Simulation::replaceSolver(const OperationReport& edit) {
  const CgPreconditioner used = solver_->preconditioner();
  std::vector<char> changed(model_.mesh().numElements(), 0);
  for (ElementId e : edit.touched) changed[e.index()] = 1;
  for (const auto& [id, sources] : edit.lineage.changed) changed[id] = 1;  // made or moved
  DynamicSolver before = std::move(*solver_);
  solver_.reset();
  solver_.emplace(model_.mesh(), model_.moments(2 * scene_.discretization.basis.degree), loads_,
                  dynamics_, std::move(before), changed);
  solver_->startWith(used);
  return solver_->elementsComputed();
}

/// The scene's initial velocity, linear and angular about the centre of mass; undeformed.
void Simulation::setInitialVelocity() {
  const Vec3 c = solver_->state().centreOfMass;
  const Eigen::VectorXd v = solver_->affineField(skew(scene_.angularVelocity), scene_.velocity, c);
  solver_->setState(0.0, Eigen::VectorXd::Zero(v.size()), v);
}

/// The surface carried along: the scene's "embed", or the contact points on the surface.
void Simulation::embedSurface() {
  contactOnSurface_ = !scene_.obstacles.empty() && scene_.contact.points == ContactPoints::Surface;
  if (!scene_.embed.enabled && !contactOnSurface_) return;
  const Stopwatch te;
  EmbeddingOptions eo;
  eo.support = scene_.embed.support;
  surface_ = model_.embedSurface(scene_.embed.file, scene_.discretization.basis.degree, eo,
                                 &solver_->basis());
  SimulationEmbedding& info = report_.embedding;
  info.surface = surface_.file;
  info.points = surface_.surface.vertices.size();
  info.triangles = surface_.surface.triangles.size();
  info.samples = surface_.embedding->numSamples();
  info.pieces = surface_.embedding->numPieces();
  info.outside = surface_.embedding->outside();
  info.weightNonzeros = surface_.embedding->weightNonzeros();
  info.storedNonzeros = surface_.embedding->storedNonzeros();
  info.setupSeconds = te.seconds();
  report_.setupSeconds += info.setupSeconds;
}

/// The obstacles and the penalty contact of the scene's points with them.
void Simulation::setUpContact() {
  if (scene_.obstacles.empty()) return;
  const Stopwatch to;
  SimulationEmbedding& info = report_.embedding;
  const double diagonal = meshBounds(model_.mesh()).diagonal().norm();
  obstacles_ = makeObstacles(scene_, diagonal, info);
  contactOptions_.stiffness = scene_.contact.stiffness > 0.0
                                  ? scene_.contact.stiffness
                                  : 100.0 * scene_.material.youngsModulus / diagonal;
  contactOptions_.friction = scene_.contact.friction;
  contactOptions_.slipSpeed =
      scene_.contact.slipSpeed > 0.0 ? scene_.contact.slipSpeed : 0.01 * diagonal;
  if (contactOnSurface_) areas_ = vertexAreas(surface_.surface);
  makeContact();
  info.contactPointKind = contactOnSurface_ ? "surface" : "nodes";
  info.contactStiffness = contactOptions_.stiffness;
  info.slipSpeed = contactOptions_.slipSpeed;
  report_.setupSeconds += to.seconds();
}

/// The contact model of the current points (the surface's, or the mesh's boundary nodes).
void Simulation::makeContact() {
  const SurfaceEmbedding* points = surface_.embedding.get();
  if (!contactOnSurface_) {
    nodes_ = std::make_unique<SurfaceEmbedding>(
        SurfaceEmbedding::boundaryNodes(model_.mesh(), solver_->basis(), areas_));
    points = nodes_.get();
  }
  contact_ = std::make_unique<ContactModel>(*points, areas_, obstacles_, contactOptions_);
  solver_->setContact(contact_.get());
  report_.embedding.contactPoints = points->numPoints();
}

// --- the run -----------------------------------------------------------------------------------

SimulationReport Simulation::run() {
  cutsDue(0.0);
  writeFrame(0);
  for (int k = 1; k <= scene_.steps; ++k) {
    step(k);
    const bool cut = cutsDue(solver_->time());
    const bool adapted = adaptationDue(k);
    if (cut || adapted) freshSolver_ = true;  // a new solver after the edit
    if (k % scene_.outputEvery == 0 || k == scene_.steps || editedSinceFrame_) writeFrame(k);
    if (options_.progress) options_.progress({k, scene_.steps, solver_->time()});
  }
  const Stopwatch tf;
  finish();
  report_.finishSeconds = tf.seconds();
  report_.wallSeconds = wall_.seconds();
  return std::move(report_);
}

/// One time step of scene.dt and its report.
void Simulation::step(int k) {
  const Stopwatch ts;
  SimulationStep step;
  try {
    step.step = solver_->step(scene_.dt);
  } catch (const std::runtime_error& e) {
    // The step solver's message ends with what helps.
    throw CheckFailure("step " + std::to_string(k) + " (t = " + std::to_string(solver_->time()) +
                       "): " + e.what());
  }
  step.seconds = ts.seconds();
  // The cuts made at the last step boundary: this step completes their latency.
  for (std::size_t i = report_.cuts.size() - cutsAwaitingStep_; i < report_.cuts.size(); ++i) {
    report_.cuts[i].nextStepSeconds = step.seconds;
    report_.cuts[i].nextStepPreconditionerSeconds = step.step.preconditionerSeconds;
  }
  cutsAwaitingStep_ = 0;
  step.solver = solverAction(step.step, solver_->solverKind(), freshSolver_);
  freshSolver_ = false;
  const Stopwatch tr;
  step.state = solver_->state();
  if (contact_) {
    step.contact = contact_->measure(solver_->displacement(), solver_->time());
    step.collisionSeconds = step.step.contactQuerySeconds + contact_->takeQuerySeconds();
  }
  report_.stateSeconds += tr.seconds();
  report_.rotationSeconds += step.step.rotationSeconds;
  report_.assemblySeconds += step.step.assemblySeconds;
  report_.solveSeconds += step.step.solveSeconds;
  report_.steps.push_back(step);
}

/// The model keeps the last mesh and the final displacement as its solution.
void Simulation::finish() {
  const int degree = scene_.discretization.basis.degree;
  state_.adoptSolution(std::make_unique<DgBasis>(solver_->basis()), solver_->displacement(),
                       scene_.material, model_.moments(2 * degree));
  report_.facesIntegrated = model_.facesIntegrated() - integratedBefore_;
}

// --- edits -----------------------------------------------------------------------------------

/// The cuts whose time has come: at the first step boundary at or after their time, each through
/// the model's cut(); whether any was made.
bool Simulation::cutsDue(double t) {
  bool made = false;
  while (nextCut_ < scene_.cuts.size() && scene_.cuts[nextCut_].time <= t + 1e-9 * scene_.dt) {
    const TimedCut& timed = scene_.cuts[nextCut_++];
    const Stopwatch tc;
    SimulationCut record;
    record.time = solver_->time();
    record.elementsBefore = model_.mesh().numElements();
    const DgBasis oldBasis = solver_->basis();
    const Eigen::VectorXd oldU = solver_->displacement(), oldV = solver_->velocity();
    record.report = model_.cut(timed.request);
    requirePassed(record.report.check, "the cut", record.time);
    record.elementsAfter = model_.mesh().numElements();
    record.cutSeconds = tc.seconds();
    record.checkSeconds = record.report.check.seconds;
    families_.afterCut(record.report.lineage, record.elementsAfter);
    const Stopwatch ts;
    record.solverElements = replaceSolver(record.report);
    record.solverSeconds = ts.seconds();
    const Stopwatch tt;
    TransferCounts counts;
    afterEdit(record.report.lineage, oldBasis, oldU, oldV, record.time, false, &counts);
    record.exact = counts.exact;
    record.extended = counts.extended;
    record.transferSeconds = tt.seconds();
    record.seconds = tc.seconds();
    report_.cutSeconds += record.seconds;
    report_.cuts.push_back(std::move(record));
    ++cutsAwaitingStep_;
    editedSinceFrame_ = true;
    made = true;
  }
  return made;
}

/// Refinement by stress (scene "adapt") every adapt.every steps, or, when nothing is to be
/// refined, the coarsening of families that relaxed; whether the mesh changed.
bool Simulation::adaptationDue(int k) {
  const SceneAdapt& a = scene_.adapt;
  if (!a.enabled || k % a.every != 0) return false;
  const Stopwatch tr;
  const ElementFields fields = elementFields(model_.mesh(), solver_->basis(),
                                             model_.moments(2 * scene_.discretization.basis.degree),
                                             solver_->displacement(), scene_.material);
  RefineRequest request = families_.refinement(fields, a);
  // A refinement if any element is marked, else a coarsening; the same steps around either.
  const bool coarsening = request.elements.empty();
  const CoarsenRequest coarsenRequest =
      coarsening ? families_.coarsening(fields, a) : CoarsenRequest{};
  if (coarsening && coarsenRequest.groups.empty()) {
    report_.cutSeconds += tr.seconds();  // the marking, which found nothing to do
    return false;
  }
  SimulationRefinement record;
  record.time = solver_->time();
  record.elementsBefore = model_.mesh().numElements();
  const BodyState before = solver_->state();
  const DgBasis oldBasis = solver_->basis();
  const Eigen::VectorXd oldU = solver_->displacement(), oldV = solver_->velocity();
  OperationReport edit;
  if (coarsening) {
    record.coarsened = coarsenRequest.groups.size();
    const CoarsenReport c = model_.coarsen(coarsenRequest);
    requirePassed(c.operation.check, "the coarsening", record.time);
    edit = c.operation;
    families_.afterCoarsening(edit.lineage, model_.mesh().numElements());
  } else {
    if (a.split == RefineSplit::Octants) request.directions.clear();
    record.marked = request.elements.size();
    const RefineReport r = model_.refine(request);
    requirePassed(r.operation.check, "the refinement", record.time);
    edit = r.operation;
    std::unordered_set<std::uint32_t> refined;
    for (ElementId e : request.elements) refined.insert(e.value);
    families_.afterRefinement(edit.lineage, model_.mesh().numElements(), refined);
  }
  record.elementsAfter = model_.mesh().numElements();
  replaceSolver(edit);
  TransferCounts counts;
  afterEdit(edit.lineage, oldBasis, oldU, oldV, record.time, coarsening, &counts);
  record.exact = counts.exact;
  record.extended = counts.extended;
  const BodyState after = solver_->state();
  record.momentumChange =
      (after.momentum - before.momentum).norm() / std::max(before.momentum.norm(), 1e-300);
  // A coarsening's projection can only lose kinetic energy: its change is the signed loss.
  record.kineticChange =
      coarsening ? (before.kinetic - after.kinetic) / std::max(std::abs(before.kinetic), 1e-300)
                 : relativeChange(before.kinetic, after.kinetic);
  record.elasticChange = relativeChange(before.elastic, after.elastic);
  record.seconds = tr.seconds();
  report_.cutSeconds += record.seconds;
  report_.refinements.push_back(record);
  editedSinceFrame_ = true;
  return true;
}

/// After an edit: the new solver takes the displacement and velocity through the lineage (a
/// coarsening, `project`, projects them onto the merged elements instead: L2, so mass and
/// momentum are kept), and the embedded surface's weights and the contact points follow the
/// new elements.
void Simulation::afterEdit(const ElementLineage& lineage, const DgBasis& oldBasis,
                           const Eigen::VectorXd& oldU, const Eigen::VectorXd& oldV, double time,
                           bool project, TransferCounts* counts) {
  const std::vector<Eigen::VectorXd> moved =
      project ? projectFields(oldBasis, {&oldU, &oldV}, solver_->basis(), lineage)
              : transferFields(oldBasis, {&oldU, &oldV}, solver_->basis(), lineage, counts);
  solver_->setState(time, moved[0], moved[1]);
  if (!surface_.embedding && !contact_) return;
  const std::size_t elements = model_.mesh().numElements();
  std::vector<ElementId> sources(elements);
  for (std::size_t e = 0; e < elements; ++e) {
    const std::vector<ElementId> from = lineage.sources(ElementId(e));
    sources[e] = from.size() == 1 ? from.front() : ElementId();
  }
  if (surface_.embedding)
    report_.embedding.updates.push_back(
        surface_.embedding->update(model_.mesh(), solver_->basis(), sources));
  if (contact_) {
    if (contactOnSurface_)
      contact_->refresh();  // the same points, new weights
    else
      makeContact();  // the boundary nodes changed
    solver_->setContact(contact_.get());
  }
}

// --- output ----------------------------------------------------------------------------------

/// A frame of the time series (with the deformed surface if the scene embeds one).
void Simulation::writeFrame(int k) {
  if (series_ && editedSinceFrame_) series_->meshChanged();
  editedSinceFrame_ = false;
  if (!series_) return;
  const Stopwatch t;
  const bool showSurface = scene_.embed.enabled;
  Eigen::Matrix<double, Eigen::Dynamic, 3> displacement;
  if (showSurface) {
    const Stopwatch ts;
    displacement = surface_.embedding->displacements(solver_->displacement());
    report_.surfaceSeconds += ts.seconds();
  }
  report_.frames.push_back(series_->write(model_.mesh(), *solver_, k,
                                          showSurface ? &surface_.surface : nullptr,
                                          showSurface ? &displacement : nullptr));
  report_.outputSeconds += t.seconds();
}

}  // namespace polydg
