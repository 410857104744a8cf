// A posteriori error estimation for static IP-DG elasticity solves: the residual estimator
// (element residual, traction jumps and displacement jumps) per element, the true error in the
// same norm for problems with a known solution, and the marking of elements for refinement.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "physics/solvers/static_solver.h"
#include "polydg/physics/dg/post_process.h"
#include "polydg/physics/solvers/error_estimate.h"

namespace polydg {

/// The estimate for the solution `coefficients` (layout of LinearSystem) of the static problem
/// assembled with `roles`, `form` and `loads` (as by StaticSolver::assemble(): the same face
/// roles, penalty and loads). Gravity, a constant load, does no work on the local problems'
/// fields (orthogonal to the rigid motions): it enters through the solution's flux alone. IP
/// only: throws std::invalid_argument for another method. Runs in parallel over faces and
/// elements.
ErrorEstimate estimateError(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const FaceRoles& roles, const FormCoefficients& form,
                            const LoadCase& loads, const Eigen::VectorXd& coefficients,
                            const EstimatorOptions& options = {});

/// The same for a solver after assemble(loads) and solve() (`coefficients` its solution).
ErrorEstimate estimateError(const PolyMesh& mesh, const StaticSolver& solver, const LoadCase& loads,
                            const Eigen::VectorXd& coefficients,
                            const EstimatorOptions& options = {});

/// |u - u_h| by element quadrature (integrate/quadrature.h, as errorNorms()) and face quadrature
/// exact to `quadratureDegree` (use >= p + 4 for smooth u, more for steep ones on coarse meshes).
EnergyError energyError(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                        const FaceRoles& roles, const FormCoefficients& form,
                        const Eigen::VectorXd& coefficients, const VectorField& exact,
                        const GradientField& exactGradient, int quadratureDegree);

/// sqrt(sum_k int_k sigma(e) : eps(e)), e = u_fine - u_coarse, over the elements k of a
/// refinement of the coarse mesh, fine element k lying inside coarse element parent[k]: the
/// broken energy norm of a solution's error against a reference solve on a finer mesh. Both
/// fields are polynomials on a fine element; its rule is exact to `quadratureDegree`.
double brokenEnergyDifference(const PolyMesh& fineMesh, const DgBasis& fineBasis,
                              const Eigen::VectorXd& fine, const DgBasis& coarseBasis,
                              const Eigen::VectorXd& coarse, const std::vector<ElementId>& parent,
                              const Material& material, int quadratureDegree);

/// Doerfler's bulk marking: the fewest elements whose indicators sum to at least
/// theta * sum_K indicators[K] (0 < theta <= 1), largest first (ties by element id). Empty when
/// every indicator is 0. Throws std::invalid_argument for theta outside (0, 1].
std::vector<ElementId> markBulk(const ElementData<double>& indicators, double theta);

/// The first elements of `marked` (largest first, as markBulk() orders them) that fit in a DOF
/// budget: a mesh of `dofs` DOFs in which refining one element adds `dofsPerRefinement` (8
/// children of 3 numMonomials(p) DOFs replacing one: 7 * 3 numMonomials(p)) stays within
/// `dofBudget` DOFs. Empty when the mesh is at or over the budget.
std::vector<ElementId> limitToDofBudget(std::vector<ElementId> marked, std::size_t dofs,
                                        std::size_t dofsPerRefinement, std::size_t dofBudget);

}  // namespace polydg
