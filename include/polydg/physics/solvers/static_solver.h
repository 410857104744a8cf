// Static linear elasticity on a polyhedral mesh with the DG methods: the pipeline
// moments -> basis -> penalty -> assembly -> solve, as a stateful StaticSolver that keeps
// every stage (and the factorization) and as the one-shot solveStatic().
#pragma once

#include <memory>

#include "polydg/physics/dg/assembly.h"
#include "polydg/physics/dg/block_rows.h"
#include "polydg/physics/solvers/linear_solver.h"

namespace polydg {

/// How the global penalty eta of eq. (7) is chosen.
enum class PenaltyRule {
  /// eta = safety * the coercivity bound: guaranteed SPD, no trial factorizations. Per
  /// element (elementPenaltyThresholds()) unless PenaltyOptions::local is false, then the
  /// global penaltyThreshold().
  TraceBound,
  /// The paper's rule (section 10): start at `eta` and double until the Cholesky
  /// factorization succeeds. Costs one factorization per attempt.
  Doubling,
  /// eta = `eta` as given.
  Fixed,
};

struct PenaltyOptions {
  PenaltyRule rule = PenaltyRule::TraceBound;
  double eta = 1.0;     ///< Fixed: the value; Doubling: the first value tried
  double safety = 1.0;  ///< TraceBound: multiple of the threshold
  /// TraceBound: each element's own bound eta_K (FormCoefficients::elementEta), so that a
  /// badly shaped element does not raise the penalty, and spoil the accuracy, everywhere; false:
  /// the largest bound for every face, as in the paper's global eta.
  bool local = true;
};

struct DiscretizationOptions {
  Method method = Method::IP;
  /// Method::BZ: how its penalty scales with the mesh (the superpenalty converges).
  BzPenalty bzPenalty = BzPenalty::Fixed;
  /// BzPenalty::Super: the reference length L of superpenaltyFactor(); 0 picks the mesh's
  /// bounding-box diagonal. In the model's length unit.
  double bzReferenceLength = 0.0;
  BasisOptions basis;
  PenaltyOptions penalty;
  /// Degree of exactness of the quadrature for non-polynomial loads (body force function,
  /// Dirichlet data); -1 picks 2p + 2.
  int quadratureDegree = -1;
};

struct StaticOptions {
  DiscretizationOptions discretization;
  SolverOptions solver;
};

/// Figures of one static solve. Times are wall seconds.
struct StaticReport {
  std::size_t elements = 0;
  std::size_t dofs = 0;
  std::size_t nonzeros = 0;   ///< stored entries of K (both triangles)
  double eta = 0.0;           ///< the global penalty used (local: the largest eta_K)
  double etaThreshold = 0.0;  ///< penaltyThreshold() (the IP coercivity bound)
  double bzFactor = 1.0;      ///< FormCoefficients::bzFactor (BZ superpenalty: (L/h)^(2p))
  int penaltyAttempts = 1;    ///< factorizations tried by PenaltyRule::Doubling
  std::size_t dirichletFaces = 0, tractionFaces = 0;
  std::size_t basisFallbacks = 0;  ///< DgBasis::fallbackElements()
  /// The thesis's phases (Kaufmann 2013, Table 4.1). Integration: moments, bases, face roles,
  /// penalty bounds, and the element and face matrices (localMatrices()).
  double integrateSeconds = 0.0;
  double assembleSeconds = 0.0;  ///< accumulating K from them, and the load vector F
  double solveSeconds = 0.0;     ///< factorization (or preconditioner) and solve
  /// Faces integrated by this solve: every face of the mesh when the solver made its own
  /// moments, 0 when it used the caller's (StaticSolver's `moments` argument).
  std::size_t facesIntegrated = 0;
  LinearSolveReport solver;
  double energy =
      0.0;  ///< U.F / 2: the strain energy U.K.U / 2 when prescribed displacements are 0
};

/// A solved problem: the bases and the DG coefficients (see LinearSystem for the layout).
struct StaticSolution {
  std::unique_ptr<MomentCache> moments;  ///< the solver's own; null if it used the caller's
  std::unique_ptr<DgBasis> basis;
  Eigen::VectorXd coefficients;
  StaticReport report;
};

/// The factor (L/h)^(2p) of the BZ superpenalty (BzPenalty::Super), p = basis.degree(): L is
/// `referenceLength`, or the diagonal of the mesh's bounding box if it is 0; h is the largest
/// element length, the bounding-box diagonal of an element (2 DgBasis::scale(), the length the
/// basis is scaled by). Dimensionless, so invariant to the model's unit and position; 1 on a
/// mesh of one element, n^(2p) on an n x n x n grid of a cube (L/h = n). One h for the whole
/// mesh: eta_F already grows as 1/h locally (area(F)/vol(K)), and a small cut piece does not
/// raise the factor (and the condition number) everywhere. Under uniform refinement eta_F then
/// scales as h^-(2p+1), Babuska and Zlamal's rate. Throws std::invalid_argument for a negative
/// or non-finite `referenceLength`.
double superpenaltyFactor(const PolyMesh& mesh, const DgBasis& basis, double referenceLength = 0.0);

/// What a FormCoefficients of the TraceBound rule points to: each element's bound eta_K and the
/// face area a_K its penalty is spread by (FormCoefficients::elementEta, elementFaceArea).
struct ElementPenalties {
  ElementData<double> eta;
  ElementData<double> faceArea;
};

/// The coefficients of the form of `disc` for `material`: the penalty by its rule (TraceBound:
/// the coercivity bounds of penaltyThreshold(), per element into `penalties`, which the form
/// then points to and which must outlive it; Fixed and Doubling: the given eta, on eq. 7's
/// face areas), and the BZ penalty's factor (`disc.bzPenalty`, superpenaltyFactor()).
/// `threshold` is the largest bound. Throws std::invalid_argument for a non-positive eta.
FormCoefficients formCoefficients(const PolyMesh& mesh, const DgBasis& basis,
                                  const MomentCache& moments, const FaceRoles& roles,
                                  const Material& material, const DiscretizationOptions& disc,
                                  ElementPenalties& penalties, double& threshold);

/// The stages of a static solve, each callable again (e.g. assemble() with new loads reuses
/// the moments and bases; solve() reuses the factorization when only F changed).
class StaticSolver {
 public:
  /// `mesh` must outlive the solver.
  /// `moments`, if given, is the mesh's moment cache, up to date and of degree >= 2p (a model's,
  /// kept through a pipeline): the solver uses it instead of integrating the mesh again, and it
  /// must outlive the solver. Throws std::invalid_argument if its degree is too low.
  StaticSolver(const PolyMesh& mesh, const Material& material, const StaticOptions& options,
               const MomentCache* moments = nullptr);

  /// The bases, with moments up to degree 2p integrated here unless the caller gave them.
  void integrate();
  /// Face roles, penalty, element and face matrices (timed as integration), K and F for
  /// `loads` (calls integrate() first if needed). With
  /// PenaltyRule::Doubling this factorizes K for each trial eta.
  void assemble(const LoadCase& loads);
  /// Factorizes K (unless done) and solves; throws std::runtime_error if K is not positive
  /// definite (e.g. no Dirichlet condition: rigid motions are free).
  const Eigen::VectorXd& solve();

  const MomentCache& moments() const { return *moments_; }
  const DgBasis& basis() const { return *basis_; }
  /// K (CSR) and F. A system solved by CG keeps K by block rows only (assemble()); the CSR
  /// matrix is then made from them on the first call (a second copy of K, for callers that
  /// need the matrix itself: condition estimates, zero-mode counts).
  const LinearSystem& system() const;
  /// K u, from whichever copy of K the solver keeps.
  Eigen::VectorXd stiffnessTimes(const Eigen::VectorXd& u) const;
  const FaceRoles& roles() const { return roles_; }
  const FormCoefficients& form() const { return form_; }
  const StaticReport& report() const { return report_; }
  /// Moves the results out (the solver is then spent).
  StaticSolution release();

 private:
  /// K from `local` into `matrix`, without copying it.
  void assembleInto(const LocalMatrices& local,
                    Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix) const;

  const PolyMesh* mesh_;
  Material material_;
  StaticOptions options_;
  const MomentCache* moments_ = nullptr;  ///< the caller's, or ownMoments_
  std::unique_ptr<MomentCache> ownMoments_;
  std::unique_ptr<DgBasis> basis_;
  FaceRoles roles_;
  /// Per-element penalties that form_ points to (on the heap: stable under moves).
  std::unique_ptr<ElementPenalties> penalties_;
  FormCoefficients form_;
  mutable LinearSystem system_;  ///< its matrix made on demand from rows_ (system())
  /// K by block rows, when the solve is iterative (CG): then the only copy of K.
  std::unique_ptr<BlockRows<double>> rows_;
  LinearSolver solver_;
  bool factorized_ = false;
  double momentsSeconds_ = 0.0;  ///< integrate()'s share of StaticReport::integrateSeconds
  Eigen::VectorXd coefficients_;
  StaticReport report_;
};

/// One-shot: integrate (unless `moments` is given, as for StaticSolver), assemble and solve.
StaticSolution solveStatic(const PolyMesh& mesh, const Material& material, const LoadCase& loads,
                           const StaticOptions& options = {}, const MomentCache* moments = nullptr);

}  // namespace polydg
