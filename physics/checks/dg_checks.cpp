// The whole-mesh DG checks of physics/checks/dg_checks.h: the patch test, the zero modes of each
// connected component and definiteness; the element-local checks are in local_dg_checks.cpp.
#include "physics/checks/dg_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>

#include "physics/checks/linear_field.h"
#include "polydg/integrate/moments.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/physics/dg/post_process.h"

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
  s.discretization = o.discretization;
  s.solver.kind = SolverKind::Cholesky;
  return s;
}

/// The rigid motion d of zeroModes(): the translation e_d (d < 3), or the rotation
/// e_(d-3) x (x - centre) / length.
LinearField rigidField(int d, const Vec3& centre, double length) {
  LinearField field;
  field.x0 = centre;
  if (d < 3) {
    field.b[d] = 1.0;
  } else {
    Vec3 axis = Vec3::Zero();
    axis[d - 3] = 1.0;
    field.a << 0.0, -axis.z(), axis.y(), axis.z(), 0.0, -axis.x(), -axis.y(), axis.x(), 0.0;
    field.a /= length;  // a v = axis x v / length
  }
  return field;
}

/// Smallest eigenvalues (ascending) of the symmetric matrix s, and their eigenvectors in the
/// columns of `vectors` if not null.
Eigen::VectorXd smallestEigenvalues(const SpMat& s, Eigen::MatrixXd* vectors = nullptr) {
  const auto options = vectors ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly;
  if (s.rows() <= kDenseLimit) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(s), options);
    if (vectors) *vectors = eig.eigenvectors();
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
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (h + h.transpose()), options);
  if (vectors) *vectors = x * eig.eigenvectors();  // the Ritz vectors
  return eig.eigenvalues();
}

}  // namespace

PatchTestResult patchTest(const PolyMesh& mesh, const PhysicsCheckOptions& options,
                          const MomentCache* moments) {
  const Box3 box = meshBounds(mesh);
  const Vec3 x0 = box.center();
  const double length = box.diagonal().norm();
  Eigen::Matrix3d a;
  a << 0.3, -0.2, 0.5, 0.1, 0.4, -0.3, -0.25, 0.15, 0.2;
  const Vec3 b = length * Vec3(0.1, -0.2, 0.3);
  const auto exact = [=](const Vec3& x) -> Vec3 { return b + a * (x - x0); };
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::allBoundary(), exact});
  StaticSolution s = solveStatic(mesh, options.material, loads, staticOptions(options), moments);
  const MomentCache& cache = moments ? *moments : *s.moments;
  const DgBasis& basis = *s.basis;
  const int degree = basis.degree();
  const Eigen::VectorXd projected = projectField(mesh, basis, cache, exact, degree + 1);
  const int bs = 3 * basis.size(), n = basis.size();
  double errorSq = 0.0, normSq = 0.0, worst = 0.0;
  Eigen::MatrixXd mass;
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const ElementId e(i);
    elementMass(basis, cache, e, mass);
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

namespace {

/// zeroModes() with the component of each block given; the vectors `rigid` (over all DOFs, or
/// none) must be in each component's kernel.
ZeroModeReport zeroModesOfComponents(const SpMat& matrix, int bs,
                                     std::span<const std::uint32_t> component, std::size_t count,
                                     std::span<const Eigen::VectorXd> rigid,
                                     std::vector<Eigen::MatrixXd>* kernels) {
  const Eigen::Index blocks = matrix.rows() / bs;
  if (matrix.rows() != matrix.cols() || blocks * bs != matrix.rows() ||
      static_cast<Eigen::Index>(component.size()) != blocks)
    throw std::invalid_argument("zeroModes: one component per block of a square matrix");
  // The components are the matrix's decoupled blocks: every entry stays within one. Each
  // component's DOFs, and each DOF's place among them.
  std::vector<std::vector<int>> dofs(count);
  std::vector<int> local(matrix.rows(), -1);
  for (Eigen::Index b = 0; b < blocks; ++b) {
    if (component[b] >= count) throw std::invalid_argument("zeroModes: component out of range");
    for (int k = 0; k < bs; ++k) {
      local[b * bs + k] = static_cast<int>(dofs[component[b]].size());
      dofs[component[b]].push_back(static_cast<int>(b * bs + k));
    }
  }
  for (Eigen::Index col = 0; col < matrix.outerSize(); ++col)
    for (SpMat::InnerIterator it(matrix, col); it; ++it)
      if (component[it.row() / bs] != component[col / bs])
        throw std::invalid_argument("zeroModes: the matrix couples blocks " +
                                    std::to_string(it.row() / bs) + " and " +
                                    std::to_string(col / bs) + " of different components");

  ZeroModeReport report;
  report.components = count;
  report.zeroModesPerComponent.assign(count, 0);
  report.smallestNonzeroEigenvalue = std::numeric_limits<double>::infinity();
  const Eigen::VectorXd scale = zeroModeScaling(matrix.diagonal(), bs);
  if (kernels) kernels->assign(count, Eigen::MatrixXd());
  Eigen::MatrixXd vectors;
  for (std::size_t comp = 0; comp < count; ++comp) {
    std::vector<Eigen::Triplet<double>> triplets;
    for (int col : dofs[comp])
      for (SpMat::InnerIterator it(matrix, col); it; ++it)
        triplets.emplace_back(local[it.row()], local[col],
                              it.value() * scale[it.row()] * scale[col]);
    const auto m = static_cast<int>(dofs[comp].size());
    SpMat s(m, m);
    s.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::VectorXd values = smallestEigenvalues(s, kernels ? &vectors : nullptr);
    for (Eigen::Index k = 0; k < values.size(); ++k) {
      if (values[k] < kZeroModeThreshold) {
        ++report.zeroModesPerComponent[comp];
        report.largestZeroEigenvalue = std::max(report.largestZeroEigenvalue, values[k]);
      } else {
        report.smallestNonzeroEigenvalue = std::min(report.smallestNonzeroEigenvalue, values[k]);
      }
    }
    if (kernels) {  // eigenvalues ascending: the zero modes come first; unscaled
      const auto zero = static_cast<Eigen::Index>(report.zeroModesPerComponent[comp]);
      Eigen::MatrixXd& kernel = (*kernels)[comp];
      kernel = vectors.leftCols(zero);
      for (int k = 0; k < m; ++k) kernel.row(k) *= scale[dofs[comp][k]];
    }
    for (const Eigen::VectorXd& r : rigid) {
      Eigen::VectorXd rs(m);
      for (int k = 0; k < m; ++k) rs[k] = r[dofs[comp][k]] / scale[dofs[comp][k]];
      const double norm = rs.norm();
      if (norm > 0.0)
        report.rigidMotionResidual = std::max(report.rigidMotionResidual, (s * rs).norm() / norm);
    }
    report.zeroModes += report.zeroModesPerComponent[comp];
  }
  return report;
}

}  // namespace

ZeroModeReport zeroModes(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                         const SpMat& matrix) {
  std::size_t count = 0;
  const ElementData<std::uint32_t> component = connectedComponents(mesh, count);
  const int bs = 3 * basis.size();

  // Rigid motions as coefficients: translations e_d and rotations e_d x (x - c) / length.
  const Vec3 c = meshBounds(mesh).center();
  const double length = std::max(meshBounds(mesh).diagonal().norm(), 1e-300);
  std::vector<Eigen::VectorXd> rigid;
  for (int d = 0; d < 6; ++d) {
    const LinearField field = rigidField(d, c, length);
    Eigen::VectorXd r(static_cast<Eigen::Index>(mesh.numElements()) * bs);
    for (std::size_t i = 0; i < mesh.numElements(); ++i)
      linearFieldCoefficients(basis, ElementId(i), field,
                              {r.data() + i * bs, static_cast<std::size_t>(bs)});
    rigid.push_back(std::move(r));
  }
  return zeroModesOfComponents(matrix, bs, component.raw(), count, rigid, nullptr);
}

ZeroModeReport zeroModes(const SpMat& matrix, int blockSize,
                         std::span<const std::uint32_t> component, std::size_t components,
                         std::vector<Eigen::MatrixXd>* kernels) {
  return zeroModesOfComponents(matrix, blockSize, component, components, {}, kernels);
}

Eigen::MatrixXd rigidMotionCoefficients(const DgBasis& basis, ElementId e, const Vec3& centre,
                                        double length) {
  const int bs = 3 * basis.size();
  Eigen::MatrixXd out(bs, 6);
  for (int d = 0; d < 6; ++d)
    linearFieldCoefficients(basis, e, rigidField(d, centre, length),
                            {out.col(d).data(), static_cast<std::size_t>(bs)});
  return out;
}

Eigen::VectorXd linearFieldCoefficients(const DgBasis& basis, ElementId e, const Vec3& b,
                                        const Eigen::Matrix3d& a, const Vec3& x0) {
  LinearField field;
  field.a = a;
  field.b = b;
  field.x0 = x0;
  Eigen::VectorXd out(3 * basis.size());
  linearFieldCoefficients(basis, e, field, {out.data(), static_cast<std::size_t>(out.size())});
  return out;
}

Eigen::VectorXd zeroModeScaling(const Eigen::VectorXd& diagonal, int blockSize) {
  Eigen::VectorXd scale(diagonal.size());
  for (Eigen::Index b = 0; b < diagonal.size() / blockSize; ++b) {
    const auto block = diagonal.segment(b * blockSize, blockSize);
    const double mean = block.cwiseMax(0.0).mean();
    for (int k = 0; k < blockSize; ++k) {
      const double d = block[k] > 0.0 ? block[k] : mean;
      scale[b * blockSize + k] = d > 0.0 ? 1.0 / std::sqrt(d) : 1.0;
    }
  }
  return scale;
}

std::size_t countZeroModes(const Eigen::MatrixXd& matrix, const Eigen::VectorXd& scale) {
  Eigen::MatrixXd shifted = scale.asDiagonal() * matrix * scale.asDiagonal();
  shifted.diagonal().array() -= kZeroModeThreshold;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(shifted);
  std::size_t count = 0;
  for (const double d : ldlt.vectorD()) count += !(d >= 0.0);
  return count;
}

ZeroModeReport rigidModes(const PolyMesh& mesh, const PhysicsCheckOptions& options,
                          const MomentCache* moments) {
  StaticSolver solver(mesh, options.material, staticOptions(options), moments);
  solver.integrate();
  LoadCase none;
  solver.assemble(none);
  return zeroModes(mesh, solver.basis(), solver.moments(), solver.system().matrix);
}

DefinitenessReport definiteness(const PolyMesh& mesh, const PhysicsCheckOptions& options,
                                const MomentCache* moments) {
  StaticSolver solver(mesh, options.material, staticOptions(options), moments);
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
