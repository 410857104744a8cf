#include "polydg/physics/region_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include <Eigen/SparseCore>

#include "polydg/integrate/monomials.h"
#include "polydg/mesh/geometry.h"
#include "polydg/physics/assembly.h"
#include "polydg/physics/face_quadrature.h"
#include "polydg/physics/linear_solver.h"
#include "polydg/physics/post_process.h"
#include "polydg/physics/validation.h"
#include "polydg/util/stopwatch.h"
#include "polydg/util/union_find.h"

namespace polydg {

bool RegionDgCheck::passed() const {
  if (!(patchTestError < kLocalPatchTestTolerance)) return false;
  if (!(momentMismatch <= kRegionMomentTolerance)) return false;
  return std::all_of(zeroModesPerComponent.begin(), zeroModesPerComponent.end(),
                     [](std::size_t m) { return m == 6; });
}

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Triplets = std::vector<Eigen::Triplet<double>>;

/// A copy of some elements of a mesh with their faces and vertices, local ids dense in the
/// order elements were added. Faces shared by two copied elements stay shared; faces, loops
/// and vertex orders are copied as they are, so moments computed on the copy equal the
/// original's.
class SubMesh {
 public:
  explicit SubMesh(const PolyMesh& source) : source_(source) {}

  PolyMesh& mesh() { return mesh_; }
  const PolyMesh& mesh() const { return mesh_; }
  std::size_t size() const { return global_.size(); }
  ElementId global(ElementId local) const { return global_[local.index()]; }
  FaceId face(FaceId global) const { return FaceId(faces_.at(global.value)); }
  bool contains(ElementId global) const { return elements_.count(global.value) != 0; }

  /// Copies element `e` of the source (its faces and vertices if not copied yet).
  ElementId add(ElementId e) {
    FaceList uses;
    for (const FaceUse& use : source_.element(e).faces)
      uses.push_back({copyFace(use.face), use.reversed});
    const ElementId local = mesh_.addElementFromFaces(uses);
    global_.push_back(e);
    elements_.emplace(e.value, local.value);
    return local;
  }

 private:
  FaceId copyFace(FaceId f) {
    const auto found = faces_.find(f.value);
    if (found != faces_.end()) return FaceId(found->second);
    const Face& face = source_.face(f);
    boost::container::small_vector<VertexId, 6> vertices;
    for (VertexId v : face.vertices) vertices.push_back(copyVertex(v));
    const FaceId local = mesh_.addFace({vertices.data(), vertices.size()},
                                       {face.loopEnd.data(), face.loopEnd.size()}, face.origin);
    faces_.emplace(f.value, local.value);
    return local;
  }

  VertexId copyVertex(VertexId v) {
    const auto [it, inserted] = vertices_.emplace(v.value, 0);
    if (inserted) it->second = mesh_.addVertex(source_.position(v)).value;
    return VertexId(it->second);
  }

  const PolyMesh& source_;
  PolyMesh mesh_;
  std::vector<ElementId> global_;
  std::unordered_map<std::uint32_t, std::uint32_t> vertices_, faces_, elements_;
};

/// The element on the other side of face f from e in `mesh` (invalid on a boundary face).
ElementId across(const PolyMesh& mesh, FaceId f, ElementId e) {
  const Face& face = mesh.face(f);
  return face.front == e ? face.back : face.front;
}

/// Adds a dense block at block position (row, col) to `triplets`.
void addBlock(Triplets& triplets, std::size_t row, std::size_t col, const Eigen::MatrixXd& block) {
  const auto bs = static_cast<std::size_t>(block.rows());
  for (Eigen::Index j = 0; j < block.cols(); ++j)
    for (Eigen::Index i = 0; i < block.rows(); ++i)
      if (block(i, j) != 0.0)
        triplets.emplace_back(static_cast<int>(row * bs + i), static_cast<int>(col * bs + j),
                              block(i, j));
}

/// max over the elements of `sub` of the relative difference between the caller's moments and
/// those just computed on the copy: |m_a - m'_a| / (|m'_0| h^|a|), h half the element's
/// bounding-box diagonal (the size of the monomials over the element).
double momentMismatch(const SubMesh& sub, const MomentCache& fresh, const MomentCache& given) {
  const int count = std::min(fresh.stride(), given.stride());
  double worst = 0.0;
  for (std::size_t i = 0; i < sub.size(); ++i) {
    const ElementId local(i);
    const auto a = given.element(sub.global(local));
    const auto b = fresh.element(local);
    const double h = 0.5 * elementBounds(sub.mesh(), local).diagonal().norm();
    const double volume = std::abs(b[0]);
    if (!(volume > 0.0) || !(h > 0.0)) {
      if (a[0] != b[0]) worst = std::numeric_limits<double>::infinity();
      continue;
    }
    for (int k = 0; k < count; ++k) {
      const double scale = volume * std::pow(h, monomialExponents(k).degree());
      worst = std::max(worst, std::abs(a[k] - b[k]) / scale);
    }
    if (!std::isfinite(a[0])) worst = std::numeric_limits<double>::infinity();
  }
  return worst;
}

/// The penalty of the region system: the largest local penalty eta_K of localDgChecks() over
/// the region's elements, each face weighted as in the full problem (w_F^2 = 1/4 on a face with
/// an element on both sides in the whole mesh, 1 on a boundary face). Bounds 2 tau_K / theta of
/// penaltyThreshold() for every element whose DOFs are unknowns, so the region's matrix is SPD.
double regionPenalty(const PolyMesh& mesh, const SubMesh& sub, const DgBasis& basis,
                     const MomentCache& moments) {
  double eta = 0.0;
  for (std::size_t i = 0; i < sub.size(); ++i) {
    const ElementId local(i), e = sub.global(local);
    double sum = 0.0;
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceId f = sub.face(use.face);
      const double area = moments.area(f);
      if (!(area > 0.0)) continue;
      const double w2 = across(mesh, use.face, e).valid() ? 0.25 : 1.0;
      sum += w2 * moments.volume(local) / area *
             liftingFaceGram(basis, moments, sub.mesh(), f, local).trace();
    }
    eta = std::max(eta, 2.0 * sum / kConsistencyEnergyShare);
  }
  return eta;
}

/// The region's stiffness with every face to the outside and every boundary face free, and the
/// graph it couples: block i is element i of `sub`, component[i] its component.
struct RegionStiffness {
  SpMat matrix;
  std::vector<std::uint32_t> component;
  std::size_t components = 0;
  FaceData<char> joins;  ///< by face of `sub`: its terms are in `matrix`
  std::size_t looseFaces = 0;
};

/// The IP terms of the face that element e uses as `use`, shared with `other` (faceRows()' self
/// and other blocks); every face between two elements of `mesh` has face terms.
void interiorFaceRows(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                      const FormCoefficients& form, const std::vector<int>& coupled, ElementId e,
                      const FaceUse& use, ElementId other, Eigen::MatrixXd& selfBlock,
                      Eigen::MatrixXd& otherBlock) {
  const FaceView view{.face = use.face,
                      .kind = FaceKind::Interior,
                      .self = e,
                      .other = other,
                      .selfIsFront = !use.reversed,
                      .selfCoupledFaces = coupled[e.index()],
                      .otherCoupledFaces = coupled[other.index()]};
  faceRows(mesh, basis, moments, view, form, selfBlock, otherBlock);
}

/// The region's stiffness (`sub` holds the region only): element terms and the terms of the
/// faces between two of its elements that `coupling` keeps; its components are the elements
/// joined through exactly those faces. With HoldingFaces, a face is kept when it is not
/// `released` and the two elements' rows through it alone (element terms and its face terms),
/// scaled as the region's matrix with every face is scaled, have at most 6 eigenvalues below
/// kZeroModeThreshold.
RegionStiffness freeRegionStiffness(const SubMesh& sub, const DgBasis& basis,
                                    const MomentCache& moments, const FormCoefficients& form,
                                    RegionCoupling coupling, const FaceData<char>& released) {
  const PolyMesh& mesh = sub.mesh();
  const std::size_t n = sub.size();
  const int bs = 3 * basis.size();
  const bool holding = coupling == RegionCoupling::HoldingFaces;
  // Every face between two elements of the region has face terms (the counts c_K of faceRows()).
  std::vector<int> coupled(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (const FaceUse& use : mesh.element(ElementId(i)).faces)
      coupled[i] += across(mesh, use.face, ElementId(i)).valid();

  // HoldingFaces: the element terms and the Jacobi scaling of the matrix with every face.
  std::vector<Eigen::MatrixXd> stiffness;
  Eigen::VectorXd scale;
  Eigen::MatrixXd block, selfBlock, otherBlock;
  if (holding) {
    stiffness.resize(n);
    Eigen::VectorXd diagonal(static_cast<Eigen::Index>(n) * bs);
    for (std::size_t i = 0; i < n; ++i) {
      const ElementId e(i);
      elementStiffness(basis, moments, e, form.mu, form.lambda, stiffness[i]);
      auto d = diagonal.segment(static_cast<Eigen::Index>(i) * bs, bs);
      d = stiffness[i].diagonal();
      for (const FaceUse& use : mesh.element(e).faces) {
        const ElementId other = across(mesh, use.face, e);
        if (!other.valid()) continue;
        interiorFaceRows(mesh, basis, moments, form, coupled, e, use, other, selfBlock, otherBlock);
        d += selfBlock.diagonal();
      }
    }
    scale = zeroModeScaling(diagonal, bs);
  }

  // Each face between two elements once (from its front element): its terms, if it joins them.
  RegionStiffness out;
  out.joins = FaceData<char>(mesh.numFaces(), 0);
  Triplets triplets;
  UnionFind sets(n);
  Eigen::MatrixXd backSelf, backOther, pair(2 * bs, 2 * bs);
  Eigen::VectorXd pairScale(2 * bs);
  for (std::size_t i = 0; i < n; ++i) {
    const ElementId e(i);
    if (holding) {
      addBlock(triplets, i, i, stiffness[i]);
    } else {
      elementStiffness(basis, moments, e, form.mu, form.lambda, block);
      addBlock(triplets, i, i, block);
    }
    for (const FaceUse& use : mesh.element(e).faces) {
      const ElementId other = across(mesh, use.face, e);
      if (!other.valid() || use.reversed) continue;
      if (holding && released[use.face]) {
        ++out.looseFaces;
        continue;
      }
      interiorFaceRows(mesh, basis, moments, form, coupled, e, use, other, selfBlock, otherBlock);
      interiorFaceRows(mesh, basis, moments, form, coupled, other, {use.face, true}, e, backSelf,
                       backOther);
      if (holding) {
        pair << stiffness[i] + selfBlock, otherBlock, backOther,
            stiffness[other.index()] + backSelf;
        pairScale << scale.segment(static_cast<Eigen::Index>(i) * bs, bs),
            scale.segment(static_cast<Eigen::Index>(other.index()) * bs, bs);
        if (countZeroModes(pair, pairScale) > 6) {
          ++out.looseFaces;
          continue;
        }
      }
      addBlock(triplets, i, i, selfBlock);
      addBlock(triplets, i, other.index(), otherBlock);
      addBlock(triplets, other.index(), other.index(), backSelf);
      addBlock(triplets, other.index(), i, backOther);
      sets.unite(static_cast<std::uint32_t>(i), other.value);
      out.joins[use.face] = 1;
    }
  }
  out.components = sets.labels(out.component);
  const auto dofs = static_cast<int>(n) * bs;
  out.matrix = SpMat(dofs, dofs);
  out.matrix.setFromTriplets(triplets.begin(), triplets.end());
  return out;
}

/// Zero modes beyond one rigid body's 6, summed over the components.
std::size_t surplusZeroModes(const ZeroModeReport& modes) {
  std::size_t surplus = 0;
  for (std::size_t m : modes.zeroModesPerComponent) surplus += m > 6 ? m - 6 : 0;
  return surplus;
}

/// For each component of `k` with more than 6 zero modes, the joined face across which its zero
/// modes slip most: fitted per element to rigid motions (6 x modes coefficients A_K, by least
/// squares), the face with the largest |A_K - A_L|^2 / (|A_K|^2 + |A_L|^2). A component whose
/// zero modes are one rigid motion has A_K = A_L across every face.
std::vector<FaceId> mostSlippingFaces(const SubMesh& sub, const DgBasis& basis,
                                      const RegionStiffness& k, const ZeroModeReport& modes,
                                      const std::vector<Eigen::MatrixXd>& kernels) {
  const PolyMesh& mesh = sub.mesh();
  const Eigen::Index bs = 3 * basis.size();
  const Box3 box = meshBounds(mesh);
  const double length = std::max(box.diagonal().norm(), 1e-300);
  // Each element's rows in its component's kernel, and its fitted rigid motions.
  std::vector<Eigen::Index> row(sub.size());
  std::vector<Eigen::Index> rows(k.components, 0);
  for (std::size_t i = 0; i < sub.size(); ++i) {
    row[i] = rows[k.component[i]];
    rows[k.component[i]] += bs;
  }
  std::vector<Eigen::MatrixXd> fitted(sub.size());
  auto fit = [&](std::size_t i) -> const Eigen::MatrixXd& {
    if (fitted[i].size() == 0) {
      const Eigen::MatrixXd r = rigidMotionCoefficients(basis, ElementId(i), box.center(), length);
      fitted[i] = r.colPivHouseholderQr().solve(kernels[k.component[i]].middleRows(row[i], bs));
    }
    return fitted[i];
  };
  std::vector<FaceId> worst(k.components);
  std::vector<double> slip(k.components, -1.0);
  for (std::size_t i = 0; i < sub.size(); ++i) {
    const std::uint32_t c = k.component[i];
    if (modes.zeroModesPerComponent[c] <= 6) continue;
    for (const FaceUse& use : mesh.element(ElementId(i)).faces) {
      if (!k.joins[use.face] || use.reversed) continue;
      const ElementId other = across(mesh, use.face, ElementId(i));
      const Eigen::MatrixXd& a = fit(i);
      const Eigen::MatrixXd& b = fit(other.index());
      const double norm = a.squaredNorm() + b.squaredNorm();
      const double s = norm > 0.0 ? (a - b).squaredNorm() / norm : 0.0;
      if (s > slip[c]) {
        slip[c] = s;
        worst[c] = use.face;
      }
    }
  }
  std::vector<FaceId> out;
  for (FaceId f : worst)
    if (f.valid()) out.push_back(f);
  return out;
}

/// int_F phi_i for element e's functions, by face quadrature exact to the basis degree.
Eigen::VectorXd faceIntegrals(const PolyMesh& mesh, const DgBasis& basis, FaceId f, ElementId e) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(basis.size());
  Eigen::VectorXd values(basis.size());
  for (const QuadraturePoint& q : faceQuadrature(mesh, f, basis.degree())) {
    basis.values(e, q.point, {values.data(), static_cast<std::size_t>(values.size())});
    out += q.weight * values;
  }
  return out;
}

/// The patch test on `sub` = the region's elements (local ids 0 .. regionSize-1) followed by
/// their neighbours outside it, which are held at `exact` (see regionDgChecks()).
double regionPatchTest(const SubMesh& sub, std::size_t regionSize, const DgBasis& basis,
                       const MomentCache& moments, const FormCoefficients& form,
                       const Eigen::Matrix3d& gradient, const Eigen::VectorXd& exact) {
  const PolyMesh& mesh = sub.mesh();
  const int n = basis.size(), bs = 3 * n;
  const Eigen::Matrix3d strain = 0.5 * (gradient + gradient.transpose());
  const Eigen::Matrix3d stress =
      2.0 * form.mu * strain + form.lambda * strain.trace() * Eigen::Matrix3d::Identity();
  // Every face of the full problem has face terms: c_K is the element's face count.
  const auto coupled = [&](ElementId e) { return static_cast<int>(mesh.element(e).faces.size()); };

  // A_RR and the residual r = A_RR U_R + A_RQ U_Q - F_R at the exact coefficients U, assembled
  // per element as in localDgChecks(): a Dirichlet face (g = u) contributes S_F U_K to A U and
  // S_F U_K + t_F to F, so -t_F to r, with t_F(v) = int_F (sigma(u) n) . v.
  Triplets triplets;
  Eigen::VectorXd residual = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(regionSize) * bs);
  Eigen::MatrixXd block, selfBlock, otherBlock;
  for (std::size_t i = 0; i < regionSize; ++i) {
    const ElementId e(i);
    auto r = residual.segment(static_cast<Eigen::Index>(i) * bs, bs);
    const auto ue = exact.segment(static_cast<Eigen::Index>(i) * bs, bs);
    elementStiffness(basis, moments, e, form.mu, form.lambda, block);
    addBlock(triplets, i, i, block);
    r.noalias() += block * ue;
    for (const FaceUse& use : mesh.element(e).faces) {
      const ElementId other = across(mesh, use.face, e);
      FaceView view;
      view.face = use.face;
      view.kind = FaceKind::Dirichlet;
      view.self = e;
      view.selfIsFront = !use.reversed;
      view.selfCoupledFaces = coupled(e);
      if (other.valid()) {
        view.kind = FaceKind::Interior;
        view.other = other;
        view.otherCoupledFaces = coupled(other);
      }
      faceRows(mesh, basis, moments, view, form, selfBlock, otherBlock);
      addBlock(triplets, i, i, selfBlock);
      if (other.valid()) {
        r.noalias() += selfBlock * ue;
        r.noalias() +=
            otherBlock * exact.segment(static_cast<Eigen::Index>(other.index()) * bs, bs);
        if (other.index() < regionSize) addBlock(triplets, i, other.index(), otherBlock);
      } else {
        const Vec3 normal =
            use.reversed ? Vec3(-moments.faceNormal(use.face)) : moments.faceNormal(use.face);
        const Vec3 traction = stress * normal;
        const Eigen::VectorXd integrals = faceIntegrals(mesh, basis, use.face, e);
        for (int d = 0; d < 3; ++d) r.segment(d * n, n) -= traction[d] * integrals;
      }
    }
  }
  const auto dofs = static_cast<int>(residual.size());
  SpMat a(dofs, dofs);
  a.setFromTriplets(triplets.begin(), triplets.end());

  // The error delta = U_h - U solves A_RR delta = -r.
  LinearSolver solver(SolverOptions{.kind = SolverKind::Cholesky});
  if (!solver.compute(a, bs)) return std::numeric_limits<double>::infinity();
  LinearSolveReport report;
  const Eigen::VectorXd delta = solver.solve(-residual, report);
  double errorSq = 0.0, normSq = 0.0;
  Eigen::MatrixXd mass;
  for (std::size_t i = 0; i < regionSize; ++i) {
    elementMass(basis, moments, ElementId(i), mass);
    for (int d = 0; d < 3; ++d) {
      const Eigen::Index at = static_cast<Eigen::Index>(i) * bs + d * n;
      const Eigen::VectorXd err = delta.segment(at, n), u = exact.segment(at, n);
      errorSq += err.dot(mass * err);
      normSq += u.dot(mass * u);
    }
  }
  const double error = std::sqrt(std::max(0.0, errorSq) / normSq);
  return std::isfinite(error) ? error : std::numeric_limits<double>::infinity();
}

}  // namespace

RegionDgCheck regionDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                             std::span<const char> region, const LocalDgCheckOptions& options,
                             RegionCoupling coupling) {
  const Stopwatch start;
  options.material.check();
  if (region.size() != mesh.numElements())
    throw std::invalid_argument("regionDgChecks: `region` needs one entry per element");
  const int degree = options.basis.degree;
  if (moments.degree() < 2 * degree)
    throw std::invalid_argument("regionDgChecks: the moment cache must hold degree 2p moments");

  RegionDgCheck c;
  c.degree = degree;
  // 1. The region alone: moments recomputed on the copy, zero modes of its free stiffness.
  SubMesh sub(mesh);
  try {
    for (std::size_t i = 0; i < region.size(); ++i)
      if (region[i]) sub.add(ElementId(i));
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("regionDgChecks: the region's faces are not used "
                                            "consistently (") +
                                e.what() + ")");
  }
  const std::size_t regionSize = sub.size();
  c.elements = regionSize;
  if (regionSize == 0) return c;
  MomentCache fresh(sub.mesh(), 2 * degree);
  fresh.update();
  c.momentMismatch = momentMismatch(sub, fresh, moments);
  const Box3 box = meshBounds(sub.mesh());
  FormCoefficients form{Method::IP, options.material.mu(), options.material.lambda(), 0.0};
  {
    const DgBasis basis(sub.mesh(), fresh, options.basis);
    form.eta = regionPenalty(mesh, sub, basis, fresh);
    const int bs = 3 * basis.size();
    FaceData<char> released(sub.mesh().numFaces(), 0);
    RegionStiffness k = freeRegionStiffness(sub, basis, fresh, form, coupling, released);
    ZeroModeReport modes = zeroModes(k.matrix, bs, k.component, k.components);
    // HoldingFaces: a face that holds its two elements alone may not hold the groups it joins
    // (a strip holds one element's rotation about it but not a group's, whose inertia about it
    // is larger). While a component has more than one body's zero modes, release the face its
    // zero modes slip across most (counted again for their eigenvectors), as long as that
    // lowers their surplus.
    while (coupling == RegionCoupling::HoldingFaces && surplusZeroModes(modes) > 0) {
      std::vector<Eigen::MatrixXd> kernels;
      zeroModes(k.matrix, bs, k.component, k.components, &kernels);
      FaceData<char> trial = released;
      for (FaceId f : mostSlippingFaces(sub, basis, k, modes, kernels)) trial[f] = 1;
      RegionStiffness k2 = freeRegionStiffness(sub, basis, fresh, form, coupling, trial);
      ZeroModeReport modes2 = zeroModes(k2.matrix, bs, k2.component, k2.components);
      if (surplusZeroModes(modes2) >= surplusZeroModes(modes)) break;
      released = std::move(trial);
      k = std::move(k2);
      modes = std::move(modes2);
    }
    c.looseFaces = k.looseFaces;
    c.components = modes.components;
    c.zeroModesPerComponent = modes.zeroModesPerComponent;
    c.zeroModes = modes.zeroModes;
  }

  // 2. The region and its neighbours outside it, which hold the linear field.
  for (std::size_t i = 0; i < regionSize; ++i) {
    const ElementId e = sub.global(ElementId(i));
    for (const FaceUse& use : mesh.element(e).faces) {
      const ElementId other = across(mesh, use.face, e);
      if (other.valid() && !sub.contains(other)) sub.add(other);
    }
  }
  fresh.sync();
  fresh.update();
  const DgBasis basis(sub.mesh(), fresh, options.basis);
  // The field of localDgChecks() over the region's bounding box.
  Eigen::Matrix3d gradient;
  gradient << 0.31, -0.17, 0.23, 0.13, 0.27, -0.19, -0.29, 0.11, 0.21;
  const Vec3 b = box.diagonal().norm() * Vec3(0.5, -0.6, 0.7), x0 = box.center();
  const auto u = [&](const Vec3& x) -> Vec3 { return b + gradient * (x - x0); };
  const Eigen::VectorXd exact = projectField(sub.mesh(), basis, fresh, u, degree + 1);
  c.patchTestError = regionPatchTest(sub, regionSize, basis, fresh, form, gradient, exact);
  c.seconds = start.seconds();
  return c;
}

}  // namespace polydg
