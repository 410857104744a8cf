// DG systems for solver tests: K and F of benchmark B1 on a given mesh.
#pragma once

#include "physics/benchmarks.h"
#include "physics/static_solver.h"

namespace polydg {

/// K and F of B1 on `mesh` (Dirichlet on the whole boundary, so K is SPD).
inline LinearSystem b1System(const PolyMesh& mesh, Method method, int degree) {
  const ManufacturedProblem problem = benchmarkB1Problem();
  StaticOptions o;
  o.discretization.method = method;
  o.discretization.basis.degree = degree;
  StaticSolver solver(mesh, problem.material, o);
  solver.assemble(benchmarkB1Loads(problem));
  return solver.system();
}

}  // namespace polydg
