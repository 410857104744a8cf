// The numerical-stability benchmark B4 of shared/BENCHMARKS.md: condition estimates of the DG
// stiffness matrix (with boundary conditions) on a grid with a sliver element, with and without
// sliver merging, and on one non-convex element with a thin neck; the near-incompressible
// cantilever (B3 as nu -> 1/2); and B1 and B3 scaled and translated.
#pragma once

#include "cli/bench/problems.h"
#include "physics/solvers/condition_estimate.h"

namespace polydg::bench {

/// The sliver mesh of B4: the 3 x 3 x 3 grid of unit cubes on [0,3]^3 whose centre cell is split
/// by the plane x = 1 + volumeRatio into a sliver of volume `volumeRatio` (relative to its
/// neighbours) and a piece of volume 1 - volumeRatio. volumeRatio = 1 gives the regular grid.
PolyMesh sliverMesh(double volumeRatio);

/// The thin-neck element of B4: one non-convex element, the blocks [0,1]^3 and [2,3] x [0,1]^2
/// joined by the neck [1,2] x [0,eps] x [0,1] (a prism over an 8-gon).
PolyMesh thinNeckMesh(double eps);

/// Sliver merging as in meshing (MeshingOptions::sliverTau = 0.01 of a unit cell; the rule is
/// isSliver in polydg/mesh/merge_elements.h).
inline constexpr double kStabilitySliverTau = 0.01;

/// One stiffness condition estimate of a stability case.
struct StabilityConditionRun {
  int degree = 1;
  std::size_t elements = 0, dofs = 0;
  double eta = 0.0;                  ///< the penalty used (PenaltyRule::TraceBound)
  ConditionEstimate estimate;        ///< of K
  ConditionEstimate jacobiEstimate;  ///< of jacobiScaled(K)
};

/// The IP stiffness of `mesh` (E = 1, nu = 0.3, orthonormal basis of `degree`) with u = 0
/// weakly on the boundary faces chosen by `clamp`, and the condition estimates of it and of its
/// Jacobi-scaled form.
StabilityConditionRun stiffnessCondition(const PolyMesh& mesh, int degree,
                                         const FaceSelector& clamp);

/// B4 sliver: sliverMesh(volumeRatio), merged by mergeSlivers with kStabilitySliverTau times
/// the unit cell's volume if `merge`, clamped on the whole boundary.
StabilityConditionRun runSliverCase(double volumeRatio, bool merge, int degree);

/// B4 thin neck: thinNeckMesh(eps) clamped on x = 0.
StabilityConditionRun runThinNeckCase(double eps, int degree);

/// The cantilever meshes of the locking test (tests/cli/bench/problems_test.cpp, issue 4):
/// 40 x 4 x 4 with the trace-bound penalty for p = 2; 160 x 4 x 8 with penalty doubling for
/// p = 1 (linear elements need the smaller penalty in bending). `quick` divides nx by 4 (a
/// coarser, faster smoke test; the 5% locking criterion is not meant for it).
struct LockingSetup {
  CantileverSetup mesh;
  StaticOptions options;
};
LockingSetup lockingSetup(int degree, bool quick = false);

/// B4 near-incompressible: B3 at Poisson ratio `nu` on lockingSetup(degree).
struct IncompressibleRun {
  int degree = 1;
  double poissonRatio = 0.3;
  double tip = 0.0;        ///< tip deflection
  double reference = 0.0;  ///< cantileverReference(nu)
  double relError = 0.0;   ///< tip / reference - 1
  StaticReport report;
};
IncompressibleRun runIncompressibleCase(double nu, int degree, bool quick = false);

/// B4 scale and position: B1 (hex grid n = 4) or B3 (lockingSetup mesh) with every length
/// multiplied by `scale` and the domain translated by `offset`.
enum class ScaleProblem { B1, B3 };
struct ScaleRun {
  ScaleProblem problem = ScaleProblem::B1;
  int degree = 2;
  double scale = 1.0;
  Vec3 offset = Vec3::Zero();
  /// B1: L2 error / L2 norm of the exact solution; B3: tip deflection / scale (the deflection
  /// of the unscaled beam, since displacements scale with lengths under the same tractions).
  double value = 0.0;
  /// Relative resolution of the coordinates: 2^-52 max|x| / (scale * domain size); round-off in
  /// the geometry is of this order.
  double coordinateResolution = 0.0;
};
ScaleRun runScaleCase(ScaleProblem problem, double scale, const Vec3& offset, int degree,
                      bool quick = false);

/// The condition estimate of the unscaled problem's stiffness (the mesh and boundary condition
/// of runScaleCase(), E = 1: the condition number does not depend on E). Scaling and
/// translation perturb the geometry by about ScaleRun::coordinateResolution relatively; the
/// solution then changes by up to about that times this condition number.
double scaleProblemCondition(ScaleProblem problem, int degree, bool quick = false);

}  // namespace polydg::bench
