// The element-local DG checks of physics/checks/dg_checks.h (localDgChecks and
// localDgChecksOfSelection): rigid modes, the local patch test and definiteness of each
// element, with small fixed-size matrices.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
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
#include "util/resident.h"
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
  FaceData<Face> faces;
  growResident(faces.raw(), kept);  // faulted in on both cores, then filled in parallel
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
  // Every vertex, copied in parallel into resident pages.
  VertexData<Vec3> positions;
  growResident(positions.raw(), mesh.numVertices());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numVertices(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      std::copy(mesh.positions().raw().begin() + r.begin(),
                                mesh.positions().raw().begin() + r.end(),
                                positions.raw().begin() + r.begin());
                    });
  PolyMesh sub;
  sub.assign(std::move(positions), std::move(faces), std::move(elements));
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
