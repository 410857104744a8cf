#include "polydg/model/model.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <sstream>

#include <tbb/parallel_invoke.h>
#include <unistd.h>

#include "model/files.h"
#include "model/tet_solve.h"
#include "model_state.h"
#include "physics/checks/mesh_checks.h"
#include "physics/dg/reactions.h"
#include "physics/solvers/error_estimator.h"
#include "physics/solvers/static_solver.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/model/names.h"
#include "polydg/model/provenance.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg {

namespace fs = std::filesystem;

double medianElementVolume(const PolyMesh& mesh) {
  if (mesh.numElements() == 0) return 0.0;
  std::vector<double> volumes = signedVolumes(mesh);
  std::nth_element(volumes.begin(), volumes.begin() + volumes.size() / 2, volumes.end());
  return volumes[volumes.size() / 2];
}

Model::Model(PolyMesh mesh, Provenance provenance) : state_(std::make_unique<State>()) {
  if (mesh.numElements() == 0)
    throw InputError("the mesh has no elements; there is nothing to model");
  if (!(provenance.referenceVolume > 0.0) || !std::isfinite(provenance.referenceVolume)) {
    // Not positive for an inverted or flat mesh, which the checks report; edits refuse it.
    provenance.referenceVolume = medianElementVolume(mesh);
    provenance.referenceKind = ReferenceKind::MedianElement;
  }
  state_->provenance = std::move(provenance);
  state_->mesh = std::move(mesh);
}

Model::~Model() = default;
Model::Model(Model&&) noexcept = default;
Model& Model::operator=(Model&&) noexcept = default;

const PolyMesh& Model::mesh() const { return state_->currentMesh(); }
const Provenance& Model::provenance() const { return state_->provenance; }

double Model::volume() const {
  if (state_->editor) return state_->editor->volume();
  const PolyMesh& mesh = state_->mesh;
  double v = 0.0;
  if (const MomentCache* m = state_->moments.get())
    for (std::size_t e = 0; e < mesh.numElements(); ++e) v += m->volume(ElementId(e));
  else
    for (std::size_t e = 0; e < mesh.numElements(); ++e) v += signedVolume(mesh, ElementId(e));
  return v;
}

const MomentCache& Model::moments(int degree) {
  State& s = *state_;
  s.requireUsable();
  // Degree 2 at least: every DG operation of degree 1 reads those, so a first request for
  // volumes alone does not cost a second integration later.
  degree = std::max(degree, 2);
  if (s.editor) return s.editor->requireMoments(degree);
  if (!s.moments || s.moments->degree() < degree) {
    if (s.moments) s.retiredIntegrations += s.moments->facesIntegrated();
    s.moments = std::make_unique<MomentCache>(s.mesh, degree);
    s.moments->update();
  }
  return *s.moments;
}

std::size_t Model::facesIntegrated() const {
  const State& s = *state_;
  if (s.editor) return s.retiredIntegrations + s.editor->facesIntegrated();
  return s.retiredIntegrations + (s.moments ? s.moments->facesIntegrated() : 0);
}

// --- creation ------------------------------------------------------------------------------

std::vector<std::string> MeshReport::failures() const {
  std::vector<std::string> out;
  if (!meshing.geometry.passed) {
    if (meshing.geometry.messages.empty()) out.push_back("geometry: the new mesh is invalid");
    for (const std::string& m : meshing.geometry.messages) out.push_back("geometry: " + m);
  }
  for (std::string& m : dg.failures()) out.push_back(std::move(m));
  return out;
}

namespace {

/// A file written under a temporary name beside `path` and renamed into place by commit();
/// removed if never committed.
class PendingFile {
 public:
  explicit PendingFile(std::string path)
      : path_(std::move(path)), temporary_(path_ + ".pending-" + std::to_string(::getpid())) {}
  ~PendingFile() {
    std::error_code ignored;
    if (!committed_) fs::remove(temporary_, ignored);
  }
  const std::string& temporary() const { return temporary_; }
  /// In a handler of `e`: a writer's error that names the temporary file, as one about the
  /// file asked for; any other error as it is.
  std::exception_ptr failure(const std::exception& e) const {
    std::string message = e.what();
    std::size_t at = message.find(temporary_);
    if (at == std::string::npos) return std::current_exception();
    for (; at != std::string::npos; at = message.find(temporary_, at + path_.size()))
      message.replace(at, temporary_.size(), path_);
    return std::make_exception_ptr(
        OutputError(message + "; check the output's folder and its free space"));
  }
  void commit() {
    std::error_code ec;
    fs::rename(temporary_, path_, ec);
    if (ec) throw OutputError("cannot write " + path_ + ": " + ec.message());
    committed_ = true;
  }

 private:
  std::string path_, temporary_;
  bool committed_ = false;
};

/// Writes the tets of `mesh` (tetrahedralize()) to `path` with the provenance as field data.
TetOutputReport writeTets(const PolyMesh& mesh, const Provenance& provenance,
                          double polyhedralVolume, const std::string& path) {
  TetOutputReport r;
  const TetMesh tets = tetrahedralize(mesh, &r.split);
  r.vertices = tets.numVertices();
  // Neumaier's compensated sum: a plain one drifts by 5e-14 relative over 3e4 tets of a torus.
  double carry = 0.0;
  for (std::size_t t = 0; t < tets.numTets(); ++t) {
    const double v = sixVolume(tets, t) / 6.0, sum = r.volume + v;
    carry += std::abs(r.volume) >= std::abs(v) ? (r.volume - sum) + v : (v - sum) + r.volume;
    r.volume = sum;
  }
  r.volume += carry;
  r.polyhedralVolume = polyhedralVolume;
  r.volumeRelDifference = (r.volume - polyhedralVolume) / polyhedralVolume;
  const Stopwatch write;
  writeTetVtu(tets, path, {}, provenanceFieldData(provenance));
  r.writeSeconds = write.seconds();
  return r;
}

}  // namespace

Model Model::fromSurface(const TriangleSurface& surface, const MeshOptions& options,
                         MeshReport& report, const std::string& source) {
  const Stopwatch wall;
  if (options.momentDegree != 0 && (options.momentDegree < 2 || options.momentDegree > 6))
    throw InputError("the moment degree to keep must be 0 or 2..6");
  if (options.tets && options.output.empty())
    throw InputError("the tets are written to the output file: give one");
  if (!options.output.empty()) requireWritable(options.output);  // before the work, not after
  MeshingOptions meshing;
  meshing.cellSize = options.cellSize;
  meshing.cellsAlongLongest = options.cells;
  meshing.repair = options.repair;
  meshing.sliverTau = options.sliverFraction;
  // Octree slicing: the grid 2^levels times coarser than the finest cell, with at least two
  // cells along the longest side.
  double finest = 0.0;
  int levels = 0;
  if (options.adaptive) {
    const Box3 box = bounds(surface);
    const double longest = box.diagonal().maxCoeff();
    if (!(longest > 0.0)) throw InputError("the surface is flat; there is no volume to mesh");
    if (!options.cellSize && options.cells < 1)
      throw InputError("the number of cells must be at least 1");
    finest = options.cellSize ? *options.cellSize : longest / options.cells;
    while (levels < 10 && std::ldexp(finest, levels + 1) * 2.0 <= longest) ++levels;
    meshing.cellSize = std::ldexp(finest, levels);
    meshing.cellsAlongLongest = 0;
    meshing.octreeLevels = levels;
  }
  meshing.progress = options.progress;
  meshing.checkGeometry = false;  // below, beside the checks and the writing
  MeshingResult meshed = meshSurface(surface, meshing);
  report.meshing = std::move(meshed.report);
  const Grid& grid = report.meshing.grid;

  Provenance provenance;
  provenance.source = source;
  provenance.cellSize = options.adaptive ? finest : grid.cellSize;
  provenance.referenceVolume = provenance.cellSize * provenance.cellSize * provenance.cellSize;
  provenance.referenceKind = ReferenceKind::GridCell;
  provenance.sliverFraction = options.sliverFraction;
  Model model(std::move(meshed.mesh), provenance);
  if (options.adaptive) {
    report.levels = levels;
    report.coarseCellSize = grid.cellSize;
    report.elementsPerLevel.assign(static_cast<std::size_t>(levels) + 1, 0);
    for (int l : meshed.elementLevels) report.elementsPerLevel[static_cast<std::size_t>(l)] += 1;
    report.elementLevels = std::move(meshed.elementLevels);
    report.refineSeconds = report.meshing.slice.secondsOctree;
  }
  const PolyMesh& mesh = model.mesh();

  // The mesh is validated, DG-checked and written side by side: all three only read it, and
  // the writer's serial part (formatting and I/O) fills the gaps of the checks' parallel
  // loops. The DG checks presume a geometrically valid mesh (faces shared properly), so their
  // outcome counts only if the validation passed; the file is kept only if everything passed.
  std::optional<PendingFile> file;
  if (!options.output.empty()) file.emplace(options.output);
  std::exception_ptr writeFailure, dgFailure;
  MeshCheck dg;
  // The validation and the file both need every element's volume: computed once, beforehand.
  const std::vector<double> volumes = signedVolumes(mesh);
  tbb::parallel_invoke(
      [&] { checkMeshing(mesh, report.meshing, meshed.wholeCells, volumes); },
      [&] {
        if (!options.dgChecks) return;
        try {
          MeshCheckOptions checks;
          checks.geometry = false;
          checks.oneGridCellForAll = !options.adaptive;  // an octree's cells differ in size
          checks.rigidModes = GlobalCheck::Never;
          const MomentCache* moments =
              options.momentDegree > 0 ? &model.moments(options.momentDegree) : nullptr;
          dg = checkMesh(mesh, checks, moments);
        } catch (...) {
          dgFailure = std::current_exception();
        }
      },
      [&] {
        if (!file || options.tets) return;  // the tets are written once the checks passed
        try {
          const Stopwatch write;
          writeVtu(mesh, file->temporary(), {}, {}, {}, {}, provenanceFieldData(provenance),
                   volumes, meshed.wholeCells);
          report.writeSeconds = write.seconds();
        } catch (const std::exception& e) {
          writeFailure = file->failure(e);
        } catch (...) {
          writeFailure = std::current_exception();
        }
      });
  if (options.momentDegree > 0 && !options.dgChecks) model.moments(options.momentDegree);
  if (!report.meshing.geometry.passed) {
    dg = MeshCheck();
    dg.notes.push_back("DG checks skipped: the mesh failed the geometric validation");
  } else if (dgFailure) {
    std::rethrow_exception(dgFailure);
  }
  if (!options.dgChecks) dg.notes.push_back("DG checks skipped (not asked for)");
  report.dg = std::move(dg);
  if (writeFailure) std::rethrow_exception(writeFailure);
  model.state_->valid = report.meshing.geometry.passed;
  if (file && report.passed()) {
    if (options.tets) {
      try {
        report.tets = writeTets(mesh, provenance, report.meshing.outputVolume, file->temporary());
      } catch (const std::exception& e) {
        std::rethrow_exception(file->failure(e));
      }
      report.writeSeconds = report.tets->writeSeconds;
    }
    file->commit();
    report.output = options.output;
  }
  report.wallSeconds = wall.seconds();
  return model;
}

Model Model::read(const std::string& path, ReadReport* report) {
  const Stopwatch watch;
  VtuFieldData fields;
  PolyMesh mesh;
  try {
    if (isTetMeshFile(path)) {
      mesh = toPolyMesh(readTetMesh(path));
    } else {
      mesh = readVtu(path, &fields);
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (mesh.numElements() == 0)
    throw InputError(path + ": the file holds no cells; there is nothing to model");
  const std::optional<Provenance> stored = provenanceFromFieldData(fields);
  Provenance provenance;
  if (stored) {
    provenance = *stored;
  } else {
    provenance.source = path;
  }
  Model model(std::move(mesh), provenance);
  if (report) {
    report->file = path;
    report->elements = model.mesh().numElements();
    report->faces = model.mesh().numFaces();
    report->vertices = model.mesh().numVertices();
    report->provenanceRestored = stored.has_value();
    report->seconds = watch.seconds();
  }
  return model;
}

// --- editing -------------------------------------------------------------------------------

OperationReport Model::cut(const CutRequest& request) {
  State& s = *state_;
  s.requireUsable();
  CutOptions options;
  options.removeSide = request.removeSide;
  options.sliverFraction = request.sliverFraction.value_or(s.provenance.sliverFraction);
  options.checks = request.checks;
  options.checkDegree = request.checkDegree;
  if (request.removeSide < -1 || request.removeSide > 1)
    throw InputError("the side to remove must be +, - or none");
  checkEditOptions(options.sliverFraction, options.checkDegree);
  OperationReport report = s.edit().cut(request.blade, options);
  s.finishEdit(report, request.checks);
  s.provenance.cuts.push_back(request.blade);
  return report;
}

OperationReport Model::mergeSlivers(const MergeRequest& request) {
  State& s = *state_;
  s.requireUsable();
  const double fraction = request.fraction.value_or(s.provenance.sliverFraction);
  checkEditOptions(fraction, request.checkDegree);
  OperationReport report = s.edit().mergeSlivers(fraction, request.checks, request.checkDegree);
  s.finishEdit(report, request.checks);
  return report;
}

// --- checks and solves ---------------------------------------------------------------------

MeshCheck Model::check(const MeshCheckOptions& options) {
  State& s = *state_;
  s.requireUsable();
  refuseInvalid([&] { options.physics.discretization.check(); });
  const bool dg = options.local || options.patchTest != GlobalCheck::Never ||
                  options.rigidModes != GlobalCheck::Never;
  // Integrate (once, for this and every later operation) only what the DG checks read.
  const MomentCache* moments = dg ? &this->moments(2 * options.degree()) : nullptr;
  MeshCheck c = checkMesh(mesh(), options, moments);
  if (c.geometry) s.valid = c.geometry->passed;
  return c;
}

namespace {

/// Boundary faces each selection picks (a selection of zero faces is an error for the caller).
std::vector<std::size_t> countSelected(const PolyMesh& mesh,
                                       const std::vector<const FaceSelector*>& selections) {
  std::vector<std::size_t> counts(selections.size(), 0);
  const double diagonal = meshBounds(mesh).diagonal().norm();
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    if (!mesh.face(FaceId(f)).isBoundary()) continue;
    for (std::size_t i = 0; i < selections.size(); ++i)
      counts[i] += selects(*selections[i], mesh, FaceId(f), diagonal);
  }
  return counts;
}

std::string boxText(const Box3& box) {
  std::ostringstream s;
  s << "[" << box.min().x() << "," << box.min().y() << "," << box.min().z() << "]-["
    << box.max().x() << "," << box.max().y() << "," << box.max().z() << "]";
  return s.str();
}

}  // namespace

void Model::State::requireValid() {
  const PolyMesh& m = currentMesh();
  if (!valid.has_value()) valid = checkGeometry(m).passed;
  if (*valid) return;
  const GeometryCheck v = checkGeometry(m);
  throw CheckFailure("the mesh is invalid (" +
                     (v.messages.empty() ? std::string("see 'polydg check'") : v.messages.front()) +
                     "); run 'polydg check' for details");
}

void Model::State::checkSelections(const std::vector<FaceSelector>& clamps,
                                   const std::vector<const FaceSelector*>& loads,
                                   std::vector<std::size_t>& clampFaces,
                                   std::vector<std::size_t>& loadFaces, const char* clampWord,
                                   const char* loadWord) const {
  const PolyMesh& m = currentMesh();
  std::vector<const FaceSelector*> selections;
  for (const FaceSelector& c : clamps) selections.push_back(&c);
  for (const FaceSelector* t : loads) selections.push_back(t);
  const std::vector<std::size_t> counts = countSelected(m, selections);
  clampFaces.clear();
  loadFaces.clear();
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const bool clamp = i < clamps.size();
    (clamp ? clampFaces : loadFaces).push_back(counts[i]);
    if (counts[i] == 0)
      throw InputError(std::string(clamp ? clampWord : loadWord) + " " + selections[i]->describe() +
                       " selects no boundary face (the mesh spans " + boxText(meshBounds(m)) +
                       "); use a region that meets the boundary");
  }
}

void Model::State::adoptSolution(std::unique_ptr<DgBasis> basis, Eigen::VectorXd coefficients,
                                 const Material& material, const MomentCache& moments) {
  const PolyMesh& m = currentMesh();
  Solution u;
  u.material = material;
  u.basis = std::move(basis);
  u.coefficients = std::move(coefficients);
  u.corners = cornerDisplacements(m, *u.basis, u.coefficients);
  u.fields = elementFields(m, *u.basis, moments, u.coefficients, material);
  solution = std::move(u);
}

void Model::State::adoptTetSolution(const TetMesh& tets, const Eigen::VectorXd& displacement,
                                    const Material& material, const MomentCache& moments) {
  auto basis = std::make_unique<DgBasis>(currentMesh(), moments, BasisOptions{});
  Eigen::VectorXd coefficients = tetCoefficients(tets, displacement, *basis);
  adoptSolution(std::move(basis), std::move(coefficients), material, moments);
}

namespace {

/// The solution's largest displacement, jump and von Mises stress in its report.
SolveReport summarize(const Solution& solution, SolveReport report) {
  report.maxDisplacement = solution.corners.largestNorm();
  for (double j : solution.fields.largestJump) report.maxJump = std::max(report.maxJump, j);
  for (double v : solution.fields.vonMises) report.maxVonMises = std::max(report.maxVonMises, v);
  return report;
}

}  // namespace

void SolveOptions::check() const {
  try {
    material.check();
  } catch (const InvalidOption& e) {
    throw InvalidOption("material." + e.key, e.problem);
  }
  discretization.check();
  if (!gravity.allFinite()) throw InvalidOption("gravity", "must be three finite numbers");
  for (const TractionLoad& t : tractions)
    if (!t.traction.allFinite()) throw InvalidOption("traction", "must be three finite numbers");
  if (clamps.empty() && displacements.empty())
    throw InvalidOption("clamp",
                        "nothing holds the body: give at least one clamp (a plane, "
                        "below or box)");
  if (!exactDisplacement != !exactGradient)
    throw InvalidOption("exact", "an exact solution needs both its displacement and its gradient");
  if (estimate && discretization.method != Method::IP)
    throw InvalidOption("estimate", "the error estimate is for the IP method: use method ip");
  if (tetMethod) {
    const std::string dgOnly = " is for the DG methods (ip, bz), not " + toString(*tetMethod) +
                               " (linear on each tet); leave it out";
    if (adapt) throw InvalidOption("adapt", "adaptivity" + dgOnly);
    if (estimate) throw InvalidOption("estimate", "the error estimate" + dgOnly);
    if (exactDisplacement) throw InvalidOption("exact", "an exact solution" + dgOnly);
    if (discretization.basis.degree != BasisOptions{}.degree)
      throw InvalidOption("degree", "a degree" + dgOnly);
  }
}

SolveReport Model::solve(const SolveOptions& options) {
  if (options.adapt && !options.tetMethod) return solveAdaptively(*this, options);
  State& s = *state_;
  s.requireUsable();
  refuseInvalid([&] { options.check(); });
  const PolyMesh& m = mesh();
  s.requireValid();
  SolveReport report;
  report.options = options;
  std::vector<const FaceSelector*> tractions;
  for (const TractionLoad& t : options.tractions) tractions.push_back(&t.where);
  std::vector<FaceSelector> held = options.clamps;
  for (const DirichletCondition& d : options.displacements) held.push_back(d.where);
  s.checkSelections(held, tractions, report.clampFaces, report.tractionFaces);
  if (options.tetMethod) {
    // The tet methods (physics/fem/): their nodal displacement, linear on each tet, is the
    // model's solution as DG degree-1 polynomials, exactly.
    const TetMesh tets = toTetMesh(m);
    TetSolveReport solved;
    try {
      solved = solveOnTets(tets, *options.tetMethod, options);
    } catch (const InvalidOption& e) {
      throw InputError(e.what());
    } catch (const std::runtime_error& e) {
      throw CheckFailure(e.what());
    }
    fillSolveReport(solved, report);
    s.adoptTetSolution(tets, solved.displacement, options.material, moments(2));
    return summarize(*s.solution, std::move(report));
  }
  if (options.discretization.method == Method::BZ &&
      options.discretization.bzPenaltyInEffect() == BzPenalty::Fixed)
    report.warnings.push_back(
        "BZ with the fixed penalty does not converge: its error stays whatever the mesh (a "
        "uniaxial bar's displacement 87% too large at degree 1); use the superpenalty (the "
        "default) or the IP method");

  LoadCase loads;
  for (const FaceSelector& c : options.clamps) loads.dirichlet.push_back({c, {}});
  for (const DirichletCondition& d : options.displacements) loads.dirichlet.push_back(d);
  loads.bodyForce = options.bodyForce;
  for (const TractionLoad& t : options.tractions) loads.tractions.push_back({t.where, t.traction});
  loads.gravity = options.gravity;
  StaticOptions so;
  so.discretization = options.discretization;
  so.solver.kind = options.solver;
  const int degree = options.discretization.basis.degree;

  const std::size_t before = facesIntegrated();
  const MomentCache& moments = this->moments(2 * degree);
  StaticSolver solver(m, options.material, so, &moments);
  solver.integrate();
  solver.assemble(loads);
  const Eigen::VectorXd* u = nullptr;
  try {
    u = &solver.solve();
  } catch (const std::runtime_error& e) {
    throw CheckFailure(e.what());
  }
  report.solve = solver.report();
  if (!u->allFinite())
    throw InputError(
        "the solution overflows double precision: the loads are too large for the material's "
        "stiffness; scale them or the model's units down");
  if (!report.solve.solver.success)
    throw CheckFailure("the linear solver did not converge (residual " +
                       std::to_string(report.solve.solver.residual) +
                       "); is every piece of the body clamped?");
  report.facesIntegrated = facesIntegrated() - before;
  report.clampForces = dirichletForces(m, solver.basis(), solver.moments(), solver.roles(),
                                       options.material, *u, loads.dirichlet.size());
  if (options.estimate) {
    report.estimate = estimateError(m, solver, loads, *u);
    report.energyNorm = std::sqrt(std::max(0.0, u->dot(solver.stiffnessTimes(*u))));
  }

  if (options.exactDisplacement && options.exactGradient) {
    const int q = std::max(degree + 4, 2 * degree + 2);
    report.error =
        errorNorms(m, solver.basis(), *u, options.exactDisplacement, options.exactGradient, q);
    report.energyError =
        energyError(m, solver.basis(), solver.moments(), solver.roles(), solver.form(), *u,
                    options.exactDisplacement, options.exactGradient, q);
  }

  StaticSolution solved = solver.release();
  s.adoptSolution(std::move(solved.basis), std::move(solved.coefficients), options.material,
                  moments);
  return summarize(*s.solution, std::move(report));
}

const Solution* Model::solution() const { return state_->solution ? &*state_->solution : nullptr; }

EmbeddedSurface Model::embedSurface(const std::string& file, int degree,
                                    const EmbeddingOptions& options, const DgBasis* given) {
  State& s = *state_;
  s.requireUsable();
  if (degree < 1 || degree > 3) throw InputError("the degree must be 1, 2 or 3");
  EmbeddedSurface out;
  out.file = file.empty() ? provenance().source : file;
  if (out.file.empty())
    throw InputError("the mesh records no surface it was sliced from; name the surface to embed");
  try {
    out.surface = readSurface(out.file);
  } catch (const std::runtime_error& e) {
    throw InputError(std::string(e.what()) +
                     (file.empty() ? " (the surface the mesh was sliced from); name the surface "
                                     "to embed instead"
                                   : ""));
  }
  const Solution* u = solution();
  std::unique_ptr<DgBasis> own;
  const DgBasis* basis = given                               ? given
                         : u && u->basis->degree() == degree ? u->basis.get()
                                                             : nullptr;
  if (!basis) {
    own = std::make_unique<DgBasis>(mesh(), moments(2 * degree), BasisOptions{degree});
    basis = own.get();
  }
  try {
    out.embedding =
        std::make_shared<SurfaceEmbedding>(mesh(), *basis, out.surface.vertices, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return out;
}

// --- writing -------------------------------------------------------------------------------

namespace {

template <class Tag>
VtuArray<Tag> vectorArray(const std::string& name, const IndexedData<Tag, Vec3>& data) {
  VtuArray<Tag> a{name, 3, {}};
  a.values.reserve(3 * data.size());
  for (const Vec3& v : data) a.values.insert(a.values.end(), {v.x(), v.y(), v.z()});
  return a;
}

}  // namespace

ExportReport Model::exportOpenFoam(const std::string& folder, const ExportOptions& options) const {
  const State& s = *state_;
  s.requireUsable();
  const Stopwatch watch;
  const PolyMesh& m = mesh();
  const double diagonal = meshBounds(m).diagonal().norm();
  OpenFoamOptions foam;
  foam.binary = options.binary;
  foam.cuts = s.provenance.cuts;
  std::vector<const FaceSelector*> regions;
  for (const ExportPatch& p : options.patches) regions.push_back(&p.where);
  const std::vector<std::size_t> counts = countSelected(m, regions);
  for (std::size_t i = 0; i < options.patches.size(); ++i) {
    const ExportPatch& p = options.patches[i];
    if (counts[i] == 0)
      throw InputError("patch '" + p.name + "' (" + p.where.describe() +
                       ") selects no boundary face (the mesh spans " + boxText(meshBounds(m)) +
                       "); use a region that meets the boundary");
    foam.patches.push_back({p.name, [&m, diagonal, where = p.where](FaceId f) {
                              return m.face(f).isBoundary() && selects(where, m, f, diagonal);
                            }});
  }
  ExportReport r;
  r.folder = folder;
  r.foam = writeOpenFoamCase(m, folder, foam);
  r.seconds = watch.seconds();
  return r;
}

WriteReport Model::write(const std::string& path, const WriteOptions& options) const {
  const State& s = *state_;
  s.requireUsable();
  const Stopwatch watch;
  VtuWriteOptions vtu;
  vtu.encoding = options.encoding;
  std::vector<CellArray> cells;
  std::vector<CornerArray> corners;
  const bool withSolution = options.solution && s.solution.has_value();
  if (withSolution) {
    const Solution& u = *s.solution;
    cells = {vectorArray("mean_displacement", u.fields.meanDisplacement),
             CellArray{"von_mises", 1, u.fields.vonMises.raw()},
             CellArray{"largest_jump", 1, u.fields.largestJump.raw()}};
    corners.push_back(displacementPointData(u.corners));
  }
  try {
    writeVtu(mesh(), path, vtu, cells, {}, corners, provenanceFieldData(s.provenance));
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  return {path, withSolution, watch.seconds()};
}

}  // namespace polydg
