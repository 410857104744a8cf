#include "cli/bench/problems.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mesh/primitives.h"
#include "physics/dg/face_quadrature.h"
#include "polydg/mesh/merge_elements.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"

namespace polydg::bench {

namespace {
/// The B1 fields on the unit cube.
ManufacturedProblem unitCubeB1Problem() {
  using std::cos;
  using std::sin;
  constexpr double pi = std::numbers::pi;
  ManufacturedProblem p;
  p.material.youngsModulus = 1.0;
  p.material.poissonRatio = 0.3;
  p.displacement = [](const Vec3& x) -> Vec3 {
    const double X = x.x(), Y = x.y(), Z = x.z();
    return {0.01 * sin(pi * Y) * sin(pi * Z) + 0.02 * X * X,
            0.01 * sin(pi * X) * sin(pi * Z) - 0.01 * Y * Z,
            0.01 * sin(pi * X) * sin(pi * Y) + 0.015 * X * Y * Z};
  };
  p.gradient = [](const Vec3& x) -> Eigen::Matrix3d {
    const double X = x.x(), Y = x.y(), Z = x.z();
    Eigen::Matrix3d g;
    g << 0.04 * X, 0.01 * pi * cos(pi * Y) * sin(pi * Z), 0.01 * pi * sin(pi * Y) * cos(pi * Z),
        0.01 * pi * cos(pi * X) * sin(pi * Z), -0.01 * Z,
        0.01 * pi * sin(pi * X) * cos(pi * Z) - 0.01 * Y,
        0.01 * pi * cos(pi * X) * sin(pi * Y) + 0.015 * Y * Z,
        0.01 * pi * sin(pi * X) * cos(pi * Y) + 0.015 * X * Z, 0.015 * X * Y;
    return g;
  };
  p.bodyForce = [](const Vec3& x) -> Vec3 {
    const double X = x.x(), Y = x.y(), Z = x.z();
    return {pi * pi * sin(pi * Y) * sin(pi * Z) / 130 - 3 * Y / 208 - 7.0 / 130,
            pi * pi * sin(pi * X) * sin(pi * Z) / 130 - 3 * X / 208,
            pi * pi * sin(pi * X) * sin(pi * Y) / 130 + 1.0 / 104};
  };
  return p;
}
}  // namespace

ManufacturedProblem benchmarkB1Problem(const DomainTransform& t) {
  ManufacturedProblem unit = unitCubeB1Problem();
  if (t.scale == 1.0 && t.offset.isZero()) return unit;
  const double s = t.scale;
  const Vec3 o = t.offset;
  ManufacturedProblem p;
  p.material = unit.material;
  p.displacement = [u = unit.displacement, s, o](const Vec3& x) -> Vec3 {
    return s * u((x - o) / s);
  };
  p.gradient = [g = unit.gradient, s, o](const Vec3& x) -> Eigen::Matrix3d {
    return g((x - o) / s);
  };
  p.bodyForce = [f = unit.bodyForce, s, o](const Vec3& x) -> Vec3 { return f((x - o) / s) / s; };
  return p;
}

ManufacturedProblem benchmarkB12Problem(double width) {
  ManufacturedProblem p;
  p.material.youngsModulus = 1.0;
  p.material.poissonRatio = 0.3;
  const Vec3 c(0.5, 0.5, 0.5);
  const double a = 0.01, w2 = width * width;
  auto g = [c, w2](const Vec3& x) { return std::exp(-(x - c).squaredNorm() / (2.0 * w2)); };
  p.displacement = [a, g](const Vec3& x) -> Vec3 { return a * g(x) * Vec3::Ones(); };
  p.gradient = [a, g, c, w2](const Vec3& x) -> Eigen::Matrix3d {
    const Vec3 dg = -(x - c) / w2 * g(x);
    return a * Vec3::Ones() * dg.transpose();
  };
  // div sigma(u)_i = a (mu Lap g + (mu + lambda) d_i sum_k d_k g), with the Hessian of g
  // (r r^T / w^4 - I / w^2) g.
  const double mu = p.material.mu(), lambda = p.material.lambda();
  p.bodyForce = [a, g, c, w2, mu, lambda](const Vec3& x) -> Vec3 {
    const Vec3 r = x - c;
    const Eigen::Matrix3d hessian =
        (r * r.transpose() / (w2 * w2) - Eigen::Matrix3d::Identity() / w2) * g(x);
    return -a * (mu * hessian.trace() * Vec3::Ones() + (mu + lambda) * hessian * Vec3::Ones());
  };
  return p;
}

LoadCase benchmarkB1Loads(const ManufacturedProblem& problem) {
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::allBoundary(), problem.displacement});
  loads.bodyForce = problem.bodyForce;
  return loads;
}

int benchmarkErrorQuadratureDegree(int degree) { return std::max(degree + 4, 2 * degree + 2); }

namespace {
BenchmarkRun makeRun(const StaticOptions& options, int n, const StaticReport& report) {
  BenchmarkRun run;
  run.method = options.discretization.method;
  run.degree = options.discretization.basis.degree;
  run.n = n;
  run.report = report;
  const double dofs = static_cast<double>(report.dofs);
  run.sparsity = dofs > 0 ? static_cast<double>(report.nonzeros) / (dofs * dofs) : 0.0;
  return run;
}
}  // namespace

namespace {
PolyMesh unitCubeB1Mesh(BenchmarkMesh kind, int n) {
  const Box3 cube(Vec3::Zero(), Vec3::Ones());
  if (kind == BenchmarkMesh::Hex) return hexGridMesh(n, n, n, cube);
  Grid grid;
  grid.cellSize = 1.0 / n;
  grid.cells = {n + 1, n + 1, n + 1};
  grid.centre = Vec3(0.5, 0.5, 0.5) + grid.cellSize * Vec3(0.37, 0.29, 0.23);
  const PolyMesh sliced = sliceSurface(boxSurface(cube), grid);
  return mergeSlivers(sliced, 0.01 * grid.cellVolume());
}
}  // namespace

PolyMesh benchmarkB1Mesh(BenchmarkMesh kind, int n, const DomainTransform& transform) {
  PolyMesh mesh = unitCubeB1Mesh(kind, n);
  if (transform.scale != 1.0 || !transform.offset.isZero())
    polydg::transform(mesh, transform.scale, transform.offset);
  return mesh;
}

BenchmarkRun runBenchmarkB1(int n, const StaticOptions& options, BenchmarkMesh kind,
                            const DomainTransform& transform) {
  const ManufacturedProblem problem = benchmarkB1Problem(transform);
  const PolyMesh mesh = benchmarkB1Mesh(kind, n, transform);
  const StaticSolution s = solveStatic(mesh, problem.material, benchmarkB1Loads(problem), options);
  BenchmarkRun run = makeRun(options, n, s.report);
  run.mesh = kind;
  const ErrorNorms e =
      errorNorms(mesh, *s.basis, s.coefficients, problem.displacement, problem.gradient,
                 benchmarkErrorQuadratureDegree(s.basis->degree()));
  run.l2Error = e.l2;
  run.h1Error = e.h1;
  run.l2Norm = e.l2Exact;
  return run;
}

PolyMesh benchmarkB2Mesh() { return hexGridMesh(10, 10, 10, Box3(Vec3::Zero(), Vec3::Ones())); }

Material benchmarkB2Material() {
  Material material;
  material.youngsModulus = 1000.0;
  material.poissonRatio = 0.3;
  material.density = 1.0;
  return material;
}

LoadCase benchmarkB2Loads() {
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::inPlane(0, 0.0), {}});
  loads.gravity = Vec3(0, 0, -1);
  return loads;
}

BenchmarkRun runBenchmarkB2(const StaticOptions& options) {
  const PolyMesh mesh = benchmarkB2Mesh();
  const StaticSolution s = solveStatic(mesh, benchmarkB2Material(), benchmarkB2Loads(), options);
  return makeRun(options, 10, s.report);
}

double meanBoundaryDisplacement(const PolyMesh& mesh, const DgBasis& basis,
                                const Eigen::VectorXd& coefficients, const FaceSelector& where,
                                int axis) {
  const double diagonal = meshBounds(mesh).diagonal().norm();
  double area = 0.0, integral = 0.0;
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const ElementId e(i);
    for (const FaceUse& use : mesh.element(e).faces) {
      const Face& face = mesh.face(use.face);
      if (face.front.valid() && face.back.valid()) continue;
      if (!selects(where, mesh, use.face, diagonal)) continue;
      for (const QuadraturePoint& q : faceQuadrature(mesh, use.face, basis.degree())) {
        area += q.weight;
        integral += q.weight * displacementAt(basis, coefficients, e, q.point)[axis];
      }
    }
  }
  return area > 0.0 ? integral / area : 0.0;
}

double cantileverReference(double poissonRatio) {
  const double e = 1000.0, length = 10.0, inertia = 1.0 / 12.0, areaSection = 1.0, load = 1.0;
  const double shear = e / (2.0 * (1.0 + poissonRatio));
  return load * std::pow(length, 3) / (3.0 * e * inertia) +
         load * length / (5.0 / 6.0 * shear * areaSection);
}

CantileverResult runBenchmarkB3(const CantileverSetup& setup, const StaticOptions& options,
                                const DomainTransform& t) {
  const Box3 beam(t.offset, t.offset + t.scale * Vec3(10.0, 1.0, 1.0));
  const PolyMesh mesh = hexGridMesh(setup.nx, setup.ny, setup.nz, beam);
  Material material;
  material.youngsModulus = 1000.0;
  material.poissonRatio = setup.poissonRatio;
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::inPlane(0, beam.min().x()), {}});
  loads.tractions.push_back({FaceSelector::inPlane(0, beam.max().x()), Vec3(0, 0, -1)});
  const StaticSolution s = solveStatic(mesh, material, loads, options);
  CantileverResult r;
  r.tipDeflection = -meanBoundaryDisplacement(mesh, *s.basis, s.coefficients,
                                              FaceSelector::inPlane(0, beam.max().x()), 2);
  r.report = s.report;
  return r;
}

}  // namespace polydg::bench
