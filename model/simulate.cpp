// Model::simulate(): a scene run on the model (model/scene.h), with cuts at given times through
// the model's own cut() and the fields carried over exactly, and the ParaView time series.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "model_state.h"
#include "polydg/model/files.h"
#include "polydg/model/names.h"
#include "polydg/model/scene.h"
#include "polydg/physics/post_process.h"
#include "polydg/util/stopwatch.h"

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
  o.discretization.method = scene.method;
  o.discretization.basis.degree = scene.degree;
  o.solver.kind = scene.solver;
  o.corotational = scene.corotational;
  o.integrator = scene.integrator;
  o.dt = scene.dt;
  o.massDamping = scene.massDamping;
  o.stiffnessDamping = scene.stiffnessDamping;
  return o;
}

/// The checks of a scene made in code (parseScene() checks the same for files).
void checkScene(const Scene& scene) {
  try {
    scene.material.check();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string(e.what()) + "; check E, nu and density");
  }
  if (scene.degree < 1 || scene.degree > 3) throw InputError("the degree must be 1, 2 or 3");
  if (!(scene.dt > 0.0) || !std::isfinite(scene.dt))
    throw InputError("the time step dt must be a positive number");
  if (scene.steps < 1) throw InputError("the scene needs at least one step");
  if (scene.outputEvery < 1) throw InputError("output every must be at least 1");
  if (!(scene.massDamping >= 0.0) || !(scene.stiffnessDamping >= 0.0))
    throw InputError("damping coefficients must not be negative");
  if (!scene.gravity.allFinite() || !scene.velocity.allFinite() ||
      !scene.angularVelocity.allFinite())
    throw InputError("gravity and initial velocities must be finite");
  for (const TimedTraction& t : scene.loads)
    if (!t.traction.allFinite()) throw InputError("a traction must be three finite numbers");
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

  SimulationFrame write(const PolyMesh& mesh, const DynamicSolver& solver, int step) {
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
      for (const SimulationFrame& f : frames_)
        os << "    <DataSet timestep=\"" << f.t << "\" group=\"\" part=\"0\" file=\"" << f.file
           << "\"/>\n";
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
  checkScene(scene);
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
    DynamicSolver solver(mesh(), moments(2 * scene.degree), loads, dynamics);
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

  auto writeFrame = [&](int step) {
    if (!series) return;
    const Stopwatch t;
    report.frames.push_back(series->write(mesh(), solver, step));
    report.outputSeconds += t.seconds();
  };

  // Cuts: at the first step boundary at or after their time.
  std::size_t nextCut = 0;
  bool cutSinceFrame = false;
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
      if (!record.report.validation.passed)
        throw CheckFailure("the cut at t = " + std::to_string(record.time) + " failed (" +
                           record.report.validation.failure + "); the simulation stops there");
      record.elementsAfter = mesh().numElements();
      report.cutSeconds += tc.seconds();
      solver = build();
      const Stopwatch tt;
      const int n = solver.basis().size(), bs = 3 * n;
      Eigen::VectorXd u(static_cast<Eigen::Index>(record.elementsAfter) * bs), v(u.size());
      for (std::size_t e = 0; e < record.elementsAfter; ++e) {
        const std::vector<ElementId> sources = record.report.lineage.sources(ElementId(e));
        (sources.size() == 1 ? record.exact : record.extended) += 1;
        const Eigen::MatrixXd q =
            transferMatrix(oldBasis, sources.front(), solver.basis(), ElementId(e));
        const Eigen::Index from = static_cast<Eigen::Index>(sources.front().index()) * bs;
        const Eigen::Index to = static_cast<Eigen::Index>(e) * bs;
        for (int d = 0; d < 3; ++d) {
          u.segment(to + d * n, n) = q * oldU.segment(from + d * n, n);
          v.segment(to + d * n, n) = q * oldV.segment(from + d * n, n);
        }
      }
      solver.setState(record.time, u, v);
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
      step.step = solver.step();
    } catch (const std::runtime_error& e) {
      throw CheckFailure("step " + std::to_string(k) + " (t = " + std::to_string(solver.time()) +
                         "): " + e.what() + "; try a smaller dt");
    }
    step.seconds = ts.seconds();
    step.solver = solverAction(step.step, solver.solverKind(), first);
    first = false;
    step.state = solver.state();
    report.rotationSeconds += step.step.rotationSeconds;
    report.assemblySeconds += step.step.assemblySeconds;
    report.solveSeconds += step.step.solveSeconds;
    report.steps.push_back(step);
    const std::size_t cutsBefore = report.cuts.size();
    cutsDue(solver.time());
    if (report.cuts.size() != cutsBefore) first = true;  // a new solver after the cut
    if (k % scene.outputEvery == 0 || k == scene.steps || cutSinceFrame) {
      writeFrame(k);
      cutSinceFrame = false;
    }
    if (options.progress) options.progress({k, scene.steps, solver.time()});
  }

  s.adoptSolution(std::make_unique<DgBasis>(solver.basis()), solver.displacement(), scene.material,
                  moments(2 * scene.degree));
  report.facesIntegrated = facesIntegrated() - integratedBefore;
  report.wallSeconds = wall.seconds();
  return report;
}

}  // namespace polydg
