// The element-local DG checks of physics/checks/dg_checks.h (localDgChecks and
// localDgChecksOfSelection): rigid modes, the local patch test and definiteness of each
// element, with small fixed-size matrices.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Dense>

#include "physics/checks/dg_checks.h"
#include "physics/checks/linear_field.h"
#include "physics/checks/pivoted_ldlt.h"
#include "physics/dg/polynomial_tables.h"
#include "polydg/integrate/moments.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

namespace polydg {

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

  /// The local penalty eta_K of localDgChecks(): every face of K a Dirichlet face (w_F = 1).
  double localPenalty(ElementId e) const {
    double sum = 0.0;
    for (const FaceUse& use : mesh.element(e).faces) {
      const double area = moments.area(use.face);
      if (!(area > 0.0)) continue;
      // Degree 1: the lifting space is the constants, psi = 1 / sqrt(vol), trace = area / vol.
      sum += P == 1 ? 1.0
                    : moments.volume(e) / area *
                          liftingFaceGram(basis, moments, mesh, use.face, e).trace();
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

  /// The matrices are scratch space.
  ElementOutcome check(ElementId e, Eigen::MatrixXd& stiffness, Eigen::MatrixXd& selfBlock,
                       Eigen::MatrixXd& spare) const {
    ElementOutcome out;
    elementStiffness(basis, moments, e, mu, lambda, stiffness);
    const Mat kk(stiffness);
    out.wrongRigidModes = zeroModes(kk) != 6;

    // K's rows of A U = F with every face of K a Dirichlet face, g = u, at the exact
    // coefficients U: A = K_K + sum_F S_F (faceRows()' self block of a Dirichlet face) and F =
    // sum_F (S_F U + t_F) with t_F(v) = int_F (sigma(u) n) . v, so r = A U - F = K_K U - sum_F
    // t_F. An interior face gives the same rows when the neighbour holds u exactly ([u] = 0,
    // {sigma(u)} = sigma(u)), so the neighbours are not read.
    const FormCoefficients form{Method::IP, mu, lambda, localPenalty(e)};
    const Vec exact = exactCoefficients(e);
    const auto& uses = mesh.element(e).faces;
    Mat a = kk;
    Vec r = kk * exact;
    for (const FaceUse& use : uses) {
      FaceView view;
      view.face = use.face;
      view.kind = FaceKind::Dirichlet;
      view.self = e;
      view.selfIsFront = !use.reversed;
      view.selfCoupledFaces = static_cast<int>(uses.size());
      faceRows(mesh, basis, moments, view, form, selfBlock, spare, false);
      a += Eigen::Map<const Mat>(selfBlock.data());
      const Vec3 n =
          view.selfIsFront ? moments.faceNormal(use.face) : Vec3(-moments.faceNormal(use.face));
      const Vec3 traction = stress * n;
      const VecN integrals = faceIntegrals(use.face, e);
      for (int d = 0; d < 3; ++d) r.template segment<N>(d * N) -= traction[d] * integrals;
    }

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
    for (const FaceUse& use : uses)
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

namespace {

/// The checks of the elements of `mesh` that `only` selects (every element if empty), with the
/// patch field `u`.
CheckTotals checkElements(const PolyMesh& mesh, const MomentCache& moments,
                          const LocalDgCheckOptions& options, const std::vector<char>& only,
                          const LinearField& u) {
  const DgBasis basis(mesh, moments, options.basis);
  const double mu = options.material.mu(), lambda = options.material.lambda();
  const Eigen::Matrix3d strain = 0.5 * (u.a + u.a.transpose());
  const Eigen::Matrix3d stress =
      2.0 * mu * strain + lambda * strain.trace() * Eigen::Matrix3d::Identity();
  return detail::dispatchBasisDegree(basis.degree(), [&](auto p) {
    using Kernel = LocalCheckKernel<p()>;
    const Kernel kernel{mesh, moments, basis, u, mu, lambda, stress};
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, mesh.numElements(), 64), CheckTotals{},
        [&](const tbb::blocked_range<std::size_t>& range, CheckTotals totals) {
          Eigen::MatrixXd stiffness, selfBlock, spare;
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (!only.empty() && !only[i]) continue;
            const ElementId e(i);
            totals.add(e, kernel.check(e, stiffness, selfBlock, spare));
          }
          return totals;
        },
        [](CheckTotals a, const CheckTotals& b) {
          a.join(b);
          return a;
        });
  });
}

LocalDgCheck report(const CheckTotals& totals, const LocalDgCheckOptions& options,
                    std::size_t elements) {
  LocalDgCheck c;
  c.degree = options.basis.degree;
  c.elements = elements;
  c.maxPatchTestError = std::max(totals.maxError, 0.0);
  c.worstPatchTestElement = totals.worst;
  c.patchTestFailures = totals.patchFailures;
  c.elementsWithWrongRigidModes = totals.wrongRigid;
  c.firstWrongRigidModeElement = totals.firstWrongRigid;
  c.nonDefiniteElements = totals.nonDefinite;
  return c;
}

}  // namespace

LocalDgCheck localDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                           const LocalDgCheckOptions& options) {
  const Stopwatch start;
  options.material.check();
  if (!options.only.empty() && options.only.size() != mesh.numElements())
    throw std::invalid_argument("localDgChecks: `only` needs one entry per element");
  const CheckTotals totals =
      checkElements(mesh, moments, options, options.only, localPatchField(mesh));
  LocalDgCheck c = report(totals, options,
                          options.only.empty() ? mesh.numElements()
                                               : static_cast<std::size_t>(std::count(
                                                     options.only.begin(), options.only.end(), 1)));
  c.seconds = start.seconds();
  return c;
}

namespace {

/// Elements of a mesh copied, a few at a time, into a mesh of their own: each with the faces
/// it uses (the same loops and orientation, so the same moments) and their vertices. A face
/// whose other element was not copied keeps only the side that was.
class PartCopier {
 public:
  explicit PartCopier(const PolyMesh& mesh)
      : mesh_(mesh),
        newElement_(mesh.numElements(), kNone),
        newFace_(mesh.numFaces(), kNone),
        newVertex_(mesh.numVertices(), kNone) {}

  /// The elements `ids`, in that order (element i of the part is ids[i]).
  PolyMesh copy(std::span<const ElementId> ids) {
    std::vector<FaceId> faces;
    std::vector<VertexId> vertices;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      newElement_[ids[i].index()] = static_cast<std::uint32_t>(i);
      for (const FaceUse& use : mesh_.element(ids[i]).faces) {
        std::uint32_t& f = newFace_[use.face.index()];
        if (f != kNone) continue;
        f = static_cast<std::uint32_t>(faces.size());
        faces.push_back(use.face);
        for (VertexId v : mesh_.face(use.face).vertices) {
          std::uint32_t& w = newVertex_[v.index()];
          if (w != kNone) continue;
          w = static_cast<std::uint32_t>(vertices.size());
          vertices.push_back(v);
        }
      }
    }
    VertexData<Vec3> positions;
    positions.raw().reserve(vertices.size());
    for (VertexId v : vertices) positions.raw().push_back(mesh_.position(v));
    FaceData<Face> partFaces(faces.size());
    for (std::size_t i = 0; i < faces.size(); ++i) {
      Face& face = partFaces[FaceId(i)];
      face = mesh_.face(faces[i]);
      for (VertexId& v : face.vertices) v = VertexId(std::size_t(newVertex_[v.index()]));
      face.front = mapped(face.front);
      face.back = mapped(face.back);
    }
    ElementData<Element> elements(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      for (const FaceUse& use : mesh_.element(ids[i]).faces)
        elements[ElementId(i)].faces.push_back(
            {FaceId(std::size_t(newFace_[use.face.index()])), use.reversed});
    // Unmarked for the next part.
    for (ElementId e : ids) newElement_[e.index()] = kNone;
    for (FaceId f : faces) newFace_[f.index()] = kNone;
    for (VertexId v : vertices) newVertex_[v.index()] = kNone;
    PolyMesh part;
    part.assign(std::move(positions), std::move(partFaces), std::move(elements));
    return part;
  }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  ElementId mapped(ElementId e) const {
    return e.valid() && newElement_[e.index()] != kNone
               ? ElementId(std::size_t(newElement_[e.index()]))
               : ElementId();
  }

  const PolyMesh& mesh_;
  std::vector<std::uint32_t> newElement_, newFace_, newVertex_;
};

/// Elements checked together in localDgChecksOfSelection(), a part on each core: their
/// moments take about a MB, which the next part's reuse instead of fresh pages (a page fault and
/// its zeroing are dear here).
constexpr std::size_t kPartElements = 1024;

}  // namespace

LocalDgCheck localDgChecksOfSelection(const PolyMesh& mesh, const LocalDgCheckOptions& options) {
  const Stopwatch start;
  options.material.check();
  if (options.only.size() != mesh.numElements())
    throw std::invalid_argument("localDgChecksOfSelection: `only` needs one entry per element");
  std::vector<ElementId> selected;
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    if (options.only[e]) selected.push_back(ElementId(e));
  const LinearField u = localPatchField(mesh);  // of the whole mesh's bounding box
  // One copier per thread: a copy marks the mesh's elements, faces and vertices as it goes.
  tbb::enumerable_thread_specific<PartCopier> copiers([&] { return PartCopier(mesh); });
  const std::size_t parts = (selected.size() + kPartElements - 1) / kPartElements;
  std::vector<CheckTotals> partTotals(parts);
  std::vector<std::size_t> integrated(parts, 0);
  tbb::parallel_for(std::size_t(0), parts, [&](std::size_t k) {
    const std::size_t first = k * kPartElements;
    const std::span<const ElementId> ids(selected.data() + first,
                                         std::min(kPartElements, selected.size() - first));
    const PolyMesh part = copiers.local().copy(ids);  // serial: nothing else runs on its marks
    MomentCache moments(part, 2 * options.basis.degree);
    integrated[k] = moments.update();
    CheckTotals& t = partTotals[k];
    t = checkElements(part, moments, options, {}, u);
    // Back to the ids of `mesh`, which keep the order of the part's.
    auto back = [&](ElementId e) { return e.valid() ? ids[e.index()] : ElementId(); };
    t.worst = back(t.worst);
    t.firstWrongRigid = back(t.firstWrongRigid);
  });
  CheckTotals totals;
  for (const CheckTotals& t : partTotals) totals.join(t);
  LocalDgCheck c = report(totals, options, selected.size());
  c.seconds = start.seconds();
  c.facesIntegrated = std::accumulate(integrated.begin(), integrated.end(), std::size_t(0));
  return c;
}

}  // namespace polydg
