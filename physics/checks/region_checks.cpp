#include "physics/checks/region_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Dense>
#include <boost/container/small_vector.hpp>

#include "physics/checks/dg_checks.h"
#include "physics/dg/assembly.h"
#include "physics/dg/face_quadrature.h"
#include "polydg/integrate/moments.h"
#include "polydg/integrate/monomials.h"
#include "polydg/mesh/geometry.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"
#include "util/union_find.h"

namespace polydg {

bool RegionDgCheck::passed() const {
  if (!(patchTestResidual < kRegionPatchResidualTolerance)) return false;
  if (!(momentMismatch <= kRegionMomentTolerance)) return false;
  return std::all_of(zeroModesPerComponent.begin(), zeroModesPerComponent.end(),
                     [](std::size_t m) { return m == 6; });
}

namespace {

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
  FaceId globalFace(FaceId local) const { return globalFaces_[local.index()]; }
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
    globalFaces_.push_back(f);
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
  std::vector<FaceId> globalFaces_;
  std::unordered_map<std::uint32_t, std::uint32_t> vertices_, faces_, elements_;
};

/// The element on the other side of face f from e in `mesh` (invalid on a boundary face).
ElementId across(const PolyMesh& mesh, FaceId f, ElementId e) {
  const Face& face = mesh.face(f);
  return face.front == e ? face.back : face.front;
}

/// The region's moments recomputed from its geometry against the caller's: max over the region's
/// elements (local ids 0 .. regionSize-1 of `sub`) of |m_a - m'_a| / (|m'_0| h^|a|), m the
/// caller's element moments, m' those summed from the element's faces integrated afresh (the
/// stride of `scratch`, degree `degree`), h half the element's bounding-box diagonal (the size
/// of the monomials over the element). A face shared by two region elements is integrated once.
double momentMismatch(const SubMesh& sub, std::size_t regionSize, const MomentCache& caller,
                      int degree) {
  const PolyMesh& mesh = sub.mesh();
  const auto stride = static_cast<std::size_t>(numMonomials(degree));
  std::vector<double> faceValues(mesh.numFaces() * stride);
  FaceData<Vec3> normals(mesh.numFaces(), Vec3::Zero());
  FaceData<char> done(mesh.numFaces(), 0);
  std::vector<double> fresh(stride), scratch(stride);
  double worst = 0.0;
  for (std::size_t i = 0; i < regionSize; ++i) {
    const ElementId local(i);
    const Vec3 origin = elementReferencePoint(mesh, local);
    std::fill(fresh.begin(), fresh.end(), 0.0);
    for (const FaceUse& use : mesh.element(local).faces) {
      const std::span<double> values{faceValues.data() + use.face.index() * stride, stride};
      if (!done[use.face]) {
        faceMoments(mesh, use.face, degree, values, normals[use.face]);
        done[use.face] = 1;
      }
      accumulateElementMoments(degree, values, faceReferencePoint(mesh, use.face),
                               normals[use.face], use.reversed, origin, scratch, fresh);
    }
    const auto a = caller.element(sub.global(local));
    const double h = 0.5 * elementBounds(mesh, local).diagonal().norm();
    const double volume = std::abs(fresh[0]);
    if (!(volume > 0.0) || !(h > 0.0)) {
      if (a[0] != fresh[0]) worst = std::numeric_limits<double>::infinity();
      continue;
    }
    for (std::size_t k = 0; k < stride; ++k) {
      const double scale = volume * std::pow(h, monomialExponents(static_cast<int>(k)).degree());
      worst = std::max(worst, std::abs(a[k] - fresh[k]) / scale);
    }
    if (!std::isfinite(a[0])) worst = std::numeric_limits<double>::infinity();
  }
  return worst;
}

/// The penalty of the region's rows: the largest local penalty eta_K of localDgChecks() over
/// the region's elements (local ids 0 .. regionSize-1 of `sub`), each face weighted as in the
/// full problem (w_F^2 = 1/4 on a face with an element on both sides in the whole mesh, 1 on a
/// boundary face). Bounds 2 tau_K / theta of penaltyThreshold() for every region element, so
/// each region element's block of the IP matrix, and the region's, is SPD.
double regionPenalty(const SubMesh& sub, std::size_t regionSize, const DgBasis& basis,
                     const MomentCache& moments) {
  const PolyMesh& mesh = sub.mesh();
  double eta = 0.0;
  for (std::size_t i = 0; i < regionSize; ++i) {
    const ElementId e(i);
    double sum = 0.0;
    for (const FaceUse& use : mesh.element(e).faces) {
      const double area = moments.area(use.face);
      if (!(area > 0.0)) continue;
      const double w2 = across(mesh, use.face, e).valid() ? 0.25 : 1.0;
      sum += w2 * moments.volume(e) / area *
             liftingFaceGram(basis, moments, mesh, use.face, e).trace();
    }
    eta = std::max(eta, 2.0 * sum / kConsistencyEnergyShare);
  }
  return eta;
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

/// Copies the region's elements into `sub` (local ids 0 .. size - 1) and then, if there are
/// any, their face neighbours outside it; `box` receives the region's bounds. Returns the
/// region's size.
std::size_t copyRegion(const PolyMesh& mesh, std::span<const char> region, SubMesh& sub,
                       Box3& box) {
  try {
    for (std::size_t i = 0; i < region.size(); ++i)
      if (region[i]) sub.add(ElementId(i));
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("regionDgChecks: the region's faces are not used "
                                            "consistently (") +
                                e.what() + ")");
  }
  const std::size_t regionSize = sub.size();
  if (regionSize == 0) return 0;
  for (std::size_t i = 0; i < regionSize; ++i) {
    const ElementId e = sub.global(ElementId(i));
    box.extend(elementBounds(mesh, e));
    for (const FaceUse& use : mesh.element(e).faces) {
      const ElementId other = across(mesh, use.face, e);
      if (other.valid() && !sub.contains(other)) sub.add(other);
    }
  }
  return regionSize;
}

/// The caller's moments copied to the sub-mesh's faces, into `given` (nothing integrated).
void copyMoments(const SubMesh& sub, const MomentCache& moments, MomentCache& given) {
  const PolyMesh& local = sub.mesh();
  for (std::size_t f = 0; f < local.numFaces(); ++f) {
    const FaceId theirs = sub.globalFace(FaceId(f));
    given.assignFace(FaceId(f),
                     moments.face(theirs).first(static_cast<std::size_t>(given.stride())),
                     moments.faceNormal(theirs));
  }
  given.update();
}

/// The region's rows of the IP system at a linear field's coefficients (the patch test),
/// element by element on every core, with what the count of zero modes needs of each element:
/// its stiffness, its Jacobi scaling, its zero modes beyond 6, and the faces it shares with
/// other region elements (whose terms pairMatrix() computes again: kept, the four blocks of
/// every such face took 100 MB for a cut of 3,250 elements of B10's beam at 130 cells, and
/// the kernel's clearing of their fresh pages a quarter of the cut command).
class RegionRows {
 public:
  RegionRows(const PolyMesh& local, std::size_t regionSize, const DgBasis& basis,
             const MomentCache& given, const FormCoefficients& form, const Box3& box, int degree)
      : stiffnesses(regionSize),
        scales(regionSize),
        surplus(regionSize, 0),
        joins(local.numFaces(), 0),
        local_(local),
        regionSize_(regionSize),
        basis_(basis),
        given_(given),
        form_(form),
        degree_(degree),
        n_(basis.size()),
        bs_(3 * n_),
        residuals_(regionSize, 0.0),
        definite_(regionSize, 1) {
    Eigen::Matrix3d gradient;
    gradient << 0.31, -0.17, 0.23, 0.13, 0.27, -0.19, -0.29, 0.11, 0.21;
    const Vec3 b = box.diagonal().norm() * Vec3(0.5, -0.6, 0.7), x0 = box.center();
    exact_.resize(static_cast<Eigen::Index>(local.numElements()) * bs_);
    tbb::parallel_for(std::size_t(0), local.numElements(), [&](std::size_t i) {
      exact_.segment(static_cast<Eigen::Index>(i) * bs_, bs_) =
          linearFieldCoefficients(basis, ElementId(i), b, gradient, x0);
    });
    const Eigen::Matrix3d strain = 0.5 * (gradient + gradient.transpose());
    stress_ = 2.0 * form.mu * strain + form.lambda * strain.trace() * Eigen::Matrix3d::Identity();
  }

  /// Every region element's rows (addElement()), on every core: each task writes its elements'
  /// entries and the face blocks of their sides only.
  void addElements() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, regionSize_, 16),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        Scratch s;
                        for (std::size_t i = range.begin(); i != range.end(); ++i) addElement(i, s);
                      });
  }

  /// The largest relative residual of the rows, or infinity if an element's block is not
  /// positive definite.
  double patchTestResidual() const {
    if (std::find(definite_.begin(), definite_.end(), 0) != definite_.end())
      return std::numeric_limits<double>::infinity();
    return residuals_.empty() ? 0.0 : *std::max_element(residuals_.begin(), residuals_.end());
  }

  std::vector<Eigen::MatrixXd> stiffnesses;
  std::vector<Eigen::VectorXd> scales;
  std::vector<long long> surplus;  // element zero modes beyond 6
  /// By local face: 1 for the faces between two region elements.
  std::vector<char> joins;

  /// An element's matrices and vectors, reused from element to element by a task.
  struct Scratch {
    Eigen::MatrixXd stiffness, a, selfBlock, otherBlock, backSelf, backOther;
    Eigen::VectorXd r, size, diagonal;
  };

  /// The IP matrix of joining face f's two elements with its terms, [K_front + S_0, O_0;
  /// O_1, K_back + S_1] (faceRows()' self and other blocks S and O by side: 0 the face's
  /// front element, 1 its back), into `pair`.
  void pairMatrix(FaceId f, Scratch& s, Eigen::MatrixXd& pair) const {
    const Face& face = local_.face(f);
    faceRows(local_, basis_, given_, faceView(f, face.front, face.back, true), form_, s.selfBlock,
             s.otherBlock);
    faceRows(local_, basis_, given_, faceView(f, face.back, face.front, false), form_, s.backSelf,
             s.backOther);
    pair.resize(2 * bs_, 2 * bs_);
    pair << stiffnesses[face.front.index()] + s.selfBlock, s.otherBlock, s.backOther,
        stiffnesses[face.back.index()] + s.backSelf;
  }

 private:
  /// Face f seen from element `self`: interior if `other` is valid, else a Dirichlet face.
  FaceView faceView(FaceId f, ElementId self, ElementId other, bool selfIsFront) const {
    FaceView view;
    view.face = f;
    view.kind = other.valid() ? FaceKind::Interior : FaceKind::Dirichlet;
    view.self = self;
    view.other = other;
    view.selfIsFront = selfIsFront;
    view.selfCoupledFaces = coupled(self);
    view.otherCoupledFaces = other.valid() ? coupled(other) : 0;
    return view;
  }

  /// Region element i's rows: r = A U - F over them, its block of A tested for definiteness.
  void addElement(std::size_t i, Scratch& s) {
    const ElementId e(i);
    const auto ue = coefficients(e);
    elementStiffness(basis_, given_, e, form_.mu, form_.lambda, s.stiffness);
    surplus[i] = static_cast<long long>(elementZeroModes(s.stiffness, degree_)) - 6;
    // r = A U - F over K's rows and, entry by entry, the size of the terms summed into it.
    s.a = s.stiffness;
    s.r = s.stiffness * ue;
    s.size = s.stiffness.cwiseAbs() * ue.cwiseAbs();
    s.diagonal = s.stiffness.diagonal();
    for (const FaceUse& use : local_.element(e).faces) addFace(e, use, s);
    // Relative to the largest term in K's rows: round-off in the sum stays below a few
    // machine epsilons of it, times the relative round-off of the matrices' entries.
    const double largest = s.size.maxCoeff();
    const double relative = largest > 0.0     ? s.r.cwiseAbs().maxCoeff() / largest
                            : s.r.isZero(0.0) ? 0.0
                                              : std::numeric_limits<double>::infinity();
    residuals_[i] = std::isfinite(relative) ? relative : std::numeric_limits<double>::infinity();
    // K's block of the IP matrix (every face with its terms) is SPD on a valid element.
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(s.a);
    for (const double d : ldlt.vectorD()) definite_[i] = definite_[i] && d > 0.0;
    scales[i] = zeroModeScaling(s.diagonal, bs_);
    stiffnesses[i] = s.stiffness;
  }

  Eigen::VectorXd::ConstSegmentReturnType coefficients(ElementId e) const {
    return exact_.segment(static_cast<Eigen::Index>(e.index()) * bs_, bs_);
  }
  // Every face of the full problem has face terms: c_K is the element's face count.
  int coupled(ElementId e) const { return static_cast<int>(local_.element(e).faces.size()); }

  /// Face `use` of element e: its terms in K's rows; a face between region elements is marked
  /// in `joins`.
  void addFace(ElementId e, const FaceUse& use, Scratch& s) {
    const auto ue = coefficients(e);
    const ElementId other = across(local_, use.face, e);
    faceRows(local_, basis_, given_, faceView(use.face, e, other, !use.reversed), form_,
             s.selfBlock, s.otherBlock);
    s.a += s.selfBlock;
    if (other.valid()) {
      // A Dirichlet face's S_F U_K is on both sides of A U = F: only its t_F is left below.
      const auto uo = coefficients(other);
      s.r.noalias() += s.selfBlock * ue + s.otherBlock * uo;
      s.size.noalias() +=
          s.selfBlock.cwiseAbs() * ue.cwiseAbs() + s.otherBlock.cwiseAbs() * uo.cwiseAbs();
      if (other.index() < regionSize_) {
        s.diagonal += s.selfBlock.diagonal();
        if (!use.reversed) joins[use.face.index()] = 1;  // written by one side only
      }
    } else {
      const Vec3 normal =
          use.reversed ? Vec3(-given_.faceNormal(use.face)) : given_.faceNormal(use.face);
      const Vec3 traction = stress_ * normal;
      const Eigen::VectorXd integrals = faceIntegrals(local_, basis_, use.face, e);
      for (int d = 0; d < 3; ++d) {
        s.r.segment(d * n_, n_) -= traction[d] * integrals;
        s.size.segment(d * n_, n_) += std::abs(traction[d]) * integrals.cwiseAbs();
      }
    }
  }

  const PolyMesh& local_;
  const std::size_t regionSize_;
  const DgBasis& basis_;
  const MomentCache& given_;
  const FormCoefficients& form_;
  const int degree_, n_, bs_;
  Eigen::VectorXd exact_;          ///< the linear field's coefficients on every element
  Eigen::Matrix3d stress_;         ///< its stress, constant
  std::vector<double> residuals_;  ///< each element's relative residual
  std::vector<char> definite_;     ///< each element's block positive definite
};

/// Zero modes: 6 per element (its own stiffness), and per face between region elements the
/// rigid motions it leaves free; components by union-find over the faces that join. Sets c's
/// components, zero modes and loose faces.
void countRegionZeroModes(const PolyMesh& local, const RegionRows& rows, int bs,
                          RegionCoupling coupling, RegionDgCheck& c) {
  const std::size_t regionSize = rows.stiffnesses.size();
  // Each joining face's pair of elements and its zero modes, on every core.
  std::vector<std::uint32_t> joining;
  for (std::size_t f = 0; f < rows.joins.size(); ++f)
    if (rows.joins[f]) joining.push_back(static_cast<std::uint32_t>(f));
  std::vector<std::size_t> pairModes(joining.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, joining.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      RegionRows::Scratch s;
                      Eigen::MatrixXd pair;
                      Eigen::VectorXd pairScale(2 * bs);
                      for (std::size_t k = range.begin(); k != range.end(); ++k) {
                        const FaceId f{std::size_t{joining[k]}};
                        const Face& face = local.face(f);
                        rows.pairMatrix(f, s, pair);
                        pairScale << rows.scales[face.front.index()],
                            rows.scales[face.back.index()];
                        pairModes[k] = countZeroModes(pair, pairScale);
                      }
                    });
  UnionFind sets(regionSize);
  std::vector<long long> faceSurplus;
  std::vector<std::uint32_t> faceFront;
  for (std::size_t k = 0; k < joining.size(); ++k) {
    const Face& face = local.face(FaceId(std::size_t(joining[k])));
    const std::size_t modes = pairModes[k];
    if (coupling == RegionCoupling::HoldingFaces && modes > 6) {
      ++c.looseFaces;
      continue;
    }
    sets.unite(face.front.value, face.back.value);
    // A face whose terms do not vanish on the rigid motions common to its two elements (fewer
    // than 6) takes zero modes from its component. AllFaces joins hinges too, without counting
    // their soft modes: a count over a component's cycles would take its global eigen-solve.
    faceSurplus.push_back(std::min(static_cast<long long>(modes) - 6, 0LL));
    faceFront.push_back(face.front.value);
  }
  std::vector<std::uint32_t> component;
  c.components = sets.labels(component);
  std::vector<long long> perComponent(c.components, 6);
  for (std::size_t i = 0; i < regionSize; ++i) perComponent[component[i]] += rows.surplus[i];
  for (std::size_t k = 0; k < faceSurplus.size(); ++k)
    perComponent[component[faceFront[k]]] += faceSurplus[k];
  for (const long long m : perComponent) {
    c.zeroModesPerComponent.push_back(static_cast<std::size_t>(std::max(m, 0LL)));
    c.zeroModes += c.zeroModesPerComponent.back();
  }
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
  // The region (local ids 0 .. regionSize-1), then its neighbours outside it.
  SubMesh sub(mesh);
  Box3 box;
  const std::size_t regionSize = copyRegion(mesh, region, sub, box);
  c.elements = regionSize;
  if (regionSize == 0) return c;
  const PolyMesh& local = sub.mesh();

  // 1. Moments: the caller's, copied to the sub-mesh (nothing integrated), and the region's
  //    recomputed from its geometry to compare.
  const int momentDegree = 2 * degree;
  MomentCache given(local, momentDegree);
  copyMoments(sub, moments, given);
  c.momentMismatch = momentMismatch(sub, regionSize, moments, momentDegree);

  // 2. The region's rows of the IP system at the linear field's coefficients, element by element.
  const DgBasis basis(local, given, options.basis);
  const FormCoefficients form{Method::IP, options.material.mu(), options.material.lambda(),
                              regionPenalty(sub, regionSize, basis, given)};
  RegionRows rows(local, regionSize, basis, given, form, box, degree);
  rows.addElements();
  c.patchTestResidual = rows.patchTestResidual();

  // 3. Zero modes per component of the region.
  countRegionZeroModes(local, rows, 3 * basis.size(), coupling, c);
  c.seconds = start.seconds();
  return c;
}

}  // namespace polydg
