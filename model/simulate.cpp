// Model::simulate(): a scene run on the model (model/scene.h), with cuts at given times through
// the model's own cut() and the fields carried over exactly, and the ParaView time series.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "field_transfer.h"
#include "mesh/vtp_io.h"
#include "model/files.h"
#include "model_state.h"
#include "physics/contact/contact.h"
#include "physics/dynamics/dynamics.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/names.h"
#include "polydg/model/scene.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

namespace polydg {

namespace fs = std::filesystem;

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

/// What the step did with its matrix, in words.
std::string solverAction(const StepReport& r, SolverKind kind, bool first) {
  if (kind == SolverKind::Cholesky)
    return first            ? "cholesky: factorized"
           : r.refactorized ? "cholesky: refactorized"
                            : "cholesky: factorization reused";
  const std::string cg = "cg (" + toString(r.preconditioner) + "): ";
  return cg + (first || r.preconditionerRebuilt ? "preconditioner built" : "preconditioner reused");
}

/// The time series: one VTU per frame and the ParaView collection listing them, rewritten
/// (atomically) after every frame so that an interrupted run leaves a readable series.
class TimeSeries {
 public:
  TimeSeries(const fs::path& folder, VtuEncoding encoding) : folder_(folder), encoding_(encoding) {
    std::error_code ec;
    fs::create_directories(folder_, ec);
    if (ec || !fs::is_directory(folder_))
      throw InputError("cannot create the output folder " + folder_.string() + ": " +
                       (ec ? ec.message() : "a file has that name") + "; choose another -o");
  }

  std::string pvd() const { return (folder_ / "scene.pvd").string(); }

  /// One frame; with `surface`, also its deformed surface (`displacement`: #V by 3).
  SimulationFrame write(const PolyMesh& mesh, const DynamicSolver& solver, int step,
                        const TriangleSurface* surface,
                        const Eigen::Matrix<double, Eigen::Dynamic, 3>* displacement) {
    SimulationFrame frame;
    frame.step = step;
    frame.t = solver.time();
    char name[32];
    std::snprintf(name, sizeof name, "scene_%06d.vtu", step);
    frame.file = name;
    const CornerValues u = cornerDisplacements(mesh, solver.basis(), solver.displacement());
    const CornerValues v = cornerDisplacements(mesh, solver.basis(), solver.velocity());
    const std::vector<double> vonMises = solver.vonMises();
    VtuWriteOptions options;
    options.encoding = encoding_;
    try {
      writeVtu(mesh, (folder_ / name).string(), options, {CellArray{"von_mises", 1, vonMises}}, {},
               {displacementPointData(u), displacementPointData(v, "velocity")});
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());
    }
    if (surface) {
      std::snprintf(name, sizeof name, "scene_%06d.vtp", step);
      frame.surfaceFile = name;
      std::vector<Vec3> deformed(surface->vertices.size());
      std::vector<double> u(3 * deformed.size());
      for (std::size_t p = 0; p < deformed.size(); ++p) {
        const Vec3 d = displacement->row(static_cast<Eigen::Index>(p)).transpose();
        deformed[p] = surface->vertices[p] + d;
        for (int k = 0; k < 3; ++k) u[3 * p + static_cast<std::size_t>(k)] = d[k];
      }
      try {
        writeVtp((folder_ / name).string(), deformed, surface->triangles,
                 {SurfacePointArray{"displacement", 3, u}}, encoding_);
      } catch (const std::runtime_error& e) {
        throw InputError(e.what());
      }
    }
    frames_.push_back(frame);
    writeCollection();
    return frame;
  }

 private:
  void writeCollection() const {
    writeFileAtomically(folder_ / "scene.pvd", [&](std::ostream& os) {
      os << "<?xml version=\"1.0\"?>\n"
            "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
            "  <Collection>\n";
      os.precision(17);
      // Part 0 is the mesh, part 1 the deformed embedded surface (ParaView shows them as one
      // multiblock data set per time).
      for (const SimulationFrame& f : frames_) {
        os << "    <DataSet timestep=\"" << f.t << "\" group=\"\" part=\"0\" file=\"" << f.file
           << "\"/>\n";
        if (!f.surfaceFile.empty())
          os << "    <DataSet timestep=\"" << f.t << "\" group=\"\" part=\"1\" file=\""
             << f.surfaceFile << "\"/>\n";
      }
      os << "  </Collection>\n</VTKFile>\n";
    });
  }

  fs::path folder_;
  VtuEncoding encoding_;
  std::vector<SimulationFrame> frames_;
};

}  // namespace

SimulationReport Model::simulate(const Scene& scene, const SimulateOptions& options) {
  State& s = *state_;
  s.requireUsable();
  const Stopwatch wall;
  refuseInvalid([&] { checkScene(scene); });
  s.requireValid();
  SimulationReport report;
  report.scene = scene;
  std::vector<const FaceSelector*> loadRegions;
  for (const TimedTraction& t : scene.loads) loadRegions.push_back(&t.where);
  s.checkSelections(scene.fixed, loadRegions, report.fixedFaces, report.loadFaces,
                    "the fixed region", "the load on");
  std::unique_ptr<TimeSeries> series;
  if (!options.outputDir.empty()) {
    series = std::make_unique<TimeSeries>(options.outputDir, options.encoding);
    report.pvd = series->pvd();
  }

  const DynamicsOptions dynamics = dynamicsOptions(scene);
  const DynamicLoads loads{scene.fixed, scene.loads, scene.gravity};
  const std::size_t integratedBefore = facesIntegrated();
  auto build = [&]() {
    const Stopwatch t;
    DynamicSolver solver(mesh(), moments(2 * scene.discretization.basis.degree), loads, dynamics);
    report.setupSeconds += t.seconds();
    return solver;
  };
  DynamicSolver solver = build();
  report.elements = mesh().numElements();
  report.dofs = solver.dofs();
  {
    const Vec3 c = solver.state().centreOfMass;
    const Eigen::VectorXd v = solver.affineField(skew(scene.angularVelocity), scene.velocity, c);
    solver.setState(0.0, Eigen::VectorXd::Zero(v.size()), v);
  }
  report.initial = solver.state();

  // The embedded surface, the contact points and the obstacles.
  const double diagonal = meshBounds(mesh()).diagonal().norm();
  SimulationEmbedding& info = report.embedding;
  const bool contacts = !scene.obstacles.empty();
  const bool onSurface = contacts && scene.contact.points == ContactPoints::Surface;
  EmbeddedSurface surface;
  if (scene.embed.enabled || onSurface) {
    const Stopwatch te;
    EmbeddingOptions eo;
    eo.support = scene.embed.support;
    surface =
        embedSurface(scene.embed.file, scene.discretization.basis.degree, eo, &solver.basis());
    info.surface = surface.file;
    info.points = surface.surface.vertices.size();
    info.triangles = surface.surface.triangles.size();
    info.samples = surface.embedding->numSamples();
    info.pieces = surface.embedding->numPieces();
    info.outside = surface.embedding->outside();
    info.weightNonzeros = surface.embedding->weightNonzeros();
    info.storedNonzeros = surface.embedding->storedNonzeros();
    info.setupSeconds = te.seconds();
    report.setupSeconds += info.setupSeconds;
  }
  const bool showSurface = scene.embed.enabled;
  std::vector<double> areas;
  std::unique_ptr<SurfaceEmbedding> nodes;
  std::unique_ptr<ContactModel> contact;
  ContactOptions contactOptions;
  std::vector<Obstacle> obstacles;
  auto makeContact = [&]() {
    const SurfaceEmbedding* points = surface.embedding.get();
    if (!onSurface) {
      nodes = std::make_unique<SurfaceEmbedding>(
          SurfaceEmbedding::boundaryNodes(mesh(), solver.basis(), areas));
      points = nodes.get();
    }
    contact = std::make_unique<ContactModel>(*points, areas, obstacles, contactOptions);
    solver.setContact(contact.get());
    info.contactPoints = points->numPoints();
  };
  if (contacts) {
    const Stopwatch to;
    obstacles = makeObstacles(scene, diagonal, info);
    contactOptions.stiffness = scene.contact.stiffness > 0.0
                                   ? scene.contact.stiffness
                                   : 100.0 * scene.material.youngsModulus / diagonal;
    contactOptions.friction = scene.contact.friction;
    contactOptions.slipSpeed =
        scene.contact.slipSpeed > 0.0 ? scene.contact.slipSpeed : 0.01 * diagonal;
    if (onSurface) areas = vertexAreas(surface.surface);
    makeContact();
    info.contactPointKind = onSurface ? "surface" : "nodes";
    info.contactStiffness = contactOptions.stiffness;
    info.slipSpeed = contactOptions.slipSpeed;
    report.setupSeconds += to.seconds();
  }

  auto writeFrame = [&](int step) {
    if (!series) return;
    const Stopwatch t;
    Eigen::Matrix<double, Eigen::Dynamic, 3> displacement;
    if (showSurface) {
      const Stopwatch ts;
      displacement = surface.embedding->displacements(solver.displacement());
      report.surfaceSeconds += ts.seconds();
    }
    report.frames.push_back(series->write(mesh(), solver, step,
                                          showSurface ? &surface.surface : nullptr,
                                          showSurface ? &displacement : nullptr));
    report.outputSeconds += t.seconds();
  };

  // Cuts: at the first step boundary at or after their time.
  std::size_t nextCut = 0;
  bool cutSinceFrame = false;
  // After an edit: the new solver takes the displacement and velocity through the lineage, the
  // embedded surface's weights and the contact points follow the new elements.
  // A coarsening (`project`) projects the fields onto the merged elements instead (L2: mass and
  // momentum kept).
  auto afterEdit = [&](const ElementLineage& lineage, const DgBasis& oldBasis,
                       const Eigen::VectorXd& oldU, const Eigen::VectorXd& oldV, double time,
                       bool project = false) {
    TransferCounts counts;
    const std::vector<Eigen::VectorXd> moved =
        project ? projectFields(oldBasis, {&oldU, &oldV}, solver.basis(), lineage)
                : transferFields(oldBasis, {&oldU, &oldV}, solver.basis(), lineage, &counts);
    solver.setState(time, moved[0], moved[1]);
    if (surface.embedding || contact) {
      const std::size_t elements = mesh().numElements();
      std::vector<ElementId> sources(elements);
      for (std::size_t e = 0; e < elements; ++e) {
        const std::vector<ElementId> from = lineage.sources(ElementId(e));
        sources[e] = from.size() == 1 ? from.front() : ElementId();
      }
      if (surface.embedding)
        info.updates.push_back(surface.embedding->update(mesh(), solver.basis(), sources));
      if (contact) {
        if (onSurface)
          contact->refresh();  // the same points, new weights
        else
          makeContact();  // the boundary nodes changed
        solver.setContact(contact.get());
      }
    }
    return counts;
  };

  // Refinement by stress (scene "adapt"): each element's level, and the refinement due after a
  // step.
  std::vector<int> level(mesh().numElements(), 0);
  // Families: the children of one refined element (coarsening merges a whole family back). Each
  // element's family (-1: none), each family's parent family and its number of children.
  std::vector<int> family(mesh().numElements(), -1), familyParent;
  std::vector<std::size_t> familySize;
  auto familiesAfter = [&](const ElementLineage& lineage,
                           const std::unordered_set<std::uint32_t>& refined, bool merged) {
    std::unordered_map<std::uint32_t, int> made;  // refined element -> its children's family
    std::vector<int> next(mesh().numElements(), -1);
    for (std::size_t e = 0; e < next.size(); ++e) {
      const std::vector<ElementId> sources = lineage.sources(ElementId(e));
      const ElementId s = sources.front();
      if (refined.count(s.value)) {
        auto [it, inserted] = made.try_emplace(s.value, static_cast<int>(familyParent.size()));
        if (inserted) {
          familyParent.push_back(family[s.index()]);
          familySize.push_back(0);
        }
        next[e] = it->second;
        ++familySize[static_cast<std::size_t>(it->second)];
      } else if (merged && sources.size() > 1 && family[s.index()] >= 0) {
        next[e] = familyParent[static_cast<std::size_t>(family[s.index()])];
      } else {
        next[e] = family[s.index()];
      }
    }
    family = std::move(next);
  };
  auto refineDue = [&](int k) {
    const SceneAdapt& a = scene.adapt;
    if (!a.enabled || k % a.every != 0) return false;
    const Stopwatch tr;
    const ElementFields fields =
        elementFields(mesh(), solver.basis(), moments(2 * scene.discretization.basis.degree),
                      solver.displacement(), scene.material);
    RefineRequest request;
    request.split = a.split;
    request.checks = CheckLevel::None;
    for (std::size_t e = 0; e < level.size(); ++e)
      if (level[e] < a.maxLevel && std::abs(fields.principalStress[ElementId(e)]) > a.stress) {
        request.elements.push_back(ElementId(e));
        request.directions.push_back(fields.principalDirection[ElementId(e)]);
      }
    // Families whose children are all still there, none refined further, and all below the
    // coarsening threshold are merged back (none that a refinement marked now).
    CoarsenRequest coarsenRequest;
    coarsenRequest.checks = CheckLevel::None;
    if (a.coarsen > 0.0) {
      std::vector<std::vector<ElementId>> members(familySize.size());
      std::vector<char> keep(familySize.size(), 1);
      for (std::size_t e = 0; e < family.size(); ++e) {
        if (family[e] < 0) continue;
        const std::size_t f = static_cast<std::size_t>(family[e]);
        members[f].push_back(ElementId(e));
        if (std::abs(fields.principalStress[ElementId(e)]) >= a.coarsen * a.stress) keep[f] = 0;
      }
      for (std::size_t f = 0; f < members.size(); ++f)
        if (keep[f] && members[f].size() == familySize[f] && members[f].size() >= 2)
          coarsenRequest.groups.push_back(members[f]);
    }
    if (request.elements.empty() && coarsenRequest.groups.empty()) return false;
    // A refinement if any element is marked, else a coarsening; the same steps around either.
    const bool coarsening = request.elements.empty();
    SimulationRefinement record;
    record.time = solver.time();
    record.elementsBefore = mesh().numElements();
    const BodyState before = solver.state();
    const DgBasis oldBasis = solver.basis();
    const Eigen::VectorXd oldU = solver.displacement(), oldV = solver.velocity();
    ElementLineage lineage;
    if (coarsening) {
      record.coarsened = coarsenRequest.groups.size();
      const CoarsenReport c = coarsen(coarsenRequest);
      if (!c.operation.check.passed)
        throw CheckFailure("the coarsening at t = " + std::to_string(record.time) + " failed (" +
                           c.operation.check.failure + "); the simulation stops there");
      lineage = c.operation.lineage;
      std::vector<int> next(mesh().numElements(), 0);
      for (std::size_t e = 0; e < next.size(); ++e) {
        const std::vector<ElementId> sources = lineage.sources(ElementId(e));
        next[e] = level[sources.front().index()] - (sources.size() > 1 ? 1 : 0);
      }
      level = std::move(next);
      familiesAfter(lineage, {}, true);
    } else {
      if (a.split == RefineSplit::Octants) request.directions.clear();
      record.marked = request.elements.size();
      const RefineReport r = refine(request);
      if (!r.operation.check.passed)
        throw CheckFailure("the refinement at t = " + std::to_string(record.time) + " failed (" +
                           r.operation.check.failure + "); the simulation stops there");
      lineage = r.operation.lineage;
      std::unordered_set<std::uint32_t> refined;
      for (ElementId e : request.elements) refined.insert(e.value);
      level = levelsAfter(level, lineage, mesh().numElements(), refined);
      familiesAfter(lineage, refined, false);
    }
    record.elementsAfter = mesh().numElements();
    solver = build();
    const TransferCounts counts = afterEdit(lineage, oldBasis, oldU, oldV, record.time, coarsening);
    record.exact = counts.exact;
    record.extended = counts.extended;
    const BodyState after = solver.state();
    auto relative = [](double a, double b) {
      return std::abs(a - b) / std::max(std::abs(a), 1e-300);
    };
    record.momentumChange =
        (after.momentum - before.momentum).norm() / std::max(before.momentum.norm(), 1e-300);
    // A coarsening's projection can only lose kinetic energy: its change is the signed loss.
    record.kineticChange =
        coarsening ? (before.kinetic - after.kinetic) / std::max(std::abs(before.kinetic), 1e-300)
                   : relative(before.kinetic, after.kinetic);
    record.elasticChange = relative(before.elastic, after.elastic);
    record.seconds = tr.seconds();
    report.cutSeconds += record.seconds;
    report.refinements.push_back(record);
    return true;
  };

  auto cutsDue = [&](double t) {
    while (nextCut < scene.cuts.size() && scene.cuts[nextCut].time <= t + 1e-9 * scene.dt) {
      const TimedCut& timed = scene.cuts[nextCut++];
      const Stopwatch tc;
      SimulationCut record;
      record.time = solver.time();
      record.elementsBefore = mesh().numElements();
      const DgBasis oldBasis = solver.basis();
      const Eigen::VectorXd oldU = solver.displacement(), oldV = solver.velocity();
      record.report = cut(timed.request);
      if (!record.report.check.passed)
        throw CheckFailure("the cut at t = " + std::to_string(record.time) + " failed (" +
                           record.report.check.failure + "); the simulation stops there");
      record.elementsAfter = mesh().numElements();
      report.cutSeconds += tc.seconds();
      level = levelsAfter(level, record.report.lineage, record.elementsAfter, {});
      familiesAfter(record.report.lineage, {}, false);
      solver = build();
      const Stopwatch tt;
      const TransferCounts counts =
          afterEdit(record.report.lineage, oldBasis, oldU, oldV, record.time);
      record.exact = counts.exact;
      record.extended = counts.extended;
      record.seconds = tc.seconds();
      report.cutSeconds += tt.seconds();
      report.cuts.push_back(std::move(record));
      cutSinceFrame = true;
    }
  };

  cutsDue(0.0);
  writeFrame(0);
  cutSinceFrame = false;
  bool first = true;
  for (int k = 1; k <= scene.steps; ++k) {
    const Stopwatch ts;
    SimulationStep step;
    try {
      step.step = solver.step(scene.dt);
    } catch (const std::runtime_error& e) {
      throw CheckFailure("step " + std::to_string(k) + " (t = " + std::to_string(solver.time()) +
                         "): " + e.what() + "; try a smaller dt");
    }
    step.seconds = ts.seconds();
    step.solver = solverAction(step.step, solver.solverKind(), first);
    first = false;
    step.state = solver.state();
    if (contact) {
      step.contact = contact->measure(solver.displacement(), solver.time());
      step.collisionSeconds = step.step.contactQuerySeconds + contact->takeQuerySeconds();
    }
    report.rotationSeconds += step.step.rotationSeconds;
    report.assemblySeconds += step.step.assemblySeconds;
    report.solveSeconds += step.step.solveSeconds;
    report.steps.push_back(step);
    const std::size_t cutsBefore = report.cuts.size();
    cutsDue(solver.time());
    if (report.cuts.size() != cutsBefore) first = true;  // a new solver after the cut
    if (refineDue(k)) {
      first = true;
      cutSinceFrame = true;
    }
    if (k % scene.outputEvery == 0 || k == scene.steps || cutSinceFrame) {
      writeFrame(k);
      cutSinceFrame = false;
    }
    if (options.progress) options.progress({k, scene.steps, solver.time()});
  }

  s.adoptSolution(std::make_unique<DgBasis>(solver.basis()), solver.displacement(), scene.material,
                  moments(2 * scene.discretization.basis.degree));
  report.facesIntegrated = facesIntegrated() - integratedBefore;
  report.wallSeconds = wall.seconds();
  return report;
}

}  // namespace polydg
