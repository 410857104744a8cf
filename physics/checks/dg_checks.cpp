#include "physics/checks/dg_checks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/CholmodSupport>
#include <Eigen/Dense>

#include "physics/dg/polynomial_tables.h"
#include "polydg/integrate/moments.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

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

/// A linear field u(x) = b + A (x - x0).
struct LinearField {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  Vec3 x0 = Vec3::Zero();
  Vec3 operator()(const Vec3& x) const { return b + a * (x - x0); }
};

/// Element e's coefficients of the linear field u (3n values in LinearSystem's order d n + i),
/// exact since every basis spans the linear functions: with phi = T m (T lower triangular),
/// u_d = mu_d . m for the monomial coefficients mu_d = (u_d(c), h A(d, :), 0, ...), so
/// U_d = T^(-T) mu_d.
void linearFieldCoefficients(const DgBasis& basis, ElementId e, const LinearField& u,
                             std::span<double> out) {
  const int n = basis.size();
  const auto t = basis.coefficients(e);
  const Vec3 uc = u(basis.centre(e));
  const double h = basis.scale(e);
  for (int d = 0; d < 3; ++d) {
    double* ud = out.data() + d * n;
    for (int i = n - 1; i >= 0; --i) {  // back substitution with T^T
      double v = i == 0 ? uc[d] : i <= 3 ? h * u.a(d, i - 1) : 0.0;
      for (int j = i + 1; j < n; ++j) v -= t(j, i) * ud[j];
      ud[i] = v / t(i, i);
    }
  }
}

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

namespace {

LinearField localPatchField(const PolyMesh& mesh) {
  const Box3 box = meshBounds(mesh);
  LinearField u;
  u.a << 0.31, -0.17, 0.23, 0.13, 0.27, -0.19, -0.29, 0.11, 0.21;
  u.b = box.diagonal().norm() * Vec3(0.5, -0.6, 0.7);
  u.x0 = box.center();
  return u;
}

/// What one element contributes to a LocalDgCheck.
struct ElementOutcome {
  double error = 0.0;
  bool wrongRigidModes = false;
  bool nonDefinite = false;
};

/// LDL^T = P A P^T of a symmetric B x B matrix with diagonal pivoting (the largest remaining
/// |diagonal| first), as Eigen::LDLT, but unrolled for small fixed sizes, where Eigen's
/// blocked kernels cost several times more. By Sylvester's law of inertia the signs of D are
/// those of A's eigenvalues. Stable for the (shifted) semi-definite matrices used here.
template <int B>
class PivotedLdlt {
 public:
  using Mat = Eigen::Matrix<double, B, B>;
  using Vec = Eigen::Matrix<double, B, 1>;

  explicit PivotedLdlt(const Mat& m) : f_(m) {
    // Only the lower triangle is read and written.
    for (int i = 0; i < B; ++i) order_[i] = i;
    for (int k = 0; k < B; ++k) {
      int p = k;
      for (int i = k + 1; i < B; ++i)
        if (std::abs(f_(i, i)) > std::abs(f_(p, p))) p = i;
      if (p != k) {  // symmetric swap of k and p in lower storage
        for (int j = 0; j < k; ++j) std::swap(f_(k, j), f_(p, j));
        std::swap(f_(k, k), f_(p, p));
        for (int i = k + 1; i < p; ++i) std::swap(f_(i, k), f_(p, i));
        for (int i = p + 1; i < B; ++i) std::swap(f_(i, k), f_(i, p));
        std::swap(order_[k], order_[p]);
      }
      const double d = f_(k, k);
      nonPositive_ += !(d > 0.0);
      if (d == 0.0 || !std::isfinite(d)) {  // nothing to eliminate with
        for (int i = k + 1; i < B; ++i) f_(i, k) = 0.0;
        continue;
      }
      // A22 -= a21 a21^T / d, then column k of L = a21 / d.
      for (int j = k + 1; j < B; ++j) {
        const double lj = f_(j, k) / d;
        for (int i = j; i < B; ++i) f_(i, j) -= f_(i, k) * lj;
      }
      for (int i = k + 1; i < B; ++i) f_(i, k) /= d;
    }
  }

  /// Pivots that are not positive: the eigenvalues <= 0 (NaN pivots included).
  int nonPositivePivots() const { return nonPositive_; }

  /// A^(-1) b; valid when no pivot is zero.
  Vec solve(const Vec& b) const {
    Vec y;
    for (int i = 0; i < B; ++i) y[i] = b[order_[i]];
    for (int i = 0; i < B; ++i)
      for (int j = 0; j < i; ++j) y[i] -= f_(i, j) * y[j];
    for (int i = 0; i < B; ++i) y[i] /= f_(i, i);
    for (int i = B - 1; i >= 0; --i)
      for (int j = i + 1; j < B; ++j) y[i] -= f_(j, i) * y[j];
    Vec x;
    for (int i = 0; i < B; ++i) x[order_[i]] = y[i];
    return x;
  }

 private:
  Mat f_;  // L below the diagonal, D on it
  std::array<int, B> order_;
  int nonPositive_ = 0;
};

/// The checks of one element for basis degree P: 3N x 3N fixed-size matrices, N functions per
/// component.
template <int P>
struct LocalCheckKernel {
  static constexpr int N = numMonomials(P);
  static constexpr int B = 3 * N;
  using Mat = Eigen::Matrix<double, B, B>;
  using Vec = Eigen::Matrix<double, B, 1>;
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;

  const PolyMesh& mesh;
  const MomentCache& moments;
  const DgBasis& basis;
  const FaceRoles& roles;
  const LinearField& u;
  double mu, lambda;
  Eigen::Matrix3d stress;  ///< sigma(u), constant

  Vec exactCoefficients(ElementId e) const {
    Vec out;
    linearFieldCoefficients(basis, e, u, {out.data(), B});
    return out;
  }

  /// int_F phi_i for K's functions: the face's moments about its reference point r, scaled by
  /// h_K and shifted to K's centre c (int_F m_a = sum_b C(a, b) ((r - c) / h)^(a - b) M_b / h^|b|).
  VecN faceIntegrals(FaceId f, ElementId e) const {
    const double h = basis.scale(e);
    const auto fm = moments.face(f);
    double inversePowers[P + 1] = {1.0}, scaled[N], shifted[N];
    for (int k = 1; k <= P; ++k) inversePowers[k] = inversePowers[k - 1] / h;
    for (int a = 0; a < N; ++a) scaled[a] = fm[a] * inversePowers[monomialExponents(a).degree()];
    shiftMoments(P, (faceReferencePoint(mesh, f) - basis.centre(e)) / h, {scaled, N}, {shifted, N});
    return MatN(basis.coefficients(e)) * Eigen::Map<const VecN>(shifted);
  }

  /// The local penalty eta_K of localDgChecks().
  double localPenalty(ElementId e) const {
    double sum = 0.0;
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceKind kind = roles.kind[use.face];
      if (kind == FaceKind::Free) continue;
      const double area = moments.area(use.face);
      if (!(area > 0.0)) continue;
      const double w2 = kind == FaceKind::Interior ? 0.25 : 1.0;
      // Degree 1: the lifting space is the constants, psi = 1 / sqrt(vol), trace = area / vol.
      const double trace = P == 1 ? 1.0
                                  : moments.volume(e) / area *
                                        liftingFaceGram(basis, moments, mesh, use.face, e).trace();
      sum += w2 * trace;
    }
    return 2.0 * sum / kConsistencyEnergyShare;
  }

  /// Eigenvalues of the Jacobi-scaled k below kElementZeroModeThreshold times its largest
  /// absolute row sum: the negative pivots of LDL^T of the shifted matrix (Sylvester).
  static int zeroModes(const Mat& k) {
    Vec s;
    for (int i = 0; i < B; ++i) s[i] = k(i, i) > 0.0 ? 1.0 / std::sqrt(k(i, i)) : 1.0;
    Mat m = s.asDiagonal() * k * s.asDiagonal();
    const double bound = m.cwiseAbs().rowwise().sum().maxCoeff();
    if (!(bound > 0.0)) return B;
    m.diagonal().array() -= kElementZeroModeThreshold * bound;
    return PivotedLdlt<B>(m).nonPositivePivots();
  }

  /// `exact` holds every element's exactCoefficients(); the matrices are scratch space.
  ElementOutcome check(ElementId e, const ElementData<Vec>& exact, Eigen::MatrixXd& stiffness,
                       Eigen::MatrixXd& selfBlock, Eigen::MatrixXd& otherBlock,
                       Eigen::MatrixXd& spare) const {
    ElementOutcome out;
    elementStiffness(basis, moments, e, mu, lambda, stiffness);
    const Mat kk(stiffness);
    out.wrongRigidModes = zeroModes(kk) != 6;

    // K's rows of A U = F at the exact coefficients U (U_L on the neighbours), A = K_K + sum_F
    // S_F: r = (K_K + sum_interior S_F) U + sum_interior O_F U_L - sum_Dirichlet t_F, since the
    // Dirichlet load of g = u is S_F U + t_F with t_F(v) = int_F (sigma(u) n) . v. (S_F and O_F:
    // faceRows()' self and other blocks.)
    const FormCoefficients form{Method::IP, mu, lambda, localPenalty(e)};
    Mat interior = kk, dirichlet = Mat::Zero();
    Vec r = Vec::Zero();
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceUses& uses = roles.uses[use.face];
      const FaceKind kind = roles.kind[use.face];
      if (kind == FaceKind::Free) continue;
      const int side = uses.element[0] == e ? 0 : 1;
      FaceView view;
      view.face = use.face;
      view.kind = kind;
      view.self = e;
      view.selfIsFront = !uses.reversed[side];
      view.selfCoupledFaces = roles.coupledFaces[e];
      if (kind == FaceKind::Interior) {
        view.other = uses.element[1 - side];
        view.otherCoupledFaces = roles.coupledFaces[view.other];
      }
      // faceRows() empties `otherBlock` on boundary faces: give it a spare so that the interior
      // faces' block keeps its storage.
      faceRows(mesh, basis, moments, view, form, selfBlock,
               kind == FaceKind::Interior ? otherBlock : spare);
      const Eigen::Map<const Mat> s(selfBlock.data());
      if (kind == FaceKind::Interior) {
        interior += s;
        r.noalias() += Eigen::Map<const Mat>(otherBlock.data()) * exact[view.other];
      } else {
        dirichlet += s;
        const Vec3 n =
            view.selfIsFront ? moments.faceNormal(use.face) : Vec3(-moments.faceNormal(use.face));
        const Vec3 traction = stress * n;
        const VecN integrals = faceIntegrals(use.face, e);
        for (int d = 0; d < 3; ++d) r.template segment<N>(d * N) -= traction[d] * integrals;
      }
    }
    r.noalias() += interior * exact[e];
    const Mat a = interior + dirichlet;

    // The error field delta = U_K - U = -A^(-1) r, in K's monomials (m^T T^T delta_d).
    const PivotedLdlt<B> ldlt(a);
    Vec delta;
    if (ldlt.nonPositivePivots() == 0) {
      delta = -ldlt.solve(r);
    } else {
      out.nonDefinite = true;
      delta = -a.fullPivLu().solve(r);
    }
    const MatN t(basis.coefficients(e));
    Eigen::Matrix<double, N, 3> monomialError;
    for (int d = 0; d < 3; ++d)
      monomialError.col(d) = t.transpose() * delta.template segment<N>(d * N);
    double largestError = 0.0, largestValue = 0.0;  // squared
    double m[N];
    const Vec3 c = basis.centre(e);
    const double inverseScale = 1.0 / basis.scale(e);
    for (const FaceUse& use : mesh.element(e).faces)
      for (VertexId v : mesh.face(use.face).vertices) {
        const Vec3& x = mesh.position(v);
        scaledMonomials(P, (x - c) * inverseScale, {m, N});
        const Vec3 err = monomialError.transpose() * Eigen::Map<const VecN>(m);
        largestError = std::max(largestError, err.squaredNorm());
        largestValue = std::max(largestValue, u(x).squaredNorm());
      }
    out.error = std::sqrt(largestError / largestValue);
    if (!std::isfinite(out.error)) out.error = std::numeric_limits<double>::infinity();
    return out;
  }
};

/// Reduction of the element outcomes (lowest ids win ties, so the result is deterministic).
struct CheckTotals {
  double maxError = -1.0;
  ElementId worst;
  std::size_t patchFailures = 0, wrongRigid = 0, nonDefinite = 0;
  ElementId firstWrongRigid;

  void add(ElementId e, const ElementOutcome& o) {
    if (o.error > maxError || (o.error == maxError && e.value < worst.value)) {
      maxError = o.error;
      worst = e;
    }
    patchFailures += !(o.error < kLocalPatchTestTolerance);
    nonDefinite += o.nonDefinite;
    if (o.wrongRigidModes) {
      ++wrongRigid;
      if (!firstWrongRigid.valid() || e.value < firstWrongRigid.value) firstWrongRigid = e;
    }
  }
  void join(const CheckTotals& o) {
    if (o.maxError > maxError || (o.maxError == maxError && o.worst.value < worst.value)) {
      maxError = o.maxError;
      worst = o.worst;
    }
    patchFailures += o.patchFailures;
    wrongRigid += o.wrongRigid;
    nonDefinite += o.nonDefinite;
    if (o.firstWrongRigid.valid() &&
        (!firstWrongRigid.valid() || o.firstWrongRigid.value < firstWrongRigid.value))
      firstWrongRigid = o.firstWrongRigid;
  }
};

}  // namespace

std::size_t elementZeroModes(const Eigen::MatrixXd& stiffness, int degree) {
  return detail::dispatchBasisDegree(degree, [&](auto p) -> std::size_t {
    using Kernel = LocalCheckKernel<p()>;
    if (stiffness.rows() != Kernel::B || stiffness.cols() != Kernel::B)
      throw std::invalid_argument("elementZeroModes: the stiffness is not 3n x 3n for the degree");
    return static_cast<std::size_t>(Kernel::zeroModes(typename Kernel::Mat(stiffness)));
  });
}

LocalDgCheck localDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                           const LocalDgCheckOptions& options) {
  const Stopwatch start;
  options.material.check();
  if (!options.only.empty() && options.only.size() != mesh.numElements())
    throw std::invalid_argument("localDgChecks: `only` needs one entry per element");
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::allBoundary(), {}});
  const FaceRoles roles = classifyFaces(mesh, loads);
  const DgBasis basis(mesh, moments, options.basis);
  const LinearField u = localPatchField(mesh);
  const double mu = options.material.mu(), lambda = options.material.lambda();
  const Eigen::Matrix3d strain = 0.5 * (u.a + u.a.transpose());
  const Eigen::Matrix3d stress =
      2.0 * mu * strain + lambda * strain.trace() * Eigen::Matrix3d::Identity();

  const CheckTotals totals = detail::dispatchBasisDegree(basis.degree(), [&](auto p) {
    using Kernel = LocalCheckKernel<p()>;
    const Kernel kernel{mesh, moments, basis, roles, u, mu, lambda, stress};
    ElementData<typename Kernel::Vec> exact(mesh.numElements(), Kernel::Vec::Zero());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numElements(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          exact[ElementId(i)] = kernel.exactCoefficients(ElementId(i));
                      });
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, mesh.numElements(), 64), CheckTotals{},
        [&](const tbb::blocked_range<std::size_t>& range, CheckTotals totals) {
          Eigen::MatrixXd stiffness, selfBlock, otherBlock, spare;
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (!options.only.empty() && !options.only[i]) continue;
            const ElementId e(i);
            totals.add(e, kernel.check(e, exact, stiffness, selfBlock, otherBlock, spare));
          }
          return totals;
        },
        [](CheckTotals a, const CheckTotals& b) {
          a.join(b);
          return a;
        });
  });

  LocalDgCheck c;
  c.degree = basis.degree();
  c.elements =
      options.only.empty()
          ? mesh.numElements()
          : static_cast<std::size_t>(std::count(options.only.begin(), options.only.end(), 1));
  c.maxPatchTestError = std::max(totals.maxError, 0.0);
  c.worstPatchTestElement = totals.worst;
  c.patchTestFailures = totals.patchFailures;
  c.elementsWithWrongRigidModes = totals.wrongRigid;
  c.firstWrongRigidModeElement = totals.firstWrongRigid;
  c.nonDefiniteElements = totals.nonDefinite;
  c.seconds = start.seconds();
  return c;
}

namespace {

/// The selected elements of `mesh` and their face neighbours as a mesh of their own, with
/// every vertex of `mesh` (same ids, so the same bounding box) and each face they use copied
/// as is (same loops and orientation, so the same moments), in the order of `mesh`. A face
/// whose other element was left out keeps only the side that was taken. `original` receives
/// each new element's old id. Built in parallel.
PolyMesh selectionWithNeighbours(const PolyMesh& mesh, const std::vector<char>& only,
                                 std::vector<ElementId>& original) {
  constexpr std::uint32_t kNone = 0xffffffffu;
  const std::size_t ne = mesh.numElements(), nf = mesh.numFaces();
  auto otherSide = [&](const FaceUse& use) {
    const Face& face = mesh.face(use.face);
    return use.reversed ? face.front : face.back;
  };
  // An element is taken if it is selected or has a selected neighbour.
  std::vector<char> taken(ne, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne, 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e) {
                        bool t = only[e] != 0;
                        for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
                          if (t) break;
                          const ElementId other = otherSide(use);
                          t = other.valid() && only[other.index()] != 0;
                        }
                        taken[e] = t;
                      }
                    });
  std::vector<std::uint32_t> newElement(ne, kNone);
  original.clear();
  for (std::size_t e = 0; e < ne; ++e)
    if (taken[e]) {
      newElement[e] = static_cast<std::uint32_t>(original.size());
      original.push_back(ElementId(e));
    }
  auto mapped = [&](ElementId e) {
    return e.valid() && newElement[e.index()] != kNone
               ? ElementId(std::size_t(newElement[e.index()]))
               : ElementId();
  };
  // Faces of taken elements, in their order in `mesh`.
  auto inSub = [&](const Face& face) {
    return (face.front.valid() && taken[face.front.index()]) ||
           (face.back.valid() && taken[face.back.index()]);
  };
  std::vector<std::uint32_t> newFace(nf, kNone);
  for (std::size_t f = 0, next = 0; f < nf; ++f)
    if (inSub(mesh.face(FaceId(f)))) newFace[f] = static_cast<std::uint32_t>(next++);
  std::size_t kept = 0;
  for (std::size_t f = nf; f-- > 0;)
    if (newFace[f] != kNone) {
      kept = newFace[f] + std::size_t(1);
      break;
    }
  FaceData<Face> faces(kept);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f) {
                        if (newFace[f] == kNone) continue;
                        Face& face = faces[FaceId(std::size_t(newFace[f]))];
                        face = mesh.face(FaceId(f));
                        face.front = mapped(face.front);
                        face.back = mapped(face.back);
                      }
                    });
  ElementData<Element> elements(original.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, original.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        for (const FaceUse& use : mesh.element(original[i]).faces)
                          elements[ElementId(i)].faces.push_back(
                              {FaceId(std::size_t(newFace[use.face.index()])), use.reversed});
                    });
  PolyMesh sub;
  sub.assign(mesh.positions(), std::move(faces), std::move(elements));
  return sub;
}

}  // namespace

LocalDgCheck localDgChecksOfSelection(const PolyMesh& mesh, const LocalDgCheckOptions& options) {
  const Stopwatch start;
  if (options.only.size() != mesh.numElements())
    throw std::invalid_argument("localDgChecksOfSelection: `only` needs one entry per element");
  std::vector<ElementId> original;
  const PolyMesh sub = selectionWithNeighbours(mesh, options.only, original);
  MomentCache moments(sub, 2 * options.basis.degree);
  const std::size_t integrated = moments.update();
  LocalDgCheckOptions subOptions = options;
  subOptions.only.resize(original.size());
  for (std::size_t i = 0; i < original.size(); ++i)
    subOptions.only[i] = options.only[original[i].index()] ? 1 : 0;
  LocalDgCheck c = localDgChecks(sub, moments, subOptions);
  auto back = [&](ElementId e) { return e.valid() ? original[e.index()] : ElementId(); };
  c.worstPatchTestElement = back(c.worstPatchTestElement);
  c.firstWrongRigidModeElement = back(c.firstWrongRigidModeElement);
  c.seconds = start.seconds();
  c.facesIntegrated = integrated;
  return c;
}

}  // namespace polydg
