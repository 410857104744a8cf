#include "physics/assembly.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <tbb/parallel_for.h>

#include "integrate/quadrature.h"
#include "physics/face_quadrature.h"

namespace polydg {

FaceData<FaceUses> faceUses(const PolyMesh& mesh) {
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

FaceRoles classifyFaces(const PolyMesh& mesh, const LoadCase& loads) {
  FaceRoles roles;
  roles.uses = faceUses(mesh);
  const std::size_t nf = mesh.numFaces();
  roles.kind.resize(nf, FaceKind::Free);
  roles.dirichlet.resize(nf, -1);
  roles.traction.resize(nf, -1);
  roles.coupledFaces.resize(mesh.numElements(), 0);
  const double diagonal = meshBounds(mesh).diagonal().norm();
  for (std::size_t i = 0; i < nf; ++i) {
    const FaceId f(i);
    const FaceUses& u = roles.uses[f];
    if (u.count == 2) {
      roles.kind[f] = FaceKind::Interior;
      ++roles.interiorFaces;
      continue;
    }
    if (u.count == 0) continue;  // unused face: no terms
    for (std::size_t c = 0; c < loads.dirichlet.size(); ++c)
      if (selects(loads.dirichlet[c].where, mesh, f, diagonal)) {
        roles.kind[f] = FaceKind::Dirichlet;
        roles.dirichlet[f] = static_cast<int>(c);
        ++roles.dirichletFaces;
        break;
      }
    if (roles.kind[f] == FaceKind::Dirichlet) continue;
    for (std::size_t c = 0; c < loads.tractions.size(); ++c)
      if (selects(loads.tractions[c].where, mesh, f, diagonal)) {
        roles.traction[f] = static_cast<int>(c);
        ++roles.tractionFaces;
        break;
      }
  }
  for (std::size_t i = 0; i < nf; ++i) {
    const FaceId f(i);
    if (roles.kind[f] == FaceKind::Free) continue;
    const FaceUses& u = roles.uses[f];
    for (int s = 0; s < u.count; ++s) ++roles.coupledFaces[u.element[s]];
  }
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

/// Side index of element e at face f.
int sideOf(const FaceRoles& roles, FaceId f, ElementId e) {
  return roles.uses[f].element[0] == e ? 0 : 1;
}

}  // namespace

double penaltyThreshold(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                        const FaceRoles& roles) {
  const ElementData<double> required = elementPenaltyThresholds(mesh, basis, moments, roles);
  return required.size() == 0 ? 0.0 : *std::max_element(required.begin(), required.end());
}

ElementData<double> elementPenaltyThresholds(const PolyMesh& mesh, const DgBasis& basis,
                                             const MomentCache& moments, const FaceRoles& roles) {
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
      const Vec3 nrm = use.reversed ? Vec3(-moments.faceNormal(use.face))
                                    : moments.faceNormal(use.face);
      // N: strain vector -> eps n, scaled by W^(-1/2).
      Eigen::Matrix<double, 3, 6> nmap;
      nmap << nrm.x(), 0, 0, nrm.y(), nrm.z(), 0,  //
          0, nrm.y(), 0, nrm.x(), 0, nrm.z(),      //
          0, 0, nrm.z(), 0, nrm.x(), nrm.y();
      for (int c = 0; c < 6; ++c) nmap.col(c) *= invSqrtW[c];
      const Eigen::Matrix<double, 6, 6> sn = nmap.transpose() * nmap;
      const Eigen::MatrixXd g = liftingFaceGram(basis, moments, mesh, use.face, e);
      const double weight = w2 * volume / area;
      for (int q = 0; q < n1; ++q)
        for (int r = 0; r < n1; ++r) form.block<6, 6>(6 * q, 6 * r) += (weight * g(q, r)) * sn;
    }
    if (!any) return;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(form, Eigen::EigenvaluesOnly);
    const double tau = eig.eigenvalues().maxCoeff();
    required[e] = 2.0 * tau / kConsistencyEnergyShare;
  });
  return required;
}

Eigen::SparseMatrix<double, Eigen::ColMajor, int> assembleStiffness(
    const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
    const FaceRoles& roles, const FormCoefficients& form) {
  const std::size_t ne = mesh.numElements();
  const int n = basis.size();
  const int bs = 3 * n;
  const bool bz = form.method == Method::BZ;

  // Neighbours of each element (sorted, with self), through coupled interior faces.
  std::vector<std::vector<std::uint32_t>> blocks(ne);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    auto& b = blocks[i];
    b.push_back(e.value);
    for (const FaceUse& use : mesh.element(e).faces) {
      if (roles.kind[use.face] != FaceKind::Interior) continue;
      const FaceUses& u = roles.uses[use.face];
      b.push_back(u.element[0] == e ? u.element[1].value : u.element[0].value);
    }
    std::sort(b.begin(), b.end());
    b.erase(std::unique(b.begin(), b.end()), b.end());
  });

  // Column pointers: column (e, c, j) holds all 3n rows of e and of IP neighbours, n rows of
  // BZ neighbours (component c only).
  const std::size_t ndof = ne * bs;
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> k(static_cast<int>(ndof),
                                                      static_cast<int>(ndof));
  std::vector<std::int64_t> columnStart(ndof + 1, 0);
  {
    std::size_t pos = 0;
    for (std::size_t i = 0; i < ne; ++i) {
      const std::size_t neighbours = blocks[i].size() - 1;
      const std::size_t perColumn = bs + neighbours * (bz ? n : bs);
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
  int* outer = k.outerIndexPtr();
  for (std::size_t c = 0; c <= ndof; ++c) outer[c] = static_cast<int>(columnStart[c]);
  int* inner = k.innerIndexPtr();
  double* values = k.valuePtr();

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, ne, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        Eigen::MatrixXd self, faceSelf, faceOther;
        std::vector<Eigen::MatrixXd> other;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const ElementId e(i);
          const auto& b = blocks[i];
          elementStiffness(basis, moments, e, form.mu, form.lambda, self);
          other.assign(b.size(), Eigen::MatrixXd::Zero(bs, bs));
          for (const FaceUse& use : mesh.element(e).faces) {
            const FaceKind kind = roles.kind[use.face];
            if (kind == FaceKind::Free) continue;
            const FaceView view = viewOf(roles, use.face, sideOf(roles, use.face, e));
            faceRows(mesh, basis, moments, view, form, faceSelf, faceOther);
            self += faceSelf;
            if (kind == FaceKind::Interior) {
              const auto it = std::lower_bound(b.begin(), b.end(), view.other.value);
              other[it - b.begin()] += faceOther;
            }
          }
          // Column (e, c) of K equals row (e, c): the rows of e's local blocks.
          for (int c = 0; c < bs; ++c) {
            std::int64_t pos = columnStart[i * bs + c];
            for (std::size_t t = 0; t < b.size(); ++t) {
              const std::size_t base = static_cast<std::size_t>(b[t]) * bs;
              const Eigen::MatrixXd& blk = b[t] == e.value ? self : other[t];
              if (b[t] == e.value || !bz) {
                for (int d = 0; d < bs; ++d) {
                  inner[pos] = static_cast<int>(base + d);
                  values[pos++] = blk(c, d);
                }
              } else {
                const int comp = c / n;
                for (int d = comp * n; d < (comp + 1) * n; ++d) {
                  inner[pos] = static_cast<int>(base + d);
                  values[pos++] = blk(c, d);
                }
              }
            }
          }
        }
      });
  return k;
}

Eigen::VectorXd assembleLoad(const PolyMesh& mesh, const DgBasis& basis,
                             const MomentCache& moments, const FaceRoles& roles,
                             const FormCoefficients& form, const Material& material,
                             const LoadCase& loads, int quadratureDegree) {
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
      const double mu = form.mu, lambda = form.lambda;
      const double cK = roles.coupledFaces[e];
      const auto rule = faceQuadrature(mesh, fid, quadratureDegree);
      // Lifting: b_q(g) = int psi_q g.n and the face matrix int psi_q phi_i.
      Eigen::VectorXd bg = Eigen::VectorXd::Zero(n1);
      Eigen::MatrixXd mpsi = Eigen::MatrixXd::Zero(n1, n);
      const auto o = basis.liftingCoefficients(e);
      for (const QuadraturePoint& q : rule) {
        const Vec3 gx = g(q.point);
        basis.values(e, q.point, phi);
        for (int d = 0; d < 3; ++d)
          for (int r = 0; r < n; ++r) fe[d * n + r] += q.weight * mu * etaF * gx[d] * phi[r];
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
      if (ip && lambda != 0.0) {
        const Eigen::VectorXd lift = mpsi.transpose() * bg;  // sum_q b_q(g) int psi_q phi_r
        for (int d = 0; d < 3; ++d)
          for (int r = 0; r < n; ++r) fe[d * n + r] += lambda * cK * normal[d] * lift[r];
      }
    }
  });
  return f;
}

}  // namespace polydg
