// The error estimator of physics/solvers/error_estimator.h (local Neumann problems with the DG
// flux): it vanishes where the IP solution is exact (polynomial solutions of degree <= p, on
// hexahedra and sliced polyhedra, with Dirichlet and traction faces); its effectivity (estimate /
// true DG energy error) lies in the specification's [0.3, 3] for p = 1-3 on B12, on a wider bump
// near the bump and away from it, and, against a reference solve two levels finer, on a sliced
// L-prism (its re-entrant edge a stress singularity) and the sliced torus under gravity; it
// falls at the error's rate and is largest where the bump is; DgBasis::hessians(); the markings.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/bench/problems.h"
#include "cli/bench/reference_error.h"
#include "mesh/primitives.h"
#include "physics/solvers/error_estimator.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/model.h"

namespace polydg {
namespace {

/// The solution must make the estimate vanish to this, relative to the energy of u.
constexpr double kExactTolerance = 1e-8;
/// The specification's window for the effectivity, estimate / true DG energy error.
constexpr double kLeastEffectivity = 0.3;
constexpr double kLargestEffectivity = 3.0;

void expectEffectivityInWindow(double estimate, double error, const std::string& what) {
  ASSERT_GT(error, 0.0) << what;
  const double effectivity = estimate / error;
  std::printf("%s: estimate %.4e, error %.4e, effectivity %.3f\n", what.c_str(), estimate, error,
              effectivity);
  EXPECT_GE(effectivity, kLeastEffectivity) << what;
  EXPECT_LE(effectivity, kLargestEffectivity) << what;
}

/// Largest difference between the rates of the estimate and of the error from n = 4 to 8.
constexpr double kRateTolerance = 0.5;

Material unitMaterial() {
  Material m;
  m.youngsModulus = 1.0;
  m.poissonRatio = 0.3;
  return m;
}

/// u_d(x) = b_d + A(d, :) x + x^T H_d x / 2 and its body force f = -div sigma(u) (constant).
struct QuadraticField {
  Vec3 b = Vec3::Zero();
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  std::array<Eigen::Matrix3d, 3> h{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(),
                                   Eigen::Matrix3d::Zero()};

  Vec3 value(const Vec3& x) const {
    Vec3 u = b + a * x;
    for (int d = 0; d < 3; ++d) u[d] += 0.5 * x.dot(h[d] * x);
    return u;
  }
  Eigen::Matrix3d gradient(const Vec3& x) const {
    Eigen::Matrix3d g = a;
    for (int d = 0; d < 3; ++d) g.row(d) += (h[d] * x).transpose();
    return g;
  }
  Vec3 bodyForce(const Material& m) const {
    Vec3 f;
    for (int d = 0; d < 3; ++d) {
      double gradDiv = 0.0;
      for (int k = 0; k < 3; ++k) gradDiv += h[k](k, d);
      f[d] = -(m.mu() * h[d].trace() + (m.mu() + m.lambda()) * gradDiv);
    }
    return f;
  }
};

QuadraticField sampleQuadratic() {
  QuadraticField q;
  q.b = Vec3(0.01, -0.02, 0.03);
  q.a << 0.010, -0.020, 0.005, 0.015, 0.030, -0.010, -0.005, 0.020, 0.025;
  q.h[0] << 0.04, 0.01, 0.00, 0.01, 0.00, 0.02, 0.00, 0.02, -0.03;
  q.h[1] << 0.00, 0.00, 0.01, 0.00, 0.02, -0.01, 0.01, -0.01, 0.00;
  q.h[2] << -0.02, 0.015, 0.00, 0.015, 0.01, 0.00, 0.00, 0.00, 0.03;
  return q;
}

/// The estimate of a solve of `loads` and its true error against the exact solution.
struct EstimatedSolve {
  ErrorEstimate estimate;
  EnergyError error;
  std::size_t dofs = 0;
};

EstimatedSolve solveAndEstimate(const PolyMesh& mesh, const Material& material,
                                const LoadCase& loads, const VectorField& exact,
                                const GradientField& exactGradient, int degree,
                                int quadratureDegree) {
  StaticOptions options;
  options.discretization.basis.degree = degree;
  options.discretization.quadratureDegree = quadratureDegree;
  StaticSolver solver(mesh, material, options);
  solver.assemble(loads);
  const Eigen::VectorXd u = solver.solve();
  EstimatorOptions estimator;
  estimator.quadratureDegree = quadratureDegree;
  EstimatedSolve out;
  out.estimate = estimateError(mesh, solver, loads, u, estimator);
  out.error = energyError(mesh, solver.basis(), solver.moments(), solver.roles(), solver.form(), u,
                          exact, exactGradient, quadratureDegree);
  out.dofs = solver.report().dofs;
  return out;
}

/// The energy norm of u on the unit cube (the scale of "vanishes").
double energyOf(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                const FaceRoles& roles, const FormCoefficients& form,
                const GradientField& gradient) {
  const Eigen::VectorXd zero =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.numElements() * 3 * basis.size()));
  const VectorField none = [](const Vec3&) -> Vec3 { return Vec3::Zero(); };
  return energyError(mesh, basis, moments, roles, form, zero, none, gradient, 6).broken;
}

void expectVanishes(const PolyMesh& mesh, const LoadCase& loads, const QuadraticField& field,
                    int degree) {
  const Material material = unitMaterial();
  StaticOptions options;
  options.discretization.basis.degree = degree;
  StaticSolver solver(mesh, material, options);
  solver.assemble(loads);
  const Eigen::VectorXd u = solver.solve();
  const ErrorEstimate estimate = estimateError(mesh, solver, loads, u);
  const GradientField gradient = [&](const Vec3& x) { return field.gradient(x); };
  const double scale =
      energyOf(mesh, solver.basis(), solver.moments(), solver.roles(), solver.form(), gradient);
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(estimate.total, kExactTolerance * scale)
      << "local " << estimate.local << " jump " << estimate.displacementJump << " dirichlet "
      << estimate.dirichlet;
  ASSERT_EQ(estimate.indicators.size(), mesh.numElements());
  double sum = 0.0;
  for (double eta2 : estimate.indicators) {
    EXPECT_GE(eta2, 0.0);
    sum += eta2;
  }
  EXPECT_NEAR(std::sqrt(sum), estimate.total, 1e-12 * scale);
}

// DgBasis::hessians(), which the element residual uses (div sigma(u_h)), against central
// differences of DgBasis::gradients() (exact for p <= 2: the gradients are at most quadratic).
TEST(DgBasisHessians, MatchDifferencesOfGradients) {
  const PolyMesh mesh = bench::benchmarkB1Mesh(bench::BenchmarkMesh::Sliced, 2);
  MomentCache moments(mesh, 6);
  moments.update();
  for (int degree : {1, 2, 3}) {
    const DgBasis basis(mesh, moments, {degree, BasisKind::Orthonormal});
    const int n = basis.size();
    std::vector<double> hess(9 * n), plus(3 * n), minus(3 * n);
    for (std::size_t i = 0; i < mesh.numElements(); ++i) {
      const ElementId e(i);
      const Vec3 x = basis.centre(e) + 0.3 * basis.scale(e) * Vec3(0.5, -0.7, 0.2);
      basis.hessians(e, x, hess);
      const double step = 1e-3 * basis.scale(e);
      for (int l = 0; l < 3; ++l) {
        const Vec3 dx = step * Vec3::Unit(l);
        basis.gradients(e, x + dx, plus);
        basis.gradients(e, x - dx, minus);
        for (int k = 0; k < 3; ++k)
          for (int f = 0; f < n; ++f) {
            const double difference = (plus[k * n + f] - minus[k * n + f]) / (2.0 * step);
            const double scale =
                1.0 / (basis.scale(e) * basis.scale(e) * std::sqrt(moments.volume(e)));
            ASSERT_NEAR(hess[(3 * k + l) * n + f], difference, 1e-6 * scale)
                << "p = " << degree << ", element " << i << ", function " << f;
          }
      }
    }
  }
}

/// The quadratic field held on the whole boundary, loaded by its constant body force.
LoadCase heldQuadraticLoads(const QuadraticField& field) {
  LoadCase loads;
  loads.dirichlet.push_back(
      {FaceSelector::allBoundary(), [field](const Vec3& x) { return field.value(x); }});
  const Vec3 f = field.bodyForce(unitMaterial());
  loads.bodyForce = [f](const Vec3&) { return f; };
  return loads;
}

TEST(ErrorEstimator, VanishesForAQuadraticSolutionOnHexahedra) {
  const QuadraticField field = sampleQuadratic();
  const PolyMesh mesh = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  expectVanishes(mesh, heldQuadraticLoads(field), field, 2);
}

TEST(ErrorEstimator, VanishesForAQuadraticSolutionOnSlicedPolyhedra) {
  const QuadraticField field = sampleQuadratic();
  const PolyMesh mesh = bench::benchmarkB1Mesh(bench::BenchmarkMesh::Sliced, 3);
  expectVanishes(mesh, heldQuadraticLoads(field), field, 2);
}

// An affine displacement held on x = 0 and loaded by its own (constant) tractions on the other
// five sides, and by gravity balanced by an equal body force: the Neumann terms vanish too.
TEST(ErrorEstimator, VanishesForAnAffineSolutionWithTractionsAndGravity) {
  QuadraticField field = sampleQuadratic();
  field.h = {Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  const Material material = unitMaterial();
  const Eigen::Matrix3d eps = 0.5 * (field.a + field.a.transpose());
  const Eigen::Matrix3d sigma =
      2.0 * material.mu() * eps + material.lambda() * eps.trace() * Eigen::Matrix3d::Identity();
  const PolyMesh mesh = hexGridMesh(3, 2, 2, Box3(Vec3::Zero(), Vec3(1.5, 1.0, 1.0)));
  LoadCase loads;
  loads.dirichlet.push_back(
      {FaceSelector::inPlane(0, 0.0), [field](const Vec3& x) { return field.value(x); }});
  const std::array<std::pair<int, double>, 5> sides{
      {{0, 1.5}, {1, 0.0}, {1, 1.0}, {2, 0.0}, {2, 1.0}}};
  for (const auto& [axis, value] : sides) {
    Vec3 n = Vec3::Zero();
    n[axis] = value > 0.0 ? 1.0 : -1.0;
    loads.tractions.push_back({FaceSelector::inPlane(axis, value), sigma * n});
  }
  loads.gravity = Vec3(0.0, 0.0, -0.1);
  loads.bodyForce = [](const Vec3&) { return Vec3(0.0, 0.0, 0.1); };
  for (int degree : {1, 2}) {
    SCOPED_TRACE("p = " + std::to_string(degree));
    expectVanishes(mesh, loads, field, degree);
  }
}

/// B12's field (cli/bench/problems.h) with bump width `width`, centred at c.
const Vec3 kBumpCentre(0.5, 0.5, 0.5);

EstimatedSolve solveBump(double width, int n, int quadratureDegree) {
  const bench::ManufacturedProblem bump = bench::benchmarkB12Problem(width);
  const PolyMesh mesh = hexGridMesh(n, n, n, Box3(Vec3::Zero(), Vec3::Ones()));
  return solveAndEstimate(mesh, bump.material, bench::benchmarkB1Loads(bump), bump.displacement,
                          bump.gradient, 2, quadratureDegree);
}

// B12's field with a bump wide enough (w = 0.15) to be resolved from n = 4 on, p = 2.
// Measured 2026-12-05 (quadrature degree 8): effectivity 1.59 (n = 4), 1.52 (n = 8); near the
// bump (elements within 2 w of its centre) 1.35 and away from it 1.88 at n = 4. The residual
// estimator before it (unit constants) gave 6.0 and 4.9.
constexpr double kBumpWidth = 0.15;
constexpr int kBumpQuadrature = 8;

TEST(ErrorEstimator, IsWithinThreeOfTheErrorOnAGaussianBumpNearItAndAwayFromIt) {
  for (int n : {4, 8}) {
    SCOPED_TRACE("n = " + std::to_string(n));
    const EstimatedSolve s = solveBump(kBumpWidth, n, kBumpQuadrature);
    expectEffectivityInWindow(s.estimate.total, s.error.total(), "n = " + std::to_string(n));
    // The largest indicator sits on one of the 8 elements around the bump's centre (a grid
    // vertex); the elements within 2 w of it, and the rest, each hold an estimate within the
    // window of the error they hold.
    const PolyMesh mesh = hexGridMesh(n, n, n, Box3(Vec3::Zero(), Vec3::Ones()));
    const auto& eta2 = s.estimate.indicators.raw();
    const std::size_t largest =
        static_cast<std::size_t>(std::max_element(eta2.begin(), eta2.end()) - eta2.begin());
    const double h = 1.0 / n;
    EXPECT_LE((elementBounds(mesh, ElementId(largest)).center() - kBumpCentre).norm(),
              0.5 * std::sqrt(3.0) * h * (1.0 + 1e-9));
    double estimate[2] = {0.0, 0.0}, error[2] = {0.0, 0.0};
    for (std::size_t i = 0; i < eta2.size(); ++i) {
      const bool near =
          (elementBounds(mesh, ElementId(i)).center() - kBumpCentre).norm() <= 2.0 * kBumpWidth;
      estimate[near] += eta2[i];
      error[near] += s.error.elements[ElementId(i)];
    }
    expectEffectivityInWindow(std::sqrt(estimate[1]), std::sqrt(error[1]), "  near the bump");
    expectEffectivityInWindow(std::sqrt(estimate[0]), std::sqrt(error[0]), "  away from it");
  }
}

TEST(ErrorEstimator, IsWithinThreeOfTheErrorOnB12ForDegreesOneToThree) {
  // B12 itself (w = 0.05), IP, n = 4 and 8. Measured 2026-12-05: p = 1: 0.89, 0.95; p = 2:
  // 0.99, 1.05 (1.32 at n = 16); p = 3: 1.01, 1.05. The residual estimator gave 8.3 and 7.1
  // at p = 2.
  const bench::ManufacturedProblem bump = bench::benchmarkB12Problem(0.05);
  for (int p : {1, 2, 3})
    for (int n : {4, 8}) {
      const PolyMesh mesh = hexGridMesh(n, n, n, Box3(Vec3::Zero(), Vec3::Ones()));
      const EstimatedSolve s = solveAndEstimate(mesh, bump.material, bench::benchmarkB1Loads(bump),
                                                bump.displacement, bump.gradient, p, 2 * p + 6);
      expectEffectivityInWindow(s.estimate.total, s.error.total(),
                                "B12 p = " + std::to_string(p) + ", n = " + std::to_string(n));
    }
}

TEST(ErrorEstimator, AReferenceTwoLevelsFinerMeasuresTheErrorOfAKnownSolution) {
  // The wider bump on 4^3 hexahedra, p = 1: the error against the reference (the same degree on
  // 16^3 cells, error ~h/4) is the true error to within the reference's own, a quarter of it
  // (triangle inequality, energy error ~ h). Measured 2026-12-05: 1.03e-2 against 1.21e-2.
  const SolveOptions o = bench::manufacturedSolveOptions(bench::benchmarkB12Problem(kBumpWidth), 1);
  const PolyMesh mesh = hexGridMesh(4, 4, 4, Box3(Vec3::Zero(), Vec3::Ones()));
  Model exact(mesh);
  const SolveReport r = exact.solve(o);
  const double error = r.energyError->total();
  const bench::ReferenceCheck c = bench::checkAgainstReference(mesh, o, 2, 1);
  std::printf("error %.4e, against the reference %.4e\n", error, c.error);
  EXPECT_EQ(c.referenceElements, 64u * 64u);
  EXPECT_NEAR(c.error, error, 0.25 * error);
}

TEST(ErrorEstimator, IsWithinThreeOfAReferenceErrorOnAnLPrismAndTheTorus) {
  // No closed form: the error against a solve of the same degree on the mesh split twice into
  // octants. The L-prism ([0,2] x [0,1] u [0,1] x [0,2], 1.5 high) sliced at 5 cells puts its
  // re-entrant edge inside cut elements; held on y = 2 and pulled along y on x = 2, the stress
  // is singular there. The torus sliced at 6 cells (cut polyhedra only) hangs from its x <= -1
  // part under gravity. Measured 2026-12-05: L-prism 1.09 (p = 1), 0.92 (p = 2); torus 1.33.
  // The problems of the adaptivity suite (bench::referenceProblems()): the L-prism at p = 1
  // and 2, the torus at p = 1.
  for (const bench::ReferenceProblem& problem : bench::referenceProblems()) {
    MeshOptions meshing;
    meshing.cells = problem.cells;
    MeshReport meshed;
    const Model model = Model::fromSurface(
        readSurface(std::string(POLYDG_TESTDATA_DIR) + "/" + problem.file), meshing, meshed);
    for (int p = 1; p <= (problem.name == "L-prism" ? 2 : 1); ++p) {
      SolveOptions options = problem.options;
      options.discretization.basis.degree = p;
      const bench::ReferenceCheck c = bench::checkAgainstReference(model.mesh(), options, 2, p);
      expectEffectivityInWindow(c.estimate, c.error, problem.name + " p = " + std::to_string(p));
    }
  }
}

TEST(ErrorEstimator, FallsAtTheRateOfTheErrorUnderUniformRefinement) {
  const EstimatedSolve coarse = solveBump(kBumpWidth, 4, kBumpQuadrature);
  const EstimatedSolve fine = solveBump(kBumpWidth, 8, kBumpQuadrature);
  const double estimateRate = std::log2(coarse.estimate.total / fine.estimate.total);
  const double errorRate = std::log2(coarse.error.total() / fine.error.total());
  std::printf("rates from n = 4 to 8: estimate %.3f, error %.3f\n", estimateRate, errorRate);
  // Energy error ~ h^p: 2 for p = 2 (1.63 from 4 to 8, 1.93 from 8 to 16; the estimate 1.95,
  // 1.95).
  EXPECT_GT(estimateRate, 1.5);
  EXPECT_NEAR(estimateRate, errorRate, kRateTolerance);
}

TEST(ErrorEstimator, TheJumpTermsAreThePenaltyTimesTheSquaredJumpOnEachFace) {
  // u_h = c on the centre element of a 3^3 grid of the unit cube and 0 elsewhere, held at 0 on
  // the boundary: the centre element's 6 faces (area 1/9) jump by c, no other face jumps. Both
  // the estimate's jump terms and the true error's jump part against u = 0 are sum over those
  // faces of mu eta_F |F| |c|^2.
  const PolyMesh mesh = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  const Material material = unitMaterial();
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::allBoundary(), nullptr});
  StaticOptions options;
  options.discretization.basis.degree = 1;
  StaticSolver solver(mesh, material, options);
  solver.assemble(loads);
  const DgBasis& basis = solver.basis();
  const int n = basis.size();
  std::size_t centre = 0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    if ((solver.moments().centroid(ElementId(e)) - Vec3::Constant(0.5)).norm() < 1e-12) centre = e;
  const Vec3 c(0.3, -0.2, 0.1);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.numElements() * 3 * n));
  const Eigen::Index base = static_cast<Eigen::Index>(centre * 3 * n);
  for (int d = 0; d < 3; ++d) u[base + d * n] = 1.0;  // the constant function, value phi_0
  const Vec3 phi0 = displacementAt(basis, u, ElementId(centre), Vec3::Constant(0.5));
  for (int d = 0; d < 3; ++d) u[base + d * n] = c[d] / phi0[d];
  double expected = 0.0;
  for (const FaceUse& use : mesh.element(ElementId(centre)).faces) {
    const Face& face = mesh.face(use.face);
    expected += material.mu() *
                facePenalty(solver.form(), solver.moments(), use.face, face.front, face.back) *
                (1.0 / 9.0) * c.squaredNorm();
  }
  ASSERT_GT(expected, 0.0);
  const ErrorEstimate estimate = estimateError(mesh, solver, loads, u);
  EXPECT_NEAR(estimate.displacementJump, expected, 1e-12 * expected);
  EXPECT_EQ(estimate.dirichlet, 0.0);
  const VectorField zero = [](const Vec3&) -> Vec3 { return Vec3::Zero(); };
  const GradientField still = [](const Vec3&) -> Eigen::Matrix3d {
    return Eigen::Matrix3d::Zero();
  };
  const EnergyError error =
      energyError(mesh, basis, solver.moments(), solver.roles(), solver.form(), u, zero, still, 4);
  EXPECT_NEAR(error.jump * error.jump, expected, 1e-12 * expected);
  EXPECT_NEAR(error.broken, 0.0, 1e-12);
  // Against u = a (constant) the boundary faces, where u_h = 0, add mu eta_F |F| |a|^2 each.
  const Vec3 a(-0.1, 0.05, 0.2);
  double boundary = 0.0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    if (!mesh.face(FaceId(f)).back.valid())
      boundary += material.mu() *
                  facePenalty(solver.form(), solver.moments(), FaceId(f),
                              mesh.face(FaceId(f)).front, ElementId()) *
                  (1.0 / 9.0) * a.squaredNorm();
  const VectorField shifted = [a](const Vec3&) -> Vec3 { return a; };
  const EnergyError against = energyError(mesh, basis, solver.moments(), solver.roles(),
                                          solver.form(), u, shifted, still, 4);
  EXPECT_NEAR(against.jump * against.jump, expected + boundary, 1e-12 * (expected + boundary));
}

TEST(ErrorEstimator, BulkMarkingTakesTheFewestLargestIndicators) {
  ElementData<double> indicators;
  for (double v : {1.0, 4.0, 0.0, 3.0, 2.0, 3.0}) indicators.push_back(v);
  // Total 13: theta = 0.5 needs 6.5: 4 + 3 (element 3 before 5, tied).
  EXPECT_EQ(markBulk(indicators, 0.5), (std::vector<ElementId>{ElementId(1), ElementId(3)}));
  // theta = 1: every element with a positive indicator, largest first.
  EXPECT_EQ(markBulk(indicators, 1.0),
            (std::vector<ElementId>{ElementId(1), ElementId(3), ElementId(5), ElementId(4),
                                    ElementId(0)}));
  EXPECT_TRUE(markBulk(ElementData<double>(3, 0.0), 0.5).empty());
  EXPECT_THROW(markBulk(indicators, 0.0), std::invalid_argument);
  EXPECT_THROW(markBulk(indicators, 1.5), std::invalid_argument);
}

TEST(ErrorEstimator, DofBudgetKeepsTheLargestThatFit) {
  const std::vector<ElementId> marked{ElementId(7), ElementId(2), ElementId(5)};
  // 100 DOFs, 30 more per refinement, budget 170: room for two.
  EXPECT_EQ(limitToDofBudget(marked, 100, 30, 170),
            (std::vector<ElementId>{ElementId(7), ElementId(2)}));
  EXPECT_EQ(limitToDofBudget(marked, 100, 30, 1000), marked);
  EXPECT_TRUE(limitToDofBudget(marked, 100, 30, 100).empty());
  EXPECT_TRUE(limitToDofBudget(marked, 200, 30, 100).empty());
}

}  // namespace
}  // namespace polydg
