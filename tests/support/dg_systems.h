// DG systems for solver tests: K and F of benchmarks B1 and B2 (cli/bench/problems.h), with the
// element frames the p-multigrid's agglomeration levels need.
#pragma once

#include "cli/bench/problems.h"
#include "physics/solvers/agglomeration.h"
#include "physics/solvers/static_solver.h"

namespace polydg {

/// K, F and the frames of the basis (physics/solvers/agglomeration.h).
struct FramedSystem {
  LinearSystem system;
  ElementFrames frames;
};

/// K, F and frames of `loads` on `mesh`. BZ with its fixed penalty ~1/h, the conditioning of
/// IP's: the systems these solver tests were written for (the superpenalty's are far stiffer).
inline FramedSystem framedSystem(const PolyMesh& mesh, const Material& material,
                                 const LoadCase& loads, Method method, int degree) {
  StaticOptions o;
  o.discretization.method = method;
  if (method == Method::BZ) o.discretization.bzPenalty = BzPenalty::Fixed;
  o.discretization.basis.degree = degree;
  StaticSolver solver(mesh, material, o);
  solver.assemble(loads);
  return {solver.system(), elementFrames(solver.basis(), mesh)};
}

/// K, F and frames of B1 on `mesh` (Dirichlet on the whole boundary, so K is SPD).
inline FramedSystem b1FramedSystem(const PolyMesh& mesh, Method method, int degree) {
  const bench::ManufacturedProblem problem = bench::benchmarkB1Problem();
  return framedSystem(mesh, problem.material, bench::benchmarkB1Loads(problem), method, degree);
}

/// K and F of B1 on `mesh`.
inline LinearSystem b1System(const PolyMesh& mesh, Method method, int degree) {
  return b1FramedSystem(mesh, method, degree).system;
}

/// K, F and frames of B2 (the clamped cube under gravity: it bends, so rotations dominate
/// the smooth part of the error).
inline FramedSystem b2FramedSystem(Method method, int degree) {
  return framedSystem(bench::benchmarkB2Mesh(), bench::benchmarkB2Material(),
                      bench::benchmarkB2Loads(), method, degree);
}

}  // namespace polydg
