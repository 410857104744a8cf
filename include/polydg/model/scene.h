// Simulation scenes: what `polydg simulate --scene SCENE.json` and Model.simulate() in Python
// run (the format is in README.md, "Scenes"). Read strictly, like pipelines: every key is
// checked before the run starts and a bad one is refused with its place in the file.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/physics/contact/contact_measure.h"
#include "polydg/physics/dynamics/motion.h"

namespace polydg {

/// A cut at a time of the simulation (scene "cuts").
struct TimedCut {
  double time = 0.0;
  CutRequest request;
};

/// The surface carried along (scene "embed"): a file `polydg` reads, or the surface the mesh
/// was sliced from (its provenance's source: "embed": true).
struct SceneEmbed {
  bool enabled = false;
  std::string file;      ///< "" for the mesh's source
  double support = 2.0;  ///< EmbeddingOptions::support
};

/// An obstacle (scene "obstacles"): the half-space "below" [a, b, c, d] (a x + b y + c z <= d
/// is solid) or the inside of a closed surface "mesh", moving with "velocity".
struct SceneObstacle {
  std::optional<Plane> below;
  std::string mesh;
  Vec3 velocity = Vec3::Zero();
  /// Distance field voxel ("voxel"); 0: the smaller of the obstacle's and the body's
  /// bounding-box diagonals over 100.
  double voxel = 0.0;
};

/// Which points collide (scene "contact": "points").
enum class ContactPoints {
  Surface,  ///< the embedded surface's vertices (the default)
  Nodes,    ///< the mesh's boundary vertices, eq. (17) (section 9's cheap option)
};

/// Penalty contact (scene "contact").
struct SceneContact {
  /// Pressure per unit penetration; 0: 100 E / the body's bounding-box diagonal.
  double stiffness = 0.0;
  double friction = 0.0;
  /// The slip speed below which friction is viscous (regularized Coulomb); 0: 1% of the
  /// body's bounding-box diagonal per unit time.
  double slipSpeed = 0.0;
  ContactPoints points = ContactPoints::Surface;
};

/// Refinement by stress during a run (scene "adapt"; paper section 10): every `every` steps,
/// elements whose mean stress has a principal value above `stress` in absolute value are split,
/// up to `maxLevel` times each.
struct SceneAdapt {
  bool enabled = false;
  double stress = 0.0;  ///< the threshold, in units of E
  RefineSplit split = RefineSplit::Octants;
  int every = 1;
  int maxLevel = 2;
  /// The children of one refinement whose stresses all fall below coarsen * stress are merged
  /// back (their fields projected: mass and momentum kept); 0: never.
  double coarsen = 0.5;
};

/// Everything a simulation needs besides the mesh.
struct Scene {
  Material material;
  /// Method, BZ penalty and basis degree (a scene keeps the default penalty rule).
  DiscretizationOptions discretization;
  /// "method": "fem" or "fs-fem": the body is a tet mesh moved by a tet method (physics/fem/)
  /// instead of DG; unset: DG with discretization.method. The DG-only keys ("degree",
  /// "bz_penalty", "cuts", "embed", "obstacles", "contact", "adapt") are refused with it.
  std::optional<TetMethod> tetMethod;
  bool corotational = true;
  Integrator integrator = Integrator::BackwardEuler;
  /// The time step: required (0 until given), checked by checkScene(), the one place, and the
  /// argument of every step.
  double dt = 0.0;
  int steps = 0;  ///< "steps", or "duration" / dt rounded to the nearest whole step
  Vec3 gravity = Vec3::Zero();
  RayleighDamping damping;
  std::vector<FaceSelector> fixed;      ///< regions held at u = 0; none: a free body
  std::vector<TimedTraction> loads;     ///< tractions, each until its time
  Vec3 velocity = Vec3::Zero();         ///< initial linear velocity
  Vec3 angularVelocity = Vec3::Zero();  ///< initial, about the centre of mass
  int outputEvery = 1;                  ///< a frame every this many steps (and the last)
  std::vector<TimedCut> cuts;           ///< in time order
  SolverKind solver = SolverKind::Auto;
  SceneEmbed embed;
  std::vector<SceneObstacle> obstacles;
  SceneContact contact;
  SceneAdapt adapt;
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
/// (physics/dynamics/dynamics.h, BodyState).
struct SimulationStep {
  StepReport step;
  BodyState state;
  std::string solver;  ///< what the step did with the matrix (see report_json.cpp)
  /// With obstacles: contacts, deepest penetration and penalty energy at the step's end.
  ContactMeasure contact;
  /// Obstacle queries and contact point positions, during the step and for its end state.
  double collisionSeconds = 0.0;
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
  double seconds = 0.0;  ///< the cut, the new solver and the fields carried over
  /// The cut's latency by phase, from its request to the next completed step: the model's cut
  /// (split, merge, re-integration and its checks, `checkSeconds` of it), the new solver, the
  /// fields carried over, and the next step (none if the run ended with the cut).
  double cutSeconds = 0.0, checkSeconds = 0.0, solverSeconds = 0.0, transferSeconds = 0.0;
  std::optional<double> nextStepSeconds;
  /// Of nextStepSeconds: the preconditioner built (or the matrix factorized) for the edited mesh.
  std::optional<double> nextStepPreconditionerSeconds;
  /// Elements whose blocks the new solver computed: those the cut made or changed and their
  /// neighbours (the others' were the old solver's).
  std::size_t solverElements = 0;
};

/// A refinement during a simulation (scene "adapt"): the fields went to the children exactly,
/// so momentum and kinetic energy after it equal those before it to round-off (relative
/// changes); or a coarsening, whose L2 projection keeps momentum exactly and can only lower the
/// kinetic energy (kineticChange: the relative loss).
struct SimulationRefinement {
  double time = 0.0;
  std::size_t marked = 0;     ///< elements refined (0 for a coarsening)
  std::size_t coarsened = 0;  ///< families merged back (a coarsening)
  std::size_t elementsBefore = 0, elementsAfter = 0;
  std::size_t exact = 0, extended = 0;
  double momentumChange = 0.0, kineticChange = 0.0, elasticChange = 0.0;
  double seconds = 0.0;
};

/// A frame of the time series.
struct SimulationFrame {
  int step = 0;
  double t = 0.0;
  std::string file;
  std::string surfaceFile;  ///< the deformed embedded surface (.vtp), "" without "embed"
};

/// The embedded surface and the contact points of a simulation.
struct SimulationEmbedding {
  std::string surface;  ///< the file, "" without "embed"
  std::size_t points = 0, triangles = 0, samples = 0, pieces = 0, outside = 0;
  std::size_t weightNonzeros = 0;  ///< of W (eq. 19), what a surface update reads
  std::size_t storedNonzeros = 0;  ///< of Phi and S, kept for updates after cuts
  double setupSeconds = 0.0;
  std::size_t contactPoints = 0;
  std::string contactPointKind;  ///< "surface" or "nodes", "" without obstacles
  double contactStiffness = 0.0, slipSpeed = 0.0;
  std::vector<double> obstacleSetupSeconds;  ///< per obstacle (distance fields)
  std::vector<std::size_t> obstacleVoxels;
  /// After each cut: surface points whose weights were computed again, and kept.
  std::vector<EmbeddingUpdate> updates;
};

struct SimulationReport {
  Scene scene;
  std::size_t elements = 0, dofs = 0;  ///< at the start
  std::vector<std::size_t> fixedFaces, loadFaces;
  BodyState initial;
  std::vector<SimulationStep> steps;
  std::vector<SimulationCut> cuts;
  std::vector<SimulationRefinement> refinements;
  std::vector<SimulationFrame> frames;
  std::string pvd;  ///< the collection file, "" without output (null in the JSON report)
  SimulationEmbedding embedding;
  /// Seconds of surface updates for output frames (embedding displacements), all frames: a part
  /// of outputSeconds.
  double surfaceSeconds = 0.0;
  /// Totals of the phases, which add up to the wall time: setup (the checks, bases, matrices,
  /// loads, the initial state, embedding and contact), rotation, assembly, solve, state (each
  /// step's reported energies, momenta and contact measures), cut (and refinement: each edit
  /// with its new solver and the fields carried over, and the marking of an adaptation that
  /// found nothing to do), output (frames), finish (the final mesh
  /// and displacement handed to the model).
  double setupSeconds = 0.0, rotationSeconds = 0.0, assemblySeconds = 0.0, solveSeconds = 0.0,
         stateSeconds = 0.0, cutSeconds = 0.0, outputSeconds = 0.0, finishSeconds = 0.0,
         wallSeconds = 0.0;
  std::size_t facesIntegrated = 0;  ///< by the simulation (moments of new faces after cuts)
};

/// The one check of a scene's values, for scenes read from files (parseScene() calls it) and
/// made in code (Model::simulate() calls it): throws InvalidOption naming the key ("dt",
/// "material.E", "cuts[2].time").
void checkScene(const Scene& scene);

/// The scene of a parsed JSON document; `file` names it in messages. Throws InputError
/// ("FILE: PLACE: WHAT; see the scene format in docs/guide.md").
Scene parseScene(const nlohmann::json& document, const std::string& file);
/// The same from a file.
Scene readScene(const std::string& file);

const Names<Integrator>& integratorNames();       ///< euler, bdf2, newmark
const Names<ContactPoints>& contactPointNames();  ///< surface, nodes

}  // namespace polydg
