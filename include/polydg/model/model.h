// The model: one object that owns a polyhedral mesh with its moment cache, its editor and its
// provenance, and the typed operations every front end applies to it (the polydg commands,
// pipeline steps, the Python module): create from a surface, read, cut, merge slivers, check,
// solve, write. Each operation returns a typed report (model/report_json.h gives their JSON).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "polydg/cut/cut.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/openfoam.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/tetrahedralize.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/physics/checks/check_reports.h"
#include "polydg/physics/contact/embedding.h"
#include "polydg/physics/dg/loads.h"
#include "polydg/physics/dg/post_process.h"
#include "polydg/physics/fem/tet_method.h"
#include "polydg/physics/solvers/error_estimate.h"
#include "polydg/physics/solvers/static_report.h"

namespace polydg {

/// What sliver fractions multiply.
enum class ReferenceKind {
  GridCell,       ///< the volume of the slicing grid's cell
  MedianElement,  ///< the median element volume of the mesh when it was first read
};

/// Where a mesh came from and the scale its rules refer to. It travels with the mesh (VTU field
/// data, model/provenance.h), so `polydg mesh` then `polydg cut` applies the same sliver
/// threshold as one `polydg run` of the same steps.
struct Provenance {
  std::string source;     ///< the file the mesh was made from; "" if built in memory
  double cellSize = 0.0;  ///< edge of the slicing grid's cells; 0 if not sliced by polydg
  /// The volume sliver fractions multiply: cellSize^3 for a sliced mesh, else the median
  /// element volume when the mesh was first read. Positive.
  double referenceVolume = 0.0;
  ReferenceKind referenceKind = ReferenceKind::MedianElement;
  /// The sliver rule: pieces below this fraction of the reference volume are slivers. Meshing
  /// sets it (MeshOptions::sliverFraction); later cuts and merges use it unless told otherwise.
  double sliverFraction = kDefaultSliverFraction;
  /// The planes of the cuts made so far, in order (a polygon blade's plane): the export names
  /// each one's faces as a patch (cut0, cut1, ...).
  std::vector<Plane> cuts;
};

// --- creation ------------------------------------------------------------------------------

/// Options of Model::fromSurface() (`polydg mesh`, pipeline mesh steps, polydg.mesh()).
struct MeshOptions {
  /// Cell edge length; if unset, `cells` cells along the bounding box's longest side.
  std::optional<double> cellSize;
  int cells = 0;
  RepairMode repair = RepairMode::None;
  /// Slivers by isSliver() (mesh/merge_elements.h) with T = this fraction of a cell's volume
  /// (volume below T, or 6 volume / area below T^(1/3)) are merged into a neighbour (0: off).
  double sliverFraction = kDefaultSliverFraction;
  /// Octree slicing: the cell size above (cellSize or cells) is the finest, used only where the
  /// surface passes; the grid starts 2^levels times coarser and each round splits the elements
  /// the surface passes into the octants of their cell, and any neighbour more than one level
  /// coarser than a neighbour, so face neighbours differ by at most one level.
  bool adaptive = false;
  /// The element-local DG checks (degree 1) of the new mesh, besides the geometric validation.
  bool dgChecks = true;
  /// Moments to keep on the model: 0 integrates only what the DG checks read (for a mesh that is
  /// written and dropped); d >= 2 integrates every face once to degree d, the DG checks read
  /// them, and later operations of up to degree d integrate nothing again.
  int momentDegree = 0;
  /// If not empty, the mesh is written to this VTU while it is validated and checked (the three
  /// overlap); the file appears only if every check passed.
  std::string output;
  /// Write `output` as the tets of the new mesh (tetrahedralize(): VTK_TETRA cells, the
  /// polyhedral mesh's vertices first, its provenance as field data) instead of the polyhedral
  /// mesh, once every check of the polyhedral mesh has passed. Needs `output`.
  bool tets = false;
  ProgressFn progress;  ///< slicing progress in [0, 1]
};

/// MeshOptions::tets: the tet mesh written in place of the polyhedral mesh.
struct TetOutputReport {
  TetrahedralizeReport split;     ///< tets, Steiner points, cones and TetGen's elements, seconds
  std::size_t vertices = 0;       ///< the tet mesh's: the polyhedral mesh's and the Steiner points
  double volume = 0.0;            ///< the sum of the tets' volumes (sixVolume() / 6, in double)
  double polyhedralVolume = 0.0;  ///< the polyhedral mesh's (MeshingReport::outputVolume)
  double volumeRelDifference = 0.0;  ///< (volume - polyhedralVolume) / polyhedralVolume
  double writeSeconds = 0.0;
};

struct MeshReport {
  MeshingReport meshing;  ///< input checks, grid, slicing, slivers, geometric validation
  /// The DG checks of the new mesh (no geometry: that is meshing.validation); empty local
  /// check when skipped (MeshOptions::dgChecks false, or the geometry failed).
  MeshCheck dg;
  /// MeshOptions::adaptive: the levels below the coarse grid (its cell edge: the finest *
  /// 2^levels), the elements of each level at the end, and the time the refinement took.
  int levels = 0;
  double coarseCellSize = 0.0;
  std::vector<std::size_t> elementsPerLevel;
  std::vector<int> elementLevels;  ///< each element's level (0: a coarse grid cell or its piece)
  double refineSeconds = 0.0;
  std::string output;                   ///< the file written, "" if none
  std::optional<TetOutputReport> tets;  ///< MeshOptions::tets: set when the tets were written
  double readSeconds = 0.0;             ///< set by callers that read the surface (fromFile)
  double writeSeconds = 0.0;            ///< overlapped with the checks
  double wallSeconds = 0.0;             ///< the whole operation, read to write

  bool passed() const { return meshing.geometry.passed && dg.passed(); }
  /// One line per failed check (empty when passed).
  std::vector<std::string> failures() const;
};

/// What Model::read() found.
struct ReadReport {
  std::string file;
  std::size_t elements = 0, faces = 0, vertices = 0;
  bool provenanceRestored = false;  ///< the file carried polydg's provenance field data
  double seconds = 0.0;
};

// --- operations ----------------------------------------------------------------------------

/// A cut of the model (`polydg cut`, pipeline cut steps, Model.cut in Python).
struct CutRequest {
  Blade blade;
  /// +1: delete the plus side (normal . x > offset), -1 the minus side, 0 keep both.
  int removeSide = 0;
  /// Pieces below this fraction of the reference volume are merged (0: never); unset: the
  /// mesh's sliver rule (Provenance::sliverFraction).
  std::optional<double> sliverFraction;
  CheckLevel checks = CheckLevel::Local;
  int checkDegree = 1;
};

/// A sliver merge (`merge` pipeline steps).
struct MergeRequest {
  std::optional<double> fraction;  ///< unset: the mesh's sliver rule
  CheckLevel checks = CheckLevel::Local;
  int checkDegree = 1;
};

/// How refinement splits an element (paper section 10, thesis Fig. 4.9).
enum class RefineSplit {
  Octants,  ///< 1-to-8: the three mid-planes of the element's bounding box
  Halves,   ///< 1-to-2: the plane through the centroid across a direction
};

/// A refinement of the model (Model.refine in Python, `solve --adapt`, the `adapt` scene key).
struct RefineRequest {
  std::vector<ElementId> elements;  ///< the elements to split, each once
  RefineSplit split = RefineSplit::Octants;
  /// Halves: the direction across which each element is split, one per element; empty: the
  /// direction of the largest absolute principal stress of the last solution.
  std::vector<Vec3> directions;
  /// If not empty: each element's own planes (1 to 3, every piece so far split by the next),
  /// instead of `split`'s.
  std::vector<std::vector<Plane>> planes;
  /// A piece below this fraction of its element's volume / number of children is merged into
  /// a neighbour; unset: the mesh's sliver rule (Provenance::sliverFraction).
  std::optional<double> sliverFraction;
  CheckLevel checks = CheckLevel::Local;
  int checkDegree = 1;
};

/// What a refinement did, with the fate of the last solution.
struct RefineReport {
  OperationReport operation;
  /// The last solution, if there was one, went to the children exactly (a polynomial
  /// restricted to a piece is the same polynomial): elements that took it exactly, and
  /// elements made of pieces of several (a merged sliver) that took their first source's.
  std::size_t solutionExact = 0, solutionExtended = 0;
};

/// A coarsening: groups of elements merged back into one each (children of a refinement).
struct CoarsenRequest {
  std::vector<std::vector<ElementId>> groups;
  CheckLevel checks = CheckLevel::Local;
  int checkDegree = 1;
};

/// What a coarsening did: the last solution, if any, went to the merged elements by L2
/// projection (mass and momentum kept exactly) in `solutionProjected` of them.
struct CoarsenReport {
  OperationReport operation;
  std::size_t solutionProjected = 0;
};

/// What `solve --adapt` refines by.
enum class AdaptCriterion {
  Error,   ///< the a posteriori error estimate (physics/solvers/error_estimator.h), bulk marking
  Stress,  ///< the largest absolute principal stress above a threshold (the paper's)
};

/// Adaptive static solves: solve, estimate or measure, mark, refine, until the goal is met.
struct AdaptOptions {
  AdaptCriterion criterion = AdaptCriterion::Error;
  RefineSplit split = RefineSplit::Octants;
  /// Error: stop once the estimate falls below this fraction of the solution's energy norm.
  std::optional<double> targetError;
  /// Stop before a refinement that would make more DOFs than this.
  std::optional<std::size_t> maxDofs;
  /// Error: mark the fewest elements that hold this share of the squared estimate (Dörfler).
  double bulk = 0.5;
  /// Stress: refine elements whose largest absolute principal stress exceeds this fraction of
  /// the first solve's largest.
  double stressFraction = 0.5;
  /// Stress: how often an element of the first mesh may be split, 1 to 8. An element split
  /// that often is not marked again: a child's mean stress rises above its parent's only
  /// because it averages over less of the stress's gradient (the outer fibre of a bent bar),
  /// so a fixed threshold would otherwise re-mark most children every round. 1 is Fig. 4.9's
  /// one level; later rounds still mark elements whose stress the refinement raised.
  int maxLevel = 1;
  /// Refinement rounds at most.
  int maxRounds = 3;
};

/// A traction (force per area) on a region of the boundary.
struct TractionLoad {
  FaceSelector where;
  Vec3 traction = Vec3::Zero();
};

/// A static solve (`polydg solve`, pipeline solve steps, Model.solve in Python).
struct SolveOptions {
  Material material;
  /// Method, BZ penalty, basis degree and penalty rule (with eta for a fixed penalty).
  DiscretizationOptions discretization;
  Vec3 gravity = Vec3::Zero();
  std::vector<FaceSelector> clamps;  ///< u = 0 (weakly) on each; at least one
  std::vector<TractionLoad> tractions;
  SolverKind solver = SolverKind::Auto;
  /// A body force per volume besides density * gravity (library and Python; empty: none).
  VectorField bodyForce;
  /// u = value (weakly) on each selection, besides the clamps (library and Python).
  std::vector<DirichletCondition> displacements;
  /// Estimate the solution's error (physics/solvers/error_estimator.h; IP only).
  bool estimate = false;
  /// A known solution to measure the error against (verification, library and Python): the
  /// report's error and energyError, and each adaptive round's. Both or neither.
  VectorField exactDisplacement;
  GradientField exactGradient;
  /// Solve adaptively (the model is refined in place); unset: one solve.
  std::optional<AdaptOptions> adapt;
  /// A tet method ("fem", "fs-fem") instead of DG: the model must be all tetrahedra, and the
  /// DG options (degree, penalty, the estimate, adaptivity, an exact solution) keep their
  /// defaults. A clamp holds every corner of the faces it selects (strongly); a traction puts a
  /// third of each face's force on each corner.
  std::optional<TetMethod> tetMethod;

  /// The one check of a solve's options (material, discretization, finite loads, something
  /// that holds the body, the estimate's method): throws InvalidOption naming the key.
  void check() const;
};

/// One round of an adaptive solve: the mesh it solved on and what it did next.
struct AdaptRound {
  std::size_t elements = 0, dofs = 0;
  double estimate = 0.0;       ///< Error: the estimate of the energy-norm error
  double energyNorm = 0.0;     ///< Error: the solution's energy norm
  double largestStress = 0.0;  ///< largest absolute principal stress (element means)
  /// With an exact solution (SolveOptions::exactDisplacement): the L2 error and the energy
  /// error (estimate / energyError is the estimator's effectivity index).
  double l2Error = 0.0, energyError = 0.0;
  std::size_t marked = 0;  ///< elements marked for refinement (0: the last round)
  std::size_t elementsAfter = 0;
  std::string stop;  ///< the last round: why it stopped
  double solveSeconds = 0.0, estimateSeconds = 0.0, refineSeconds = 0.0;
};

/// What a solve did, with the figures of its solution.
struct SolveReport {
  SolveOptions options;
  StaticReport solve;
  std::vector<std::size_t> clampFaces;     ///< boundary faces each clamp selected
  std::vector<std::size_t> tractionFaces;  ///< boundary faces each traction selected
  double maxDisplacement = 0.0;            ///< largest |u_K(v)| over element corners
  double maxVonMises = 0.0;                ///< largest element von Mises stress
  double maxJump = 0.0;                    ///< largest displacement jump across interior faces
  std::size_t facesIntegrated = 0;         ///< by this solve (0 when the model's moments sufficed)
  std::vector<AdaptRound> rounds;          ///< an adaptive solve's rounds, the last one solved
  /// SolveOptions::estimate: the error estimate, and the solution's energy norm sqrt(U.K.U).
  std::optional<ErrorEstimate> estimate;
  double energyNorm = 0.0;
  /// With an exact solution: L2 and H1 errors, and the error in the estimate's energy norm.
  std::optional<ErrorNorms> error;
  std::optional<EnergyError> energyError;
  /// The force the body's stress puts on each clamp's faces, then on each prescribed
  /// displacement's (SolveOptions::clamps, then displacements): int sigma(u_h) n dA, n out of
  /// the body. At equilibrium the clamps' forces balance the loads; the reaction on the support
  /// is their opposite.
  std::vector<Vec3> clampForces;
  /// What the user should know about the result, a sentence each (BZ's fixed penalty).
  std::vector<std::string> warnings;
  /// A tet method's counts (SolveOptions::tetMethod), unset for DG.
  struct TetCounts {
    std::size_t nodes = 0, tets = 0, heldNodes = 0;
  };
  std::optional<TetCounts> tets;
};

/// The solution of the model's last solve, until the mesh changes.
struct Solution {
  std::unique_ptr<DgBasis> basis;
  Eigen::VectorXd coefficients;  ///< LinearSystem's layout
  Material material;
  CornerValues corners;  ///< u_K at every corner (eq. 17 averages them per side of a cut)
  ElementFields fields;  ///< mean displacement, von Mises, largest jump per element
};

struct WriteOptions {
  VtuEncoding encoding = VtuEncoding::Appended;
  /// Add the last solution's fields (point displacement, per element mean displacement, von
  /// Mises stress, largest jump) if there is one.
  bool solution = true;
};

/// A surface carried by the model's displacement (physics/contact/embedding.h).
struct EmbeddedSurface {
  std::string file;  ///< the surface's file
  TriangleSurface surface;
  std::shared_ptr<SurfaceEmbedding> embedding;  ///< its vertices, in the basis it was made for
};

// Simulation (model/scene.h defines these).
struct Scene;
struct SimulateOptions;
struct SimulationReport;

struct WriteReport {
  std::string file;
  bool withSolution = false;
  double seconds = 0.0;
};

/// A named boundary patch of an export: the boundary faces `where` selects.
struct ExportPatch {
  std::string name;
  FaceSelector where;
};

/// How exportOpenFoam() writes the case.
struct ExportOptions {
  /// Patches before the default ones (wall: the input surface; cut0, cut1, ...: the faces of
  /// each recorded cut; cut: other cut faces); a face selected by several goes to the first.
  std::vector<ExportPatch> patches;
  bool binary = false;  ///< OpenFOAM's binary format instead of ASCII
};

struct ExportReport {
  std::string folder;
  OpenFoamReport foam;  ///< counts, patches and checkMesh's figures
  double seconds = 0.0;
};

/// A polyhedral mesh with its cached integrals, editor and provenance. Operations keep the
/// moment cache up to date: every face is integrated once (to the highest degree asked for so
/// far) and again only when an edit changes it; facesIntegrated() counts every integration.
/// Not thread-safe: one thread at a time (const members may be called concurrently).
class Model {
 public:
  /// A model of `mesh` (which must be valid for the operations to mean anything). An unset or
  /// non-positive reference volume in `provenance` becomes the median element volume.
  explicit Model(PolyMesh mesh, Provenance provenance = {});
  ~Model();
  Model(Model&&) noexcept;
  Model& operator=(Model&&) noexcept;

  /// Meshes a surface: checks it, orients or repairs it, slices it, merges slivers, validates
  /// the mesh and runs the DG checks of `options`. Throws InputError (one line naming the
  /// defect) for a surface it refuses. A mesh that fails a check is returned with
  /// `report.passed()` false (and no file written); `source` becomes the provenance's.
  static Model fromSurface(const TriangleSurface& surface, const MeshOptions& options,
                           MeshReport& report, const std::string& source = "");

  /// Reads a VTU file (mesh/vtu_io.h) with its provenance if polydg wrote it, or a tet mesh
  /// (TetGen .ele, Gmsh .msh: readTetMesh, its tets as elements). Throws InputError for a file
  /// it cannot read.
  static Model read(const std::string& path, ReadReport* report = nullptr);

  const PolyMesh& mesh() const;
  const Provenance& provenance() const;
  /// Sum of the element volumes (from the moments if integrated, else signedVolume()).
  double volume() const;

  /// The moments up to at least `degree` (integrated now if the cache holds less).
  const MomentCache& moments(int degree = 2);
  /// Faces integrated over the model's life (every integration of every face counts).
  std::size_t facesIntegrated() const;

  /// Cuts the model in place and validates the operation. Throws InputError for bad options.
  /// A failed validation, or a cut that leaves nothing, is reported (validation.passed false,
  /// validation.failure naming the check); the model must then not be used further: its
  /// operations throw CheckFailure naming the failed one.
  OperationReport cut(const CutRequest& request);
  /// Merges slivers (see MergeRequest), validated like a cut.
  OperationReport mergeSlivers(const MergeRequest& request);
  /// Splits elements (see RefineRequest) with the new faces coupled, validated like a cut; the
  /// last solution, if any, goes to the children exactly and stays the model's solution.
  /// Throws InputError for an element id not in the mesh, one listed twice, or Halves without
  /// directions or a solution.
  RefineReport refine(const RefineRequest& request);
  /// Merges groups of elements back into one each (see CoarsenRequest), validated like a cut;
  /// the last solution, if any, is projected onto the merged elements (L2) and stays the model's
  /// solution. Throws InputError for an element not in the mesh, one listed twice or a group of
  /// fewer than two.
  CoarsenReport coarsen(const CoarsenRequest& request);

  /// The checks of `options` (physics/checks/mesh_checks.h) with the model's moments.
  MeshCheck check(const MeshCheckOptions& options);

  /// Static linear elasticity: validates the mesh, selects the clamped and loaded faces
  /// (InputError naming a selection that picks no face), assembles with the model's moments,
  /// solves, and keeps the solution (solution()). Throws CheckFailure if the mesh is invalid or
  /// the stiffness is singular (a piece left free).
  SolveReport solve(const SolveOptions& options);
  /// The last solve's solution; null after an edit or before any solve.
  const Solution* solution() const;

  /// Moves the body in time through `scene` (model/scene.h): validates the mesh and the scene's
  /// selections (InputError naming one that picks no face), steps, cuts at the scene's times
  /// through cut() (each new element takes its parent's displacement and velocity polynomials
  /// exactly), writes frames if asked. Afterwards the model holds the cut mesh and, as its
  /// solution, the final displacement. Throws CheckFailure if the mesh is invalid, a cut fails
  /// its validation (the model is then broken, as after cut()), or a step's solve fails.
  /// If it stops early (an error, or an exception from the progress callback), the cuts made
  /// so far stay and the solution is the one before the simulation (none after a cut).
  /// With a tet method (scene.tetMethod: "fem", "fs-fem") the mesh must be all tetrahedra
  /// (toTetMesh; InputError naming the first element that is not) and simulateOnTets
  /// (model/tet_simulation.h) moves it; the model's solution is then the final displacement
  /// (linear on each tet, as DG degree 1).
  SimulationReport simulate(const Scene& scene, const SimulateOptions& options);

  /// Reads `file` (or, if "", the surface the mesh was sliced from: the provenance's source)
  /// and embeds its vertices into `basis` if given (a basis of the current mesh), else the DG
  /// basis of degree `degree` (the last solution's basis when it has that degree). Throws
  /// InputError naming a surface it cannot read, or a mesh that records no source.
  EmbeddedSurface embedSurface(const std::string& file, int degree,
                               const EmbeddingOptions& options = {},
                               const DgBasis* basis = nullptr);

  /// Writes the model as a VTU file with its provenance (and the solution's fields, see
  /// WriteOptions), atomically: `path` is never left half-written.
  WriteReport write(const std::string& path, const WriteOptions& options = {}) const;

  /// Writes the mesh as an OpenFOAM case folder (writeOpenFoamCase, mesh/openfoam.h), never
  /// half-written, with OpenFOAM's checkMesh figures in the report. Throws InputError naming a
  /// patch whose region selects no boundary face, or what writeOpenFoamCase refuses.
  ExportReport exportOpenFoam(const std::string& folder, const ExportOptions& options = {}) const;

 private:
  struct State;
  friend class Simulation;  ///< model/simulation.h: a scene's run edits the model as it goes
  std::unique_ptr<State> state_;
};

/// The default reference volume of a mesh read from a file: its median element volume.
double medianElementVolume(const PolyMesh& mesh);

}  // namespace polydg
