#include "physics/validation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>

#include "mesh/validate.h"
#include "physics/post_process.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Largest component block solved densely.
constexpr Eigen::Index kDenseLimit = 1500;
/// Eigenvalues computed per component by subspace iteration (6 rigid motions and a margin).
constexpr int kSubspaceSize = 12;
constexpr int kSubspaceIterations = 30;
/// Shift making the scaled semi-definite matrix definite for the inverse iteration.
constexpr double kSubspaceShift = 1e-10;
/// Seed of the subspace iteration's starting vectors.
constexpr unsigned kSeed = 20240611;

StaticOptions staticOptions(const PhysicsCheckOptions& o) {
  StaticOptions s;
  s.discretization.method = o.method;
  s.discretization.basis = o.basis;
  s.discretization.penalty = o.penalty;
  s.solver.kind = SolverKind::Cholesky;
  return s;
}

/// Smallest eigenvalues (ascending) of the symmetric matrix s.
Eigen::VectorXd smallestEigenvalues(const SpMat& s) {
  if (s.rows() <= kDenseLimit) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(s), Eigen::EigenvaluesOnly);
    return eig.eigenvalues();
  }
  SpMat shifted = s;
  for (Eigen::Index i = 0; i < s.rows(); ++i) shifted.coeffRef(i, i) += kSubspaceShift;
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> llt;
  llt.cholmod().print = 0;
  llt.compute(shifted);
  const int k = static_cast<int>(std::min<Eigen::Index>(kSubspaceSize, s.rows()));
  std::mt19937 rng(kSeed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd x(s.rows(), k);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = normal(rng);
  for (int it = 0; it < kSubspaceIterations; ++it) {
    Eigen::MatrixXd y = llt.solve(x);
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(y);
    x = qr.householderQ() * Eigen::MatrixXd::Identity(s.rows(), k);
  }
  const Eigen::MatrixXd h = x.transpose() * (s * x);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (h + h.transpose()),
                                                     Eigen::EigenvaluesOnly);
  return eig.eigenvalues();
}

}  // namespace

PatchTestResult patchTest(const PolyMesh& mesh, const PhysicsCheckOptions& options) {
  const Box3 box = meshBounds(mesh);
  const Vec3 x0 = box.center();
  const double length = box.diagonal().norm();
  Eigen::Matrix3d a;
  a << 0.3, -0.2, 0.5, 0.1, 0.4, -0.3, -0.25, 0.15, 0.2;
  const Vec3 b = length * Vec3(0.1, -0.2, 0.3);
  const auto exact = [=](const Vec3& x) -> Vec3 { return b + a * (x - x0); };
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::allBoundary(), exact});
  StaticSolution s = solveStatic(mesh, options.material, loads, staticOptions(options));
  const DgBasis& basis = *s.basis;
  const int degree = basis.degree();
  const Eigen::VectorXd projected = projectField(mesh, basis, *s.moments, exact, degree + 1);
  const int bs = 3 * basis.size(), n = basis.size();
  double errorSq = 0.0, normSq = 0.0, worst = 0.0;
  Eigen::MatrixXd mass;
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const ElementId e(i);
    elementMass(basis, *s.moments, e, mass);
    double ei = 0.0, ni = 0.0;
    for (int d = 0; d < 3; ++d) {
      const Eigen::VectorXd u = projected.segment(i * bs + d * n, n);
      const Eigen::VectorXd diff = s.coefficients.segment(i * bs + d * n, n) - u;
      ei += diff.dot(mass * diff);
      ni += u.dot(mass * u);
    }
    errorSq += ei;
    normSq += ni;
    if (ni > 0.0) worst = std::max(worst, std::sqrt(std::max(0.0, ei) / ni));
  }
  PatchTestResult r;
  r.relativeError = std::sqrt(std::max(0.0, errorSq) / normSq);
  r.maxElementError = worst;
  r.eta = s.report.eta;
  r.residual = s.report.solver.residual;
  return r;
}

ZeroModeReport zeroModes(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                         const SpMat& matrix) {
  ZeroModeReport report;
  std::size_t count = 0;
  const ElementData<std::uint32_t> component = connectedComponents(mesh, count);
  report.components = count;
  report.zeroModesPerComponent.assign(count, 0);
  report.smallestNonzeroEigenvalue = std::numeric_limits<double>::infinity();
  const int bs = 3 * basis.size();
  // Jacobi scaling; a zero diagonal (the constant functions of an element without coupled
  // faces) takes its element block's mean diagonal, which keeps the scaling scale-free.
  const Eigen::VectorXd diagonal = matrix.diagonal();
  Eigen::VectorXd scale(diagonal.size());
  for (Eigen::Index b = 0; b < diagonal.size() / bs; ++b) {
    const auto block = diagonal.segment(b * bs, bs);
    const double mean = block.cwiseMax(0.0).mean();
    for (int k = 0; k < bs; ++k) {
      const double d = block[k] > 0.0 ? block[k] : mean;
      scale[b * bs + k] = d > 0.0 ? 1.0 / std::sqrt(d) : 1.0;
    }
  }

  // Rigid motions as coefficients: translations e_d and rotations e_d x (x - c).
  const Vec3 c = meshBounds(mesh).center();
  const double length = std::max(meshBounds(mesh).diagonal().norm(), 1e-300);
  std::vector<Eigen::VectorXd> rigid;
  for (int d = 0; d < 6; ++d) {
    const auto field = [&](const Vec3& x) -> Vec3 {
      Vec3 axis = Vec3::Zero();
      axis[d % 3] = 1.0;
      return d < 3 ? axis : Vec3(axis.cross(x - c) / length);
    };
    rigid.push_back(projectField(mesh, basis, moments, field, basis.degree() + 1));
  }

  for (std::size_t comp = 0; comp < count; ++comp) {
    std::vector<int> dofs;
    for (std::size_t i = 0; i < mesh.numElements(); ++i)
      if (component[ElementId(i)] == comp)
        for (int k = 0; k < bs; ++k) dofs.push_back(static_cast<int>(i * bs + k));
    std::vector<int> local(matrix.rows(), -1);
    for (std::size_t k = 0; k < dofs.size(); ++k) local[dofs[k]] = static_cast<int>(k);
    std::vector<Eigen::Triplet<double>> triplets;
    for (int col : dofs)
      for (SpMat::InnerIterator it(matrix, col); it; ++it)
        if (local[it.row()] >= 0)
          triplets.emplace_back(local[it.row()], local[col],
                                it.value() * scale[it.row()] * scale[col]);
    const auto m = static_cast<int>(dofs.size());
    SpMat s(m, m);
    s.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::VectorXd values = smallestEigenvalues(s);
    for (Eigen::Index k = 0; k < values.size(); ++k) {
      if (values[k] < kZeroModeThreshold) {
        ++report.zeroModesPerComponent[comp];
        report.largestZeroEigenvalue = std::max(report.largestZeroEigenvalue, values[k]);
      } else {
        report.smallestNonzeroEigenvalue = std::min(report.smallestNonzeroEigenvalue, values[k]);
      }
    }
    for (const Eigen::VectorXd& r : rigid) {
      Eigen::VectorXd rs(m);
      for (int k = 0; k < m; ++k) rs[k] = r[dofs[k]] / scale[dofs[k]];
      const double norm = rs.norm();
      if (norm > 0.0)
        report.rigidMotionResidual = std::max(report.rigidMotionResidual, (s * rs).norm() / norm);
    }
    report.zeroModes += report.zeroModesPerComponent[comp];
  }
  return report;
}

ZeroModeReport rigidModes(const PolyMesh& mesh, const PhysicsCheckOptions& options) {
  StaticSolver solver(mesh, options.material, staticOptions(options));
  solver.integrate();
  LoadCase none;
  solver.assemble(none);
  return zeroModes(mesh, solver.basis(), solver.moments(), solver.system().matrix);
}

DefinitenessReport definiteness(const PolyMesh& mesh, const PhysicsCheckOptions& options) {
  StaticSolver solver(mesh, options.material, staticOptions(options));
  LoadCase clamped;
  clamped.dirichlet.push_back({FaceSelector::allBoundary(), {}});
  solver.assemble(clamped);
  const SpMat& k = solver.system().matrix;
  DefinitenessReport r;
  const SpMat kt = k.transpose();
  const double largest = k.coeffs().cwiseAbs().maxCoeff();
  r.asymmetry = largest > 0.0 ? SpMat(k - kt).coeffs().cwiseAbs().maxCoeff() / largest : 0.0;
  r.choleskySucceeded = isPositiveDefinite(k);
  r.modes = zeroModes(mesh, solver.basis(), solver.moments(), k);
  return r;
}

}  // namespace polydg
