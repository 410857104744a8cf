#include "model/tet_simulation.h"

#include <memory>

#include "model/model_state.h"
#include "model/simulation.h"
#include "model/tet_solve.h"
#include "model/time_series.h"
#include "physics/fem/tet_dynamics.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// The boundary faces `where` selects; InputError if none.
std::vector<FaceId> selected(const TetBoundary& boundary, const FaceSelector& where,
                             const std::string& what) {
  std::vector<FaceId> faces = boundary.select(where);
  if (faces.empty())
    throw InputError(what + " selects no boundary face of the tet mesh; check the region");
  return faces;
}

TetDynamicsOptions dynamicsOptions(const Scene& scene, const TetBoundary& boundary,
                                   SimulationReport& report) {
  TetDynamicsOptions o;
  o.material = scene.material;
  o.corotational = scene.corotational;
  o.integrator = scene.integrator;
  o.gravity = scene.gravity;
  o.massDamping = scene.damping.mass;
  o.stiffnessDamping = scene.damping.stiffness;
  o.solver.kind = scene.solver;
  for (std::size_t k = 0; k < scene.fixed.size(); ++k) {
    const std::vector<FaceId> faces =
        selected(boundary, scene.fixed[k], "the fixed region " + std::to_string(k));
    report.fixedFaces.push_back(faces.size());
    for (std::uint32_t v : boundary.nodes(faces)) o.clamped.push_back(v);
  }
  for (std::size_t k = 0; k < scene.loads.size(); ++k) {
    const TimedTraction& t = scene.loads[k];
    const std::vector<FaceId> faces =
        selected(boundary, t.where, "the load on region " + std::to_string(k));
    report.loadFaces.push_back(faces.size());
    o.loads.push_back({boundary.tractionLoad(faces, t.traction), t.until});
  }
  return o;
}

/// Node-major values as a point array.
PointArray pointArray(const char* name, const Eigen::VectorXd& values) {
  return {name, 3, std::vector<double>(values.data(), values.data() + values.size())};
}

}  // namespace

SimulationReport simulateOnTets(const TetMesh& mesh, const Scene& scene,
                                const SimulateOptions& options,
                                Eigen::VectorXd* finalDisplacement) {
  const Stopwatch wall;
  refuseInvalid([&] { checkScene(scene); });
  if (!scene.tetMethod) throw std::logic_error("simulateOnTets needs a scene with a tet method");
  SimulationReport report;
  report.scene = scene;
  const TetBoundary boundary(mesh);
  const TetDiscretization discretization(mesh, *scene.tetMethod);
  TetDynamics body(discretization, dynamicsOptions(scene, boundary, report));
  body.setRigidVelocity(scene.velocity, scene.angularVelocity, body.referencePoint());
  report.elements = mesh.numTets();
  report.dofs = discretization.numDofs();
  report.initial = body.state();
  std::unique_ptr<TimeSeries> series;
  if (!options.outputDir.empty()) {
    series = std::make_unique<TimeSeries>(options.outputDir, options.encoding);
    report.pvd = series->pvd();
  }
  auto writeFrame = [&](int k) {
    if (!series) return;
    const Stopwatch output;
    report.frames.push_back(series->write(
        boundary.mesh(), k, body.time(),
        {CellArray{
            "von_mises", 1,
            discretization.tetVonMises(body.positions(), scene.material, scene.corotational)}},
        {pointArray("displacement", body.displacement()),
         pointArray("velocity", body.velocities())}));
    report.outputSeconds += output.seconds();
  };
  report.setupSeconds = wall.seconds();
  writeFrame(0);
  for (int k = 1; k <= scene.steps; ++k) {
    const Stopwatch ts;
    SimulationStep step;
    try {
      step.step = body.step(scene.dt);
    } catch (const std::runtime_error& e) {
      throw CheckFailure("step " + std::to_string(k) + " (t = " + std::to_string(body.time()) +
                         "): " + e.what());
    }
    step.seconds = ts.seconds();
    step.solver = solverAction(step.step, body.solverKind(), k == 1);
    const Stopwatch tr;
    step.state = body.state();
    report.stateSeconds += tr.seconds();
    report.rotationSeconds += step.step.rotationSeconds;
    report.assemblySeconds += step.step.assemblySeconds;
    report.solveSeconds += step.step.solveSeconds;
    report.steps.push_back(step);
    if (k % scene.outputEvery == 0 || k == scene.steps) writeFrame(k);
    if (options.progress) options.progress({k, scene.steps, body.time()});
  }
  if (finalDisplacement) *finalDisplacement = body.displacement();
  report.wallSeconds = wall.seconds();
  return report;
}

}  // namespace polydg
