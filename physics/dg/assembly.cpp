#include "physics/dg/assembly.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Eigenvalues>

#include "integrate/quadrature.h"
#include "physics/dg/block_rows.h"
#include "physics/dg/face_quadrature.h"
#include "polydg/util/error.h"
#include "util/resident.h"

namespace polydg {

namespace {

/// faceUses() one element after another: the reference order, and the error it throws.
FaceData<FaceUses> faceUsesInOrder(const PolyMesh& mesh) {
  FaceData<FaceUses> uses(mesh.numFaces());
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const ElementId e(i);
    for (const FaceUse& use : mesh.element(e).faces) {
      FaceUses& u = uses[use.face];
      if (u.count == 2)
        throw std::invalid_argument("face " + std::to_string(use.face.value) +
                                    " is used by more than two elements");
      if (u.count == 1 && u.reversed[0] == use.reversed)
        throw std::invalid_argument("face " + std::to_string(use.face.value) +
                                    " is used twice with the same orientation");
      u.element[u.count] = e;
      u.reversed[u.count] = use.reversed;
      ++u.count;
    }
  }
  return uses;
}

}  // namespace

FaceData<FaceUses> faceUses(const PolyMesh& mesh) {
  // On both cores: each use takes the next of its face's two slots, then a face's two uses are
  // put in element order, as faceUsesInOrder() finds them. A face used wrongly (a third time,
  // or twice the same way) is rare: the serial pass then says which, as it always did.
  FaceData<FaceUses> uses;
  growResident(uses.raw(), mesh.numFaces());
  std::atomic<bool> wrong{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numElements(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const ElementId e(i);
                        for (const FaceUse& use : mesh.element(e).faces) {
                          FaceUses& u = uses[use.face];
                          const int slot =
                              std::atomic_ref<int>(u.count).fetch_add(1, std::memory_order_relaxed);
                          if (slot >= 2) {
                            wrong.store(true, std::memory_order_relaxed);
                            continue;
                          }
                          u.element[slot] = e;
                          u.reversed[slot] = use.reversed;
                        }
                      }
                    });
  if (wrong.load()) return faceUsesInOrder(mesh);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f) {
                        FaceUses& u = uses[FaceId(f)];
                        if (u.count < 2) continue;
                        if (u.reversed[0] == u.reversed[1])
                          wrong.store(true, std::memory_order_relaxed);
                        if (u.element[1].value < u.element[0].value) {
                          std::swap(u.element[0], u.element[1]);
                          std::swap(u.reversed[0], u.reversed[1]);
                        }
                      }
                    });
  if (wrong.load()) return faceUsesInOrder(mesh);
  return uses;
}

FaceRoles classifyFaces(const PolyMesh& mesh, const LoadCase& loads) {
  FaceRoles roles;
  roles.uses = faceUses(mesh);
  const std::size_t nf = mesh.numFaces();
  roles.kind.resize(nf, FaceKind::Free);
  roles.dirichlet.resize(nf, -1);
  roles.traction.resize(nf, -1);
  roles.coupledFaces.resize(mesh.numElements(), 0);
  const double diagonal = meshBounds(mesh).diagonal().norm();
  struct Counts {
    std::size_t interior = 0, dirichlet = 0, traction = 0;
  };
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nf, 4096), Counts{},
      [&](const tbb::blocked_range<std::size_t>& r, Counts c) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const FaceId f(i);
          const FaceUses& u = roles.uses[f];
          if (u.count == 2) {
            roles.kind[f] = FaceKind::Interior;
            ++c.interior;
            continue;
          }
          if (u.count == 0) continue;  // unused face: no terms
          for (std::size_t k = 0; k < loads.dirichlet.size(); ++k)
            if (selects(loads.dirichlet[k].where, mesh, f, diagonal)) {
              roles.kind[f] = FaceKind::Dirichlet;
              roles.dirichlet[f] = static_cast<int>(k);
              ++c.dirichlet;
              break;
            }
          if (roles.kind[f] == FaceKind::Dirichlet) continue;
          for (std::size_t k = 0; k < loads.tractions.size(); ++k)
            if (selects(loads.tractions[k].where, mesh, f, diagonal)) {
              roles.traction[f] = static_cast<int>(k);
              ++c.traction;
              break;
            }
        }
        return c;
      },
      [](Counts a, const Counts& b) {
        a.interior += b.interior;
        a.dirichlet += b.dirichlet;
        a.traction += b.traction;
        return a;
      });
  roles.interiorFaces = counts.interior;
  roles.dirichletFaces = counts.dirichlet;
  roles.tractionFaces = counts.traction;
  // c_K: the uses of faces with terms, counted per element (a face an element uses twice
  // counts twice, as it has two uses).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numElements(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        int coupled = 0;
                        for (const FaceUse& use : mesh.element(ElementId(i)).faces)
                          coupled += roles.kind[use.face] != FaceKind::Free;
                        roles.coupledFaces[ElementId(i)] = coupled;
                      }
                    });
  return roles;
}

namespace {

/// The view of face `f` from side `s` of its uses.
FaceView viewOf(const FaceRoles& roles, FaceId f, int s) {
  const FaceUses& u = roles.uses[f];
  FaceView v;
  v.face = f;
  v.kind = roles.kind[f];
  v.self = u.element[s];
  v.selfIsFront = !u.reversed[s];
  v.selfCoupledFaces = roles.coupledFaces[v.self];
  if (u.count == 2) {
    v.other = u.element[1 - s];
    v.otherCoupledFaces = roles.coupledFaces[v.other];
  }
  return v;
}

/// The largest eigenvalue of the symmetric matrix `a`. Fixed sizes for the penalty bound's
/// 6 numMonomials(p - 1) (p = 1, 2, 3): Eigen's dynamic-size solver spent a sixth of the
/// p = 2 assembly time.
template <int D>
double largestEigenvalue(const Eigen::MatrixXd& a) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig(
      Eigen::Matrix<double, D, D>(a), Eigen::EigenvaluesOnly);
  return eig.eigenvalues().maxCoeff();
}

double largestEigenvalue(const Eigen::MatrixXd& a) {
  switch (a.rows()) {
    case 6: return largestEigenvalue<6>(a);
    case 24: return largestEigenvalue<24>(a);
    case 60: return largestEigenvalue<60>(a);
    default: {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a, Eigen::EigenvaluesOnly);
      return eig.eigenvalues().maxCoeff();
    }
  }
}

/// Side index of element e at face f.
int sideOf(const FaceRoles& roles, FaceId f, ElementId e) {
  return roles.uses[f].element[0] == e ? 0 : 1;
}

}  // namespace

double penaltyThreshold(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                        const FaceRoles& roles) {
  const ElementData<double> required = elementPenaltyThresholds(
      mesh, basis, moments, roles, meanCoupledFaceAreas(mesh, moments, roles));
  return required.size() == 0 ? 0.0 : *std::max_element(required.begin(), required.end());
}

ElementData<double> meanCoupledFaceAreas(const PolyMesh& mesh, const MomentCache& moments,
                                         const FaceRoles& roles) {
  ElementData<double> mean(mesh.numElements(), 0.0);
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const ElementId e(i);
    double sum = 0.0;
    int count = 0;
    for (const FaceUse& use : mesh.element(e).faces) {
      if (roles.kind[use.face] == FaceKind::Free) continue;
      const double area = moments.area(use.face);
      if (!(area > 0.0)) continue;
      sum += area;
      ++count;
    }
    if (count > 0) mean[e] = sum / count;
  }
  return mean;
}

ElementData<double> elementPenaltyThresholds(const PolyMesh& mesh, const DgBasis& basis,
                                             const MomentCache& moments, const FaceRoles& roles,
                                             const ElementData<double>& meanArea) {
  const std::size_t ne = mesh.numElements();
  const int n1 = basis.liftingSize();
  const int dim = 6 * n1;
  // Strain vector (e11, e22, e33, e12, e13, e23): |eps|^2 = e11^2 + e22^2 + e33^2 +
  // 2 (e12^2 + e13^2 + e23^2); W^(-1/2) turns it into the Euclidean norm.
  const double invSqrtW[6] = {1, 1, 1, 1 / std::sqrt(2.0), 1 / std::sqrt(2.0), 1 / std::sqrt(2.0)};
  ElementData<double> required(ne, 0.0);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    const double volume = moments.volume(e);
    Eigen::MatrixXd form = Eigen::MatrixXd::Zero(dim, dim);
    bool any = false;
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceKind kind = roles.kind[use.face];
      if (kind == FaceKind::Free) continue;
      const double area = moments.area(use.face);
      if (!(area > 0.0)) continue;
      any = true;
      const double w2 = kind == FaceKind::Interior ? 0.25 : 1.0;
      const Vec3 nrm =
          use.reversed ? Vec3(-moments.faceNormal(use.face)) : moments.faceNormal(use.face);
      // N: strain vector -> eps n, scaled by W^(-1/2).
      Eigen::Matrix<double, 3, 6> nmap;
      nmap << nrm.x(), 0, 0, nrm.y(), nrm.z(), 0,  //
          0, nrm.y(), 0, nrm.x(), 0, nrm.z(),      //
          0, 0, nrm.z(), 0, nrm.x(), nrm.y();
      for (int c = 0; c < 6; ++c) nmap.col(c) *= invSqrtW[c];
      const Eigen::Matrix<double, 6, 6> sn = nmap.transpose() * nmap;
      const Eigen::MatrixXd g = liftingFaceGram(basis, moments, mesh, use.face, e);
      const double weight = w2 * volume / meanArea[e];
      for (int q = 0; q < n1; ++q)
        for (int r = 0; r < n1; ++r) form.block<6, 6>(6 * q, 6 * r) += (weight * g(q, r)) * sn;
    }
    if (!any) return;
    const double tau = largestEigenvalue(form);
    required[e] = 2.0 * tau / kConsistencyEnergyShare;
  });
  return required;
}

std::vector<std::vector<std::uint32_t>> coupledNeighbours(const PolyMesh& mesh,
                                                          const FaceRoles& roles) {
  std::vector<std::vector<std::uint32_t>> neighbours(mesh.numElements());
  tbb::parallel_for(std::size_t(0), mesh.numElements(), [&](std::size_t i) {
    const ElementId e(i);
    auto& b = neighbours[i];
    b.push_back(e.value);
    for (const FaceUse& use : mesh.element(e).faces) {
      if (roles.kind[use.face] != FaceKind::Interior) continue;
      const FaceUses& u = roles.uses[use.face];
      b.push_back(u.element[0] == e ? u.element[1].value : u.element[0].value);
    }
    std::sort(b.begin(), b.end());
    b.erase(std::unique(b.begin(), b.end()), b.end());
  });
  return neighbours;
}

namespace {

/// The rows of each element (of `only`, if not empty) of a form with a choice of terms: the element
/// stiffness if `element`, the face terms `diagonalTerms` (FaceTerms bits) in the diagonal blocks
/// and `couplingTerms` in the coupling blocks. For each element e, in parallel, store(e, diagonal,
/// coupling) receives e's diagonal block (bs x bs, column-major) and its coupling blocks with its
/// neighbours f > e (in the order of `neighbours`, each bs x bs row-major: column (e, c) of K reads
/// row c of the block), in a scratch buffer.
template <class Store>
void forEachElementRows(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                        const FaceRoles& roles, const FormCoefficients& form,
                        const std::vector<std::vector<std::uint32_t>>& neighbours, bool element,
                        int diagonalTerms, int couplingTerms, bool dirichletFaces,
                        std::span<const std::uint32_t> only, Store&& store) {
  const int bs = 3 * basis.size();
  const std::size_t bb = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, only.empty() ? mesh.numElements() : only.size(), 16),
      [&](const tbb::blocked_range<std::size_t>& r) {
        Eigen::MatrixXd self, faceSelf, faceOther;
        std::vector<double> coupling;
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          const std::size_t i = only.empty() ? k : only[k];
          const ElementId e(i);
          const auto& b = neighbours[i];
          const auto firstGreater = std::upper_bound(b.begin(), b.end(), e.value);
          coupling.assign(static_cast<std::size_t>(b.end() - firstGreater) * bb, 0.0);
          if (element)
            elementStiffness(basis, moments, e, form.mu, form.lambda, self);
          else
            self.setZero(bs, bs);
          for (const FaceUse& use : mesh.element(e).faces) {
            const FaceKind kind = roles.kind[use.face];
            if (kind == FaceKind::Free || (kind == FaceKind::Dirichlet && !dirichletFaces))
              continue;
            const FaceView view = viewOf(roles, use.face, sideOf(roles, use.face, e));
            // The coupling block of a face is computed from its smaller element only.
            const bool withOther =
                kind == FaceKind::Interior && view.other.value > e.value && couplingTerms != 0;
            if (diagonalTerms == couplingTerms || !withOther) {
              if (diagonalTerms == 0 && !withOther) continue;
              faceRows(mesh, basis, moments, view, form, faceSelf, faceOther, withOther,
                       diagonalTerms == 0 ? couplingTerms : diagonalTerms);
              if (diagonalTerms != 0) self += faceSelf;
            } else {  // different terms: two passes
              if (diagonalTerms != 0) {
                faceRows(mesh, basis, moments, view, form, faceSelf, faceOther, false,
                         diagonalTerms);
                self += faceSelf;
              }
              faceRows(mesh, basis, moments, view, form, faceSelf, faceOther, true, couplingTerms);
            }
            if (!withOther) continue;
            const auto t = std::lower_bound(firstGreater, b.end(), view.other.value) - firstGreater;
            // Row-major: column (e, c) of K reads row c of the block.
            Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                coupling.data() + static_cast<std::size_t>(t) * bb, bs, bs) += faceOther;
          }
          store(i, self, coupling.data());
        }
      });
}

/// Element i's diagonal block and coupling blocks (forEachElementRows()' store) where `local`'s
/// layout puts them.
void storeElementRows(LocalMatrices& local, std::size_t i, const Eigen::MatrixXd& self,
                      const double* coupling) {
  const std::size_t bb =
      static_cast<std::size_t>(local.blockSize) * static_cast<std::size_t>(local.blockSize);
  Eigen::Map<Eigen::MatrixXd>(local.diagonal.data() + i * bb, self.rows(), self.cols()) = self;
  std::copy(coupling, coupling + greaterNeighbours(local.neighbours, i) * bb,
            local.coupling.data() + local.couplingStart[i] * bb);
}

/// localMatrices() with a choice of terms (forEachElementRows()).
LocalMatrices localMatricesOf(const PolyMesh& mesh, const DgBasis& basis,
                              const MomentCache& moments, const FaceRoles& roles,
                              const FormCoefficients& form, bool element, int diagonalTerms,
                              int couplingTerms, bool dirichletFaces = true) {
  const std::size_t ne = mesh.numElements();
  LocalMatrices local;
  local.functions = basis.size();
  local.blockSize = 3 * local.functions;
  local.componentDiagonalCoupling = form.method == Method::BZ;
  const std::size_t bb =
      static_cast<std::size_t>(local.blockSize) * static_cast<std::size_t>(local.blockSize);
  local.neighbours = coupledNeighbours(mesh, roles);
  local.couplingStart.assign(ne + 1, 0);
  for (std::size_t i = 0; i < ne; ++i)
    local.couplingStart[i + 1] = local.couplingStart[i] + greaterNeighbours(local.neighbours, i);
  local.diagonal.resize(ne * bb);
  local.coupling.resize(local.couplingStart[ne] * bb);
  forEachElementRows(mesh, basis, moments, roles, form, local.neighbours, element, diagonalTerms,
                     couplingTerms, dirichletFaces, {},
                     [&](std::size_t i, const Eigen::MatrixXd& self, const double* coupling) {
                       storeElementRows(local, i, self, coupling);
                     });
  return local;
}

}  // namespace

BlockRows<double> assembleBlockRows(const PolyMesh& mesh, const DgBasis& basis,
                                    const MomentCache& moments, const FaceRoles& roles,
                                    const FormCoefficients& form) {
  const std::vector<std::vector<std::uint32_t>> neighbours = coupledNeighbours(mesh, roles);
  BlockRows<double> rows = blockRowsLayout(neighbours, basis.size(), form.method == Method::BZ);
  forEachElementRows(mesh, basis, moments, roles, form, neighbours, true, kAllFaceTerms,
                     kAllFaceTerms, true, {},
                     [&](std::size_t e, const Eigen::MatrixXd& self, const double* coupling) {
                       writeElementRows(rows, neighbours, e, self.data(), coupling);
                     });
  return rows;
}

BlockRows<double> blockRowsLayout(const LocalMatrices& local) {
  return blockRowsLayout(local.neighbours, local.functions, local.componentDiagonalCoupling);
}

LocalMatrices localMatrices(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const FaceRoles& roles, const FormCoefficients& form) {
  return localMatricesOf(mesh, basis, moments, roles, form, true, kAllFaceTerms, kAllFaceTerms);
}

void writeSplitRows(SplitLocalMatrices& split, const PolyMesh& mesh, const DgBasis& basis,
                    const MomentCache& moments, const FaceRoles& roles,
                    const FormCoefficients& form, std::span<const std::uint32_t> elements) {
  const int bs = split.jumps.blockSize;
  const std::size_t bb = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  const auto& neighbours = split.jumps.neighbours;
  // Strain of the rows' element, of the columns' element, and none (the penalty).
  const std::tuple<LocalMatrices*, bool, int, int, bool> parts[] = {
      {&split.rowStrain, true, kTrialStrainTerms | kTestStrainTerms, kTestStrainTerms, false},
      {&split.columnStrain, false, 0, kTrialStrainTerms | kOtherLiftingTerms, true},
      {&split.jumps, false, kJumpTerms, kJumpTerms, true}};
  for (const auto& [local, element, diagonalTerms, couplingTerms, dirichletFaces] : parts)
    forEachElementRows(
        mesh, basis, moments, roles, form, neighbours, element, diagonalTerms, couplingTerms,
        dirichletFaces, elements,
        [&, local = local](std::size_t i, const Eigen::MatrixXd& self, const double* coupling) {
          storeElementRows(*local, i, self, coupling);
        });
  // The neighbours' lifting terms in each diagonal block, one block per neighbour, and the
  // Dirichlet faces' strain terms.
  tbb::parallel_for(std::size_t(0), elements.size(), [&](std::size_t k) {
    const std::size_t i = elements[k];
    const std::size_t lifting = neighbours[i].size() - 1;
    double* nl = split.neighbourLifting.data() + split.neighbourStart[i] * bb;
    std::fill(nl, nl + lifting * bb, 0.0);
    for (UninitializedVector<double>* dir : {&split.dirichletTrial, &split.dirichletTest})
      std::fill(dir->data() + i * bb, dir->data() + (i + 1) * bb, 0.0);
    if (form.method != Method::IP) return;
    Eigen::MatrixXd faceSelf, faceOther;
    const ElementId e(i);
    const auto& b = neighbours[i];
    for (const FaceUse& use : mesh.element(e).faces) {
      if (roles.kind[use.face] == FaceKind::Dirichlet) {
        const FaceView view = viewOf(roles, use.face, sideOf(roles, use.face, e));
        for (auto [terms, out] : {std::pair{kTrialStrainTerms, &split.dirichletTrial},
                                  std::pair{kTestStrainTerms, &split.dirichletTest}}) {
          faceRows(mesh, basis, moments, view, form, faceSelf, faceOther, false, terms);
          Eigen::Map<Eigen::MatrixXd>(out->data() + i * bb, bs, bs) += faceSelf;
        }
        continue;
      }
      if (roles.kind[use.face] != FaceKind::Interior) continue;
      const FaceView view = viewOf(roles, use.face, sideOf(roles, use.face, e));
      faceRows(mesh, basis, moments, view, form, faceSelf, faceOther, false, kOtherLiftingTerms);
      // Slot of the neighbour among e's neighbours without e itself.
      auto t = static_cast<std::size_t>(std::lower_bound(b.begin(), b.end(), view.other.value) -
                                        b.begin());
      if (view.other.value > e.value) --t;
      Eigen::Map<Eigen::MatrixXd>(nl + t * bb, bs, bs) += faceSelf;
    }
  });
}

Eigen::SparseMatrix<double, Eigen::ColMajor, int> assembleStiffness(const LocalMatrices& local) {
  const std::size_t ne = local.neighbours.size();
  const int bs = local.blockSize;
  const int n = local.functions;
  const bool bz = local.componentDiagonalCoupling;

  // Column pointers: column (e, c) holds all 3n rows of e and of IP neighbours, n rows of
  // BZ neighbours (component c only).
  const std::size_t ndof = ne * static_cast<std::size_t>(bs);
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> k(static_cast<int>(ndof),
                                                      static_cast<int>(ndof));
  std::vector<std::int64_t> columnStart(ndof + 1, 0);
  {
    std::size_t pos = 0;
    for (std::size_t i = 0; i < ne; ++i) {
      const std::size_t neighbours = local.neighbours[i].size() - 1;
      const std::size_t perColumn = static_cast<std::size_t>(bs) + neighbours * (bz ? n : bs);
      for (int c = 0; c < bs; ++c) {
        columnStart[i * bs + c] = static_cast<std::int64_t>(pos);
        pos += perColumn;
      }
    }
    columnStart[ndof] = static_cast<std::int64_t>(pos);
    if (pos > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw std::length_error("assembleStiffness: more than 2^31 nonzeros");
  }
  k.resizeNonZeros(static_cast<Eigen::Index>(columnStart[ndof]));
  adviseHugePages(k.valuePtr(), static_cast<std::size_t>(columnStart[ndof]) * sizeof(double));
  adviseHugePages(k.innerIndexPtr(), static_cast<std::size_t>(columnStart[ndof]) * sizeof(int));
  int* outer = k.outerIndexPtr();
  for (std::size_t c = 0; c <= ndof; ++c) outer[c] = static_cast<int>(columnStart[c]);
  refillStiffness(local, k);
  return k;
}

void refillStiffness(const LocalMatrices& local,
                     Eigen::SparseMatrix<double, Eigen::ColMajor, int>& k) {
  const std::size_t ne = local.neighbours.size();
  const int bs = local.blockSize;
  const int n = local.functions;
  const bool bz = local.componentDiagonalCoupling;
  const std::size_t bb = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  if (static_cast<std::size_t>(k.cols()) != ne * static_cast<std::size_t>(bs))
    throw std::invalid_argument("refillStiffness: the matrix has another size");
  const int* columnStart = k.outerIndexPtr();
  int* inner = k.innerIndexPtr();
  double* values = k.valuePtr();

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, ne, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const auto& b = local.neighbours[i];
          // Where each neighbour block of e's rows is, and its stride along a row: the
          // diagonal block (symmetric: row c is column c), e's own coupling blocks (row-major)
          // and, for smaller neighbours f, the transpose of f's block (row c of it is column c
          // of f's row-major block).
          struct Source {
            const double* row0;
            std::size_t rowStep, entryStep;
            int base;
          };
          Source sources[64];
          std::vector<Source> many;
          Source* src = b.size() <= 64 ? sources : (many.resize(b.size()), many.data());
          std::size_t own = 0;
          for (std::size_t t = 0; t < b.size(); ++t) {
            const std::size_t f = b[t];
            const int base = static_cast<int>(f) * bs;
            if (f == i) {
              src[t] = {local.diagonal.data() + i * bb, static_cast<std::size_t>(bs), 1, base};
            } else if (f > i) {
              src[t] = {local.coupling.data() + (local.couplingStart[i] + own++) * bb,
                        static_cast<std::size_t>(bs), 1, base};
            } else {
              const auto& bf = local.neighbours[f];
              const auto firstGreater =
                  std::upper_bound(bf.begin(), bf.end(), static_cast<std::uint32_t>(f));
              const std::size_t slot = static_cast<std::size_t>(
                  std::lower_bound(firstGreater, bf.end(), static_cast<std::uint32_t>(i)) -
                  firstGreater);
              src[t] = {local.coupling.data() + (local.couplingStart[f] + slot) * bb, 1,
                        static_cast<std::size_t>(bs), base};
            }
          }
          for (int c = 0; c < bs; ++c) {
            std::int64_t pos = columnStart[i * bs + c];
            const std::int64_t end = columnStart[i * bs + c + 1];
            for (std::size_t t = 0; t < b.size(); ++t) {
              const Source& s = src[t];
              const double* row = s.row0 + static_cast<std::size_t>(c) * s.rowStep;
              int first = 0, last = bs;
              if (b[t] != i && bz) {  // BZ neighbours: component c / n only
                first = (c / n) * n;
                last = first + n;
              }
              if (pos + (last - first) > end)
                throw std::invalid_argument("refillStiffness: the matrix has another pattern");
              for (int d = first; d < last; ++d) {
                inner[pos] = s.base + d;
                values[pos++] = row[static_cast<std::size_t>(d) * s.entryStep];
              }
            }
          }
        }
      });
}

Eigen::SparseMatrix<double, Eigen::ColMajor, int> assembleStiffness(const PolyMesh& mesh,
                                                                    const DgBasis& basis,
                                                                    const MomentCache& moments,
                                                                    const FaceRoles& roles,
                                                                    const FormCoefficients& form) {
  return assembleStiffness(localMatrices(mesh, basis, moments, roles, form));
}

Eigen::VectorXd assembleLoad(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                             const FaceRoles& roles, const FormCoefficients& form,
                             const Material& material, const LoadCase& loads,
                             int quadratureDegree) {
  const std::size_t ne = mesh.numElements();
  const int n = basis.size();
  const int n1 = basis.liftingSize();
  const int bs = 3 * n;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(ne * bs));
  const Vec3 gravityForce = material.density * loads.gravity;
  const bool ip = form.method == Method::IP;

  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    Eigen::Map<Eigen::VectorXd> fe(f.data() + i * bs, bs);
    std::vector<double> phi(n), grad(3 * n), psi(n1);

    // Constant body force: int phi_i from the moments.
    if (gravityForce != Vec3::Zero()) {
      const auto t = basis.coefficients(e);
      const auto m = moments.element(e);
      const double h = basis.scale(e);
      for (int a = 0; a < n; ++a) {
        const double ma = m[a] / std::pow(h, monomialExponents(a).degree());
        for (int r = a; r < n; ++r)
          for (int d = 0; d < 3; ++d) fe[d * n + r] += gravityForce[d] * t(r, a) * ma;
      }
    }
    if (loads.bodyForce) {
      for (const QuadraturePoint& q : elementQuadrature(mesh, e, quadratureDegree)) {
        const Vec3 b = loads.bodyForce(q.point);
        basis.values(e, q.point, phi);
        for (int d = 0; d < 3; ++d)
          for (int r = 0; r < n; ++r) fe[d * n + r] += q.weight * b[d] * phi[r];
      }
    }
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceId fid = use.face;
      const int tr = roles.traction[fid];
      if (tr >= 0) {
        const Vec3 t = loads.tractions[tr].traction;
        for (const QuadraturePoint& q : faceQuadrature(mesh, fid, basis.degree())) {
          basis.values(e, q.point, phi);
          for (int d = 0; d < 3; ++d)
            for (int r = 0; r < n; ++r) fe[d * n + r] += q.weight * t[d] * phi[r];
        }
      }
      if (roles.kind[fid] != FaceKind::Dirichlet) continue;
      const VectorField& g = loads.dirichlet[roles.dirichlet[fid]].displacement;
      if (!g) continue;  // an empty field means g = 0: no right-hand side
      const Vec3 normal = use.reversed ? Vec3(-moments.faceNormal(fid)) : moments.faceNormal(fid);
      const double etaF = facePenalty(form, moments, fid, e, ElementId());
      const double etaMean = faceMeanPenalty(form, moments, fid, e, ElementId());
      const double mu = form.mu, lambda = form.lambda;
      const double cK = roles.coupledFaces[e];
      const auto rule = faceQuadrature(mesh, fid, quadratureDegree);
      // Lifting: b_q(g) = int psi_q g.n and the face matrix int psi_q phi_i.
      Eigen::VectorXd bg = Eigen::VectorXd::Zero(n1);
      Eigen::MatrixXd mpsi = Eigen::MatrixXd::Zero(n1, n);
      const auto o = basis.liftingCoefficients(e);
      // The face mean's extra penalty (faceMeanPenalty()): |F|^-1 int_F g . int_F phi.
      Vec3 gMean = Vec3::Zero();
      Eigen::VectorXd phiMean = Eigen::VectorXd::Zero(n);
      for (const QuadraturePoint& q : rule) {
        const Vec3 gx = g(q.point);
        basis.values(e, q.point, phi);
        for (int d = 0; d < 3; ++d)
          for (int r = 0; r < n; ++r) fe[d * n + r] += q.weight * mu * etaF * gx[d] * phi[r];
        if (etaMean != 0.0) {
          gMean += q.weight * gx;
          for (int r = 0; r < n; ++r) phiMean[r] += q.weight * phi[r];
        }
        if (!ip) continue;
        basis.gradients(e, q.point, grad);
        const double gn = gx.dot(normal);
        for (int r = 0; r < n; ++r) {
          const Vec3 gp(grad[r], grad[n + r], grad[2 * n + r]);
          const double dn = gp.dot(normal), dg = gp.dot(gx);
          for (int d = 0; d < 3; ++d)
            fe[d * n + r] -= q.weight * (mu * (gx[d] * dn + dg * normal[d]) + lambda * gp[d] * gn);
        }
        // psi_q = sum_a o(q, a) m_a: the lifting basis is a combination of the first n1
        // scaled monomials.
        double m[numMonomials(3)];
        scaledMonomials(basis.degree() - 1, (q.point - basis.centre(e)) / basis.scale(e),
                        {m, static_cast<std::size_t>(n1)});
        for (int a = 0; a < n1; ++a) {
          double s = 0.0;
          for (int c = 0; c <= a; ++c) s += o(a, c) * m[c];
          psi[a] = s;
        }
        for (int a = 0; a < n1; ++a) {
          bg[a] += q.weight * psi[a] * gn;
          for (int r = 0; r < n; ++r) mpsi(a, r) += q.weight * psi[a] * phi[r];
        }
      }
      if (etaMean != 0.0) {
        const double c = mu * etaMean / moments.area(fid);
        for (int d = 0; d < 3; ++d)
          for (int r = 0; r < n; ++r) fe[d * n + r] += c * gMean[d] * phiMean[r];
      }
      if (ip && lambda != 0.0) {
        const Eigen::VectorXd lift = mpsi.transpose() * bg;  // sum_q b_q(g) int psi_q phi_r
        for (int d = 0; d < 3; ++d)
          for (int r = 0; r < n; ++r) fe[d * n + r] += lambda * cK * normal[d] * lift[r];
      }
    }
  });
  // A load that overflows (a traction or gravity near 1e308, or times a large density) would
  // make CG stop at once on an infinite residual and report the zero displacement as converged.
  if (!f.allFinite())
    throw InputError(
        "the loads overflow double precision (a traction, gravity times the density, or a "
        "prescribed displacement is too large); scale them or the model's units down");
  return f;
}

}  // namespace polydg
