#include "polydg/physics/stability.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>

#include "polydg/mesh/merge_elements.h"
#include "polydg/mesh/primitives.h"

namespace polydg {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Relative accuracy of the Lanczos eigenvalues and the iteration limit.
constexpr double kLanczosTolerance = 1e-8;
constexpr int kLanczosIterations = 2000;

/// y = K^-1 x through a Cholesky factorization, as a Spectra operator.
class InverseOperator {
 public:
  using Scalar = double;
  InverseOperator(LinearSolver& solver, Eigen::Index n) : solver_(&solver), n_(n) {}
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  void perform_op(const double* x, double* y) const {
    LinearSolveReport report;
    Eigen::Map<Eigen::VectorXd>(y, n_) =
        solver_->solve(Eigen::Map<const Eigen::VectorXd>(x, n_), report);
    ++products;
  }
  mutable int products = 0;

 private:
  LinearSolver* solver_;
  Eigen::Index n_;
};

/// Counts the products of a sparse symmetric operator.
class CountingProduct : public Spectra::SparseSymMatProd<double> {
 public:
  using Spectra::SparseSymMatProd<double>::SparseSymMatProd;
  void perform_op(const double* x, double* y) const {
    Spectra::SparseSymMatProd<double>::perform_op(x, y);
    ++products;
  }
  mutable int products = 0;
};

/// The largest eigenvalue of a symmetric operator by Lanczos.
template <class Op>
double largestEigenvalue(Op& op) {
  const Eigen::Index n = op.rows();
  if (n == 1) {
    double x = 1.0, y = 0.0;
    op.perform_op(&x, &y);
    return y;
  }
  const Eigen::Index ncv = std::min<Eigen::Index>(n, 24);
  Spectra::SymEigsSolver<Op> eigs(op, 1, ncv);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, kLanczosIterations, kLanczosTolerance);
  if (eigs.info() != Spectra::CompInfo::Successful)
    throw std::runtime_error("conditionEstimate: Lanczos did not converge");
  return eigs.eigenvalues()[0];
}

}  // namespace

ConditionEstimate conditionEstimate(const SparseMatrix& matrix, int blockSize) {
  ConditionEstimate c;
  CountingProduct product(matrix);
  c.lambdaMax = largestEigenvalue(product);
  c.matrixProducts = product.products;
  SolverOptions options;
  options.kind = SolverKind::Cholesky;
  LinearSolver solver(options);
  if (!solver.compute(matrix, blockSize)) {
    c.cond = std::numeric_limits<double>::infinity();
    return c;
  }
  InverseOperator inverse(solver, matrix.rows());
  const double inverseMax = largestEigenvalue(inverse);
  c.matrixProducts += inverse.products;
  c.positiveDefinite = inverseMax > 0.0;
  c.lambdaMin = c.positiveDefinite ? 1.0 / inverseMax : 0.0;
  c.cond = c.positiveDefinite ? c.lambdaMax / c.lambdaMin : std::numeric_limits<double>::infinity();
  return c;
}

SparseMatrix jacobiScaled(const SparseMatrix& matrix) {
  const Eigen::VectorXd d = matrix.diagonal();
  if (!(d.minCoeff() > 0.0))
    throw std::invalid_argument("jacobiScaled: the diagonal must be positive");
  const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
  return s.asDiagonal() * matrix * s.asDiagonal();
}

// --- meshes ---------------------------------------------------------------------------------

namespace {

using Key = std::array<double, 3>;
Key keyOf(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

/// An axis-aligned rectangle in the plane x_axis = value, spanning [lo, hi] in the coordinates
/// u = (axis + 1) % 3 and w = (axis + 2) % 3 (so e_u x e_w = e_axis).
struct Tile {
  int axis = 0;
  double value = 0.0;
  std::array<double, 2> lo{}, hi{};
};

/// The tile's boundary loop through every vertex lying on it, counter-clockwise about e_axis
/// (or about -e_axis if `flip`).
Loop tileLoop(const Tile& t, const std::map<Key, VertexId>& vertices, bool flip) {
  const int u = (t.axis + 1) % 3, w = (t.axis + 2) % 3;
  const double lu = t.hi[0] - t.lo[0], lw = t.hi[1] - t.lo[1];
  std::vector<std::pair<double, VertexId>> onBoundary;
  for (const auto& [p, id] : vertices) {
    if (p[t.axis] != t.value) continue;
    const double a = p[u], b = p[w];
    if (a < t.lo[0] || a > t.hi[0] || b < t.lo[1] || b > t.hi[1]) continue;
    // Perimeter parameter, starting at (lo, lo): bottom, right, top, left.
    double s;
    if (b == t.lo[1])
      s = a - t.lo[0];
    else if (a == t.hi[0])
      s = lu + (b - t.lo[1]);
    else if (b == t.hi[1])
      s = lu + lw + (t.hi[0] - a);
    else if (a == t.lo[0])
      s = 2 * lu + lw + (t.hi[1] - b);
    else
      continue;  // inside the tile: not on its boundary
    onBoundary.emplace_back(s, id);
  }
  std::sort(onBoundary.begin(), onBoundary.end());
  Loop loop;
  for (const auto& [s, id] : onBoundary) loop.push_back(id);
  if (flip) std::reverse(loop.begin(), loop.end());
  return loop;
}

/// The overlap of two rectangles given as [lo, hi] pairs; empty (false) if its area is zero.
bool overlap(const Tile& a, const std::array<double, 2>& lo, const std::array<double, 2>& hi,
             Tile& out) {
  out = a;
  for (int k = 0; k < 2; ++k) {
    out.lo[k] = std::max(a.lo[k], lo[k]);
    out.hi[k] = std::min(a.hi[k], hi[k]);
    if (!(out.lo[k] < out.hi[k])) return false;
  }
  return true;
}

}  // namespace

PolyMesh boxCellsMesh(const std::vector<Box3>& boxes) {
  PolyMesh mesh;
  std::map<Key, VertexId> vertices;
  for (const Box3& b : boxes)
    for (int c = 0; c < 8; ++c) {
      const Vec3 p = b.corner(static_cast<Box3::CornerType>(c));
      if (!vertices.count(keyOf(p))) vertices.emplace(keyOf(p), mesh.addVertex(p));
    }
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    std::vector<std::vector<Loop>> boundary;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int side = 0; side < 2; ++side) {  // 0: the min side (outward -e_axis), 1: max
        Tile whole;
        whole.axis = axis;
        whole.value = side ? boxes[i].max()[axis] : boxes[i].min()[axis];
        whole.lo = {boxes[i].min()[u], boxes[i].min()[w]};
        whole.hi = {boxes[i].max()[u], boxes[i].max()[w]};
        double covered = 0.0;
        std::vector<Tile> tiles;
        for (std::size_t j = 0; j < boxes.size(); ++j) {
          const double across = side ? boxes[j].min()[axis] : boxes[j].max()[axis];
          Tile t;
          if (j == i || across != whole.value ||
              !overlap(whole, {boxes[j].min()[u], boxes[j].min()[w]},
                       {boxes[j].max()[u], boxes[j].max()[w]}, t))
            continue;
          covered += (t.hi[0] - t.lo[0]) * (t.hi[1] - t.lo[1]);
          tiles.push_back(t);
        }
        const double area = (whole.hi[0] - whole.lo[0]) * (whole.hi[1] - whole.lo[1]);
        if (tiles.empty())
          tiles.push_back(whole);
        else if (std::abs(covered - area) > 1e-12 * area)
          throw std::invalid_argument("boxCellsMesh: a box side is only partly covered");
        for (const Tile& t : tiles) boundary.push_back({tileLoop(t, vertices, side == 0)});
      }
    }
    mesh.addElement(boundary, FaceOrigin::Box);
  }
  return mesh;
}

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

}  // namespace polydg
