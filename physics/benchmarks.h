// The benchmark problems of shared/BENCHMARKS.md as library functions, used by `polydg bench`
// and by the tests: B1 (manufactured solution on the unit cube), B2 (the thesis's Table 4.1
// setup) and B3 (cantilever under an end load, and locking).
#pragma once

#include <string>

#include "physics/post_process.h"
#include "physics/static_solver.h"

namespace polydg {

/// B1: E = 1, nu = 0.3 on [0,1]^3, u_exact of BENCHMARKS.md, f = -div sigma(u_exact),
/// u = u_exact weakly on the whole boundary.
struct ManufacturedProblem {
  Material material;
  VectorField displacement;
  GradientField gradient;
  VectorField bodyForce;
};
ManufacturedProblem benchmarkB1Problem();

/// The load case of B1 (Dirichlet on every boundary face, body force by quadrature).
LoadCase benchmarkB1Loads(const ManufacturedProblem& problem);

/// The meshes of B1: the n x n x n hex grid, or the cube's surface sliced by a grid of the same
/// cell size shifted off the cube's faces (cells = n + 1 per axis, offset (0.37, 0.29, 0.23) h),
/// so that every boundary element is a cut polyhedron; slivers below 1% of a cell are merged.
enum class BenchmarkMesh { Hex, Sliced };
PolyMesh benchmarkB1Mesh(BenchmarkMesh kind, int n);

/// One run of a benchmark, with the keys of the bench reports.
struct BenchmarkRun {
  Method method = Method::IP;
  int degree = 1;
  BenchmarkMesh mesh = BenchmarkMesh::Hex;
  int n = 0;                 ///< grid cells per unit length
  StaticReport report;
  double l2Error = 0.0;  ///< B1 only
  double h1Error = 0.0;  ///< B1 only (broken H1 seminorm)
  double sparsity = 0.0; ///< nonzeros / dofs^2
};

/// Quadrature degree of the B1 error norms: max(p + 4, 2p + 2).
int benchmarkErrorQuadratureDegree(int degree);

/// B1 on benchmarkB1Mesh(kind, n).
BenchmarkRun runBenchmarkB1(int n, const StaticOptions& options,
                            BenchmarkMesh kind = BenchmarkMesh::Hex);

/// B2: 10 x 10 x 10 unit cube, clamped on x = 0, gravity (0, 0, -1), density 1, E = 1000,
/// nu = 0.3.
BenchmarkRun runBenchmarkB2(const StaticOptions& options);

/// B3: beam [0,10] x [0,1] x [0,1] on an nx x ny x nz hex grid, E = 1000, clamped on x = 0,
/// traction (0, 0, -1) on x = 10 (total load 1).
struct CantileverSetup {
  int nx = 40, ny = 4, nz = 4;
  double poissonRatio = 0.3;
};
struct CantileverResult {
  double tipDeflection = 0.0;  ///< -(mean u_z over the face x = 10), by face quadrature
  StaticReport report;
};
CantileverResult runBenchmarkB3(const CantileverSetup& setup, const StaticOptions& options);

/// Reference tip deflection of B3: P L^3 / (3 E I) + P L / (k G A) with k = 5/6 (Euler-
/// Bernoulli plus Timoshenko shear): 4.031 for nu = 0.3, 4.036 for nu = 0.499.
double cantileverReference(double poissonRatio);

/// Mean of component `axis` of u_h over the boundary faces chosen by `where` (face quadrature
/// exact for the basis degree).
double meanBoundaryDisplacement(const PolyMesh& mesh, const DgBasis& basis,
                                const Eigen::VectorXd& coefficients, const FaceSelector& where,
                                int axis);

}  // namespace polydg
