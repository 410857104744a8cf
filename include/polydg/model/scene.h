// Simulation scenes: what `polydg simulate --scene SCENE.json` and Model.simulate() in Python
// run (the format is in README.md, "Scenes"). Read strictly, like pipelines: every key is
// checked before the run starts and a bad one is refused with its place in the file.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/physics/dynamics.h"

namespace polydg {

/// A cut at a time of the simulation (scene "cuts").
struct TimedCut {
  double time = 0.0;
  CutRequest request;
};

/// Everything a simulation needs besides the mesh.
struct Scene {
  Material material;
  Method method = Method::IP;
  int degree = 1;
  bool corotational = true;
  TimeIntegrator integrator = TimeIntegrator::BackwardEuler;
  double dt = 0.0;
  int steps = 0;  ///< "steps", or "duration" / dt rounded to the nearest whole step
  Vec3 gravity = Vec3::Zero();
  double massDamping = 0.0, stiffnessDamping = 0.0;
  std::vector<FaceSelector> fixed;      ///< regions held at u = 0; none: a free body
  std::vector<TimedTraction> loads;     ///< tractions, each until its time
  Vec3 velocity = Vec3::Zero();         ///< initial linear velocity
  Vec3 angularVelocity = Vec3::Zero();  ///< initial, about the centre of mass
  int outputEvery = 1;                  ///< a frame every this many steps (and the last)
  std::vector<TimedCut> cuts;           ///< in time order
  SolverKind solver = SolverKind::Auto;
};

/// Progress of a simulation, after each step.
struct SimulationProgress {
  int step = 0, steps = 0;
  double t = 0.0;
};

struct SimulateOptions {
  /// Folder for the time series (scene.pvd and one VTU per frame), created if missing; "" for
  /// none.
  std::string outputDir;
  VtuEncoding encoding = VtuEncoding::Appended;
  std::function<void(const SimulationProgress&)> progress;
};

/// One step of a simulation. Energies and momenta are those of the state at the step's end
/// (physics/dynamics.h, BodyState).
struct SimulationStep {
  StepReport step;
  BodyState state;
  std::string solver;  ///< what the step did with the matrix (see report_json.cpp)
  double seconds = 0.0;
};

/// A cut made during a simulation.
struct SimulationCut {
  double time = 0.0;
  OperationReport report;
  std::size_t elementsBefore = 0, elementsAfter = 0;
  /// Elements that took one parent's polynomials exactly, and merged slivers (several
  /// sources) that took their first source's (the neighbour's) polynomials extended over them.
  std::size_t exact = 0, extended = 0;
  double seconds = 0.0;
};

/// A frame of the time series.
struct SimulationFrame {
  int step = 0;
  double t = 0.0;
  std::string file;
};

struct SimulationReport {
  Scene scene;
  std::size_t elements = 0, dofs = 0;  ///< at the start
  std::vector<std::size_t> fixedFaces, loadFaces;
  BodyState initial;
  std::vector<SimulationStep> steps;
  std::vector<SimulationCut> cuts;
  std::vector<SimulationFrame> frames;
  std::string pvd;  ///< the collection file, "" without output (null in the JSON report)
  /// Totals of the phases: setup (bases, matrices, loads, after each cut too), rotation,
  /// assembly, solve, cut, output.
  double setupSeconds = 0.0, rotationSeconds = 0.0, assemblySeconds = 0.0, solveSeconds = 0.0,
         cutSeconds = 0.0, outputSeconds = 0.0, wallSeconds = 0.0;
  std::size_t facesIntegrated = 0;  ///< by the simulation (moments of new faces after cuts)
};

/// The scene of a parsed JSON document; `file` names it in messages. Throws InputError
/// ("FILE: PLACE: WHAT; see the scene format in README.md").
Scene parseScene(const nlohmann::json& document, const std::string& file);
/// The same from a file.
Scene readScene(const std::string& file);

const Names<TimeIntegrator>& integratorNames();  ///< euler, bdf2, newmark

}  // namespace polydg
