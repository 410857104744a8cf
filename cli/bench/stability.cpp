#include "cli/bench/stability.h"

#include <limits>
#include <stdexcept>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/merge_elements.h"

namespace polydg::bench {

// --- meshes ---------------------------------------------------------------------------------

PolyMesh sliverMesh(double volumeRatio) {
  if (!(volumeRatio > 0.0 && volumeRatio <= 1.0))
    throw std::invalid_argument("sliverMesh: the volume ratio must lie in (0, 1]");
  std::vector<Box3> boxes;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const Vec3 lo(i, j, k);
        if (i == 1 && j == 1 && k == 1 && volumeRatio < 1.0) {
          const double cut = 1.0 + volumeRatio;
          boxes.emplace_back(lo, Vec3(cut, 2, 2));
          boxes.emplace_back(Vec3(cut, 1, 1), Vec3(2, 2, 2));
        } else {
          boxes.emplace_back(lo, lo + Vec3::Ones());
        }
      }
  return boxCellsMesh(boxes);
}

PolyMesh thinNeckMesh(double eps) {
  if (!(eps > 0.0 && eps < 1.0))
    throw std::invalid_argument("thinNeckMesh: the neck height must lie in (0, 1)");
  Polygon2 dumbbell;
  dumbbell.outer = {{0, 0}, {3, 0}, {3, 1}, {2, 1}, {2, eps}, {1, eps}, {1, 1}, {0, 1}};
  return prismMesh(dumbbell, 0.0, 1.0);
}

// --- cases ----------------------------------------------------------------------------------

StabilityConditionRun stiffnessCondition(const PolyMesh& mesh, int degree,
                                         const FaceSelector& clamp) {
  StaticOptions options;
  options.discretization.method = Method::IP;
  options.discretization.basis.degree = degree;
  LoadCase loads;
  loads.dirichlet.push_back({clamp, {}});
  StaticSolver solver(mesh, Material{}, options);
  solver.assemble(loads);
  StabilityConditionRun run;
  run.degree = degree;
  run.elements = mesh.numElements();
  run.dofs = solver.report().dofs;
  run.eta = solver.report().eta;
  run.estimate = conditionEstimate(solver.system().matrix, solver.system().blockSize);
  run.jacobiEstimate =
      conditionEstimate(jacobiScaled(solver.system().matrix), solver.system().blockSize);
  return run;
}

StabilityConditionRun runSliverCase(double volumeRatio, bool merge, int degree) {
  PolyMesh mesh = sliverMesh(volumeRatio);
  if (merge) mesh = mergeSlivers(std::move(mesh), kStabilitySliverTau);  // unit cells
  return stiffnessCondition(mesh, degree, FaceSelector::allBoundary());
}

StabilityConditionRun runThinNeckCase(double eps, int degree) {
  return stiffnessCondition(thinNeckMesh(eps), degree, FaceSelector::inPlane(0, 0.0));
}

LockingSetup lockingSetup(int degree, bool quick) {
  LockingSetup s;  // CantileverSetup's defaults: the 40 x 4 x 4 beam
  s.options.discretization.method = Method::IP;
  s.options.discretization.basis.degree = degree;
  if (degree == 1) {
    s.mesh.nx = 160;
    s.mesh.nz = 8;
    s.options.discretization.penalty.rule = PenaltyRule::Doubling;
  }
  if (quick) s.mesh.nx /= 4;
  return s;
}

IncompressibleRun runIncompressibleCase(double nu, int degree, bool quick) {
  LockingSetup s = lockingSetup(degree, quick);
  s.mesh.poissonRatio = nu;
  const CantileverResult r = runBenchmarkB3(s.mesh, s.options);
  IncompressibleRun run;
  run.degree = degree;
  run.poissonRatio = nu;
  run.tip = r.tipDeflection;
  run.reference = cantileverReference(nu);
  run.relError = run.tip / run.reference - 1.0;
  run.report = r.report;
  return run;
}

ScaleRun runScaleCase(ScaleProblem problem, double scale, const Vec3& offset, int degree,
                      bool quick) {
  ScaleRun run;
  run.problem = problem;
  run.degree = degree;
  run.scale = scale;
  run.offset = offset;
  const DomainTransform transform{scale, offset};
  StaticOptions options;
  options.discretization.basis.degree = degree;
  double size = 0.0;
  if (problem == ScaleProblem::B1) {
    const BenchmarkRun r = runBenchmarkB1(quick ? 2 : 4, options, BenchmarkMesh::Hex, transform);
    run.value = r.l2Error / r.l2Norm;
    size = 1.0;
  } else {
    const LockingSetup s = lockingSetup(degree, quick);
    run.value = runBenchmarkB3(s.mesh, s.options, transform).tipDeflection / scale;
    size = 10.0;
  }
  const double extent = offset.cwiseAbs().maxCoeff() + scale * size;
  run.coordinateResolution = std::numeric_limits<double>::epsilon() * extent / (scale * size);
  return run;
}

double scaleProblemCondition(ScaleProblem problem, int degree, bool quick) {
  if (problem == ScaleProblem::B1)
    return stiffnessCondition(benchmarkB1Mesh(BenchmarkMesh::Hex, quick ? 2 : 4), degree,
                              FaceSelector::allBoundary())
        .estimate.cond;
  const CantileverSetup beam = lockingSetup(degree, quick).mesh;
  return stiffnessCondition(
             hexGridMesh(beam.nx, beam.ny, beam.nz, Box3(Vec3::Zero(), Vec3(10.0, 1.0, 1.0))),
             degree, FaceSelector::inPlane(0, 0.0))
      .estimate.cond;
}

}  // namespace polydg::bench
