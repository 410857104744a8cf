// Simulation: a scene running on a model (Model::simulate() runs one to its end). It holds the
// moving body (DynamicSolver), the embedded surface and the contact with the obstacles, the
// time series, and the edits a scene makes between steps: cuts at given times and refinement
// and coarsening by stress, after each of which the fields, the surface and the contact points
// follow the new elements. Each phase is a method. Private to model/.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "model/field_transfer.h"
#include "model/model_state.h"
#include "model/refinement_families.h"
#include "model/time_series.h"
#include "physics/contact/contact.h"
#include "physics/dynamics/dynamics.h"
#include "polydg/model/scene.h"
#include "util/stopwatch.h"

namespace polydg {

/// What a time step did with its matrix, in words ("cholesky: factorization reused", "cg
/// (block-jacobi): preconditioner built"); `first`: the solver's first step.
std::string solverAction(const StepReport& r, SolverKind kind, bool first);

class Simulation {
 public:
  /// Checks the scene (checkScene()), the mesh and the scene's selections (InputError naming
  /// one that picks no face), and sets up the body, its initial velocity, the embedded surface,
  /// the contact and the output folder.
  Simulation(Model& model, Model::State& state, const Scene& scene, const SimulateOptions& options);

  /// Every step of the scene with its edits and frames; afterwards the model holds the last
  /// mesh and, as its solution, the final displacement. Throws CheckFailure if a step's solve
  /// or an edit's checks fail.
  SimulationReport run();

 private:
  // Setup.
  DynamicSolver makeSolver();
  std::size_t replaceSolver(const OperationReport& edit);
  void setInitialVelocity();
  void embedSurface();
  void setUpContact();
  void makeContact();
  // One time step: the solve and the step's report.
  void step(int k);
  // Edits between steps.
  bool cutsDue(double t);
  bool adaptationDue(int k);
  void afterEdit(const ElementLineage& lineage, const DgBasis& oldBasis,
                 const Eigen::VectorXd& oldU, const Eigen::VectorXd& oldV, double time,
                 bool project, TransferCounts* counts);
  // Output.
  void writeFrame(int k);
  void finish();

  Stopwatch wall_;  ///< from the start: the checks and the setup count in wallSeconds
  Model& model_;
  Model::State& state_;
  const Scene& scene_;
  const SimulateOptions& options_;
  SimulationReport report_;
  DynamicsOptions dynamics_;
  DynamicLoads loads_;
  std::size_t integratedBefore_ = 0;
  std::optional<DynamicSolver> solver_;
  std::unique_ptr<TimeSeries> series_;
  // The embedded surface and the contact points and obstacles.
  EmbeddedSurface surface_;
  bool contactOnSurface_ = false;
  std::vector<double> areas_;
  std::unique_ptr<SurfaceEmbedding> nodes_;
  std::vector<Obstacle> obstacles_;
  ContactOptions contactOptions_;
  std::unique_ptr<ContactModel> contact_;
  // Edits.
  RefinementFamilies families_;
  std::size_t nextCut_ = 0;
  bool editedSinceFrame_ = false;
  bool freshSolver_ = true;  ///< no step since the solver was made (its first factorization)
  std::size_t cutsAwaitingStep_ = 0;  ///< cuts of the last step boundary, before their next step
};

}  // namespace polydg
