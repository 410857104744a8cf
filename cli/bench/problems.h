// The benchmark problems B1 (manufactured solution on the unit cube), B2 (the thesis's Table 4.1
// setup) and B3 (cantilever under an end load, and locking) of shared/BENCHMARKS.md: their
// meshes, materials and loads, and one run of each, for `polydg bench` and the tests.
#pragma once

#include "physics/solvers/static_solver.h"
#include "polydg/physics/dg/post_process.h"

namespace polydg::bench {

/// A similarity map x -> scale * x + offset of a benchmark's domain (B4's scale and position
/// test). Lengths and displacements scale by `scale`; strains and stresses do not change.
struct DomainTransform {
  double scale = 1.0;
  Vec3 offset = Vec3::Zero();
};

/// B1: E = 1, nu = 0.3 on [0,1]^3, u_exact of BENCHMARKS.md, f = -div sigma(u_exact),
/// u = u_exact weakly on the whole boundary. Under `transform` T the domain is T([0,1]^3) and
/// the exact solution scale * u(T^-1 x) (same gradient, body force divided by scale), so that
/// relative errors are unchanged in exact arithmetic.
struct ManufacturedProblem {
  Material material;
  VectorField displacement;
  GradientField gradient;
  VectorField bodyForce;
};
ManufacturedProblem benchmarkB1Problem(const DomainTransform& transform = {});

/// B12: E = 1, nu = 0.3 on [0,1]^3, u = 0.01 (1, 1, 1) g(x), g = exp(-|x - c|^2 / (2 w^2)),
/// c = (0.5, 0.5, 0.5), w = `width` (0.05 in BENCHMARKS.md), f = -div sigma(u).
ManufacturedProblem benchmarkB12Problem(double width = 0.05);

/// The load case of B1 (Dirichlet on every boundary face, body force by quadrature).
LoadCase benchmarkB1Loads(const ManufacturedProblem& problem);

/// The meshes of B1: the n x n x n hex grid, or the cube's surface sliced by a grid of the same
/// cell size shifted off the cube's faces (cells = n + 1 per axis, offset (0.37, 0.29, 0.23) h),
/// so that every boundary element is a cut polyhedron; slivers below 1% of a cell are merged.
enum class BenchmarkMesh { Hex, Sliced };
/// `transform` maps the mesh's vertices after it is built.
PolyMesh benchmarkB1Mesh(BenchmarkMesh kind, int n, const DomainTransform& transform = {});

/// One run of a benchmark, with the keys of the bench reports.
struct BenchmarkRun {
  Method method = Method::IP;
  int degree = 1;
  BenchmarkMesh mesh = BenchmarkMesh::Hex;
  int n = 0;  ///< grid cells per unit length
  StaticReport report;
  double l2Error = 0.0;   ///< B1 only
  double h1Error = 0.0;   ///< B1 only (broken H1 seminorm)
  double l2Norm = 0.0;    ///< B1 only: L2 norm of the exact solution
  double sparsity = 0.0;  ///< nonzeros / dofs^2
};

/// Quadrature degree of the B1 error norms: max(p + 4, 2p + 2).
int benchmarkErrorQuadratureDegree(int degree);

/// B1 on benchmarkB1Mesh(kind, n, transform).
BenchmarkRun runBenchmarkB1(int n, const StaticOptions& options,
                            BenchmarkMesh kind = BenchmarkMesh::Hex,
                            const DomainTransform& transform = {});

/// B2: 10 x 10 x 10 unit cube, clamped on x = 0, gravity (0, 0, -1), density 1, E = 1000,
/// nu = 0.3. Its mesh, material and loads:
PolyMesh benchmarkB2Mesh();
Material benchmarkB2Material();
LoadCase benchmarkB2Loads();
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
/// With `transform` T the beam is T([0,10] x [0,1] x [0,1]), clamped and loaded on the images of
/// x = 0 and x = 10 (the same traction, so the deflection scales with T's scale).
CantileverResult runBenchmarkB3(const CantileverSetup& setup, const StaticOptions& options,
                                const DomainTransform& transform = {});

/// Reference tip deflection of B3: P L^3 / (3 E I) + P L / (k G A) with k = 5/6 (Euler-
/// Bernoulli plus Timoshenko shear): 4.031 for nu = 0.3, 4.036 for nu = 0.499.
double cantileverReference(double poissonRatio);

/// Mean of component `axis` of u_h over the boundary faces chosen by `where` (face quadrature
/// exact for the basis degree).
double meanBoundaryDisplacement(const PolyMesh& mesh, const DgBasis& basis,
                                const Eigen::VectorXd& coefficients, const FaceSelector& where,
                                int axis);

}  // namespace polydg::bench
