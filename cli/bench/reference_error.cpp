#include "cli/bench/reference_error.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "physics/solvers/error_estimator.h"

namespace polydg::bench {

SolveOptions manufacturedSolveOptions(const ManufacturedProblem& problem, int degree) {
  SolveOptions o;
  o.discretization.basis.degree = degree;
  o.material = problem.material;
  o.displacements = {{FaceSelector::allBoundary(), problem.displacement}};
  o.bodyForce = problem.bodyForce;
  o.exactDisplacement = problem.displacement;
  o.exactGradient = problem.gradient;
  return o;
}

std::vector<ReferenceProblem> referenceProblems() {
  SolveOptions pulled;
  pulled.material.youngsModulus = 1000.0;
  pulled.material.poissonRatio = 0.3;
  pulled.clamps = {FaceSelector::inPlane(1, 2.0)};
  pulled.tractions = {{FaceSelector::inPlane(0, 2.0), Vec3(0, 10, 0)}};
  SolveOptions hanging;
  hanging.material = pulled.material;
  hanging.material.density = 1.0;
  hanging.gravity = Vec3(0, 0, -10);
  hanging.clamps = {FaceSelector::below(Plane::make(Vec3::UnitX(), -1.0))};
  return {{"L-prism", "Lprism.ply", 5, pulled}, {"torus", "torus.obj", 6, hanging}};
}

ReferenceCheck checkAgainstReference(const PolyMesh& mesh, const SolveOptions& options, int levels,
                                     int referenceDegree) {
  ReferenceCheck out;
  Model coarse(mesh);
  SolveOptions once = options;
  once.estimate = true;
  const SolveReport report = coarse.solve(once);
  const ErrorEstimate& estimate = *report.estimate;
  out.elements = coarse.mesh().numElements();
  out.dofs = report.solve.dofs;
  out.estimate = estimate.total;

  Model fine(mesh);
  std::vector<ElementId> parent(mesh.numElements());
  for (std::size_t e = 0; e < parent.size(); ++e) parent[e] = ElementId(e);
  for (int level = 0; level < levels; ++level) {
    RefineRequest request;
    request.split = RefineSplit::Octants;
    request.sliverFraction = 0.0;
    request.checks = CheckLevel::None;
    for (std::size_t e = 0; e < fine.mesh().numElements(); ++e)
      request.elements.push_back(ElementId(e));
    const RefineReport r = fine.refine(request);
    std::vector<ElementId> next(fine.mesh().numElements());
    for (std::size_t e = 0; e < next.size(); ++e) {
      const std::vector<ElementId> sources = r.operation.lineage.sources(ElementId(e));
      if (sources.size() != 1)
        throw std::logic_error("checkAgainstReference: a fine element with several parents");
      next[e] = parent[sources.front().index()];
    }
    parent.swap(next);
  }
  SolveOptions reference = options;
  reference.estimate = false;
  reference.discretization.basis.degree = referenceDegree;
  const SolveReport fineReport = fine.solve(reference);
  out.referenceElements = fine.mesh().numElements();
  out.referenceDofs = fineReport.solve.dofs;

  const Solution& uh = *coarse.solution();
  const Solution& ur = *fine.solution();
  const int degree = 2 * std::max(options.discretization.basis.degree, referenceDegree);
  const double broken = brokenEnergyDifference(fine.mesh(), *ur.basis, ur.coefficients, *uh.basis,
                                               uh.coefficients, parent, options.material, degree);
  out.error = std::sqrt(broken * broken + estimate.displacementJump + estimate.dirichlet);
  return out;
}

}  // namespace polydg::bench
