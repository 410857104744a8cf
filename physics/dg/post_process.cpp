#include "polydg/physics/dg/post_process.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "integrate/quadrature.h"
#include "physics/dg/local_integrators.h"
#include "polydg/mesh/geometry.h"

namespace polydg {

namespace {
constexpr int kMaxFunctions = numMonomials(3);
}

Vec3 displacementAt(const DgBasis& basis, const Eigen::VectorXd& u, ElementId e, const Vec3& x) {
  const int n = basis.size();
  double phi[kMaxFunctions];
  basis.values(e, x, {phi, static_cast<std::size_t>(n)});
  const double* c = u.data() + e.index() * 3 * n;
  Vec3 v = Vec3::Zero();
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < n; ++i) v[d] += c[d * n + i] * phi[i];
  return v;
}

Eigen::Matrix3d displacementGradientAt(const DgBasis& basis, const Eigen::VectorXd& u, ElementId e,
                                       const Vec3& x) {
  const int n = basis.size();
  double grad[3 * kMaxFunctions];
  basis.gradients(e, x, {grad, static_cast<std::size_t>(3 * n)});
  const double* c = u.data() + e.index() * 3 * n;
  Eigen::Matrix3d g = Eigen::Matrix3d::Zero();
  for (int d = 0; d < 3; ++d)
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < n; ++i) g(d, k) += c[d * n + i] * grad[k * n + i];
  return g;
}

const Vec3& CornerValues::at(ElementId e, VertexId v) const {
  const auto first = vertices.begin() + static_cast<std::ptrdiff_t>(begin[e.index()]);
  const auto last = vertices.begin() + static_cast<std::ptrdiff_t>(begin[e.index() + 1]);
  const auto it = std::lower_bound(first, last, v);
  if (it == last || *it != v)
    throw std::logic_error("CornerValues::at: not a vertex of the element");
  return values[static_cast<std::size_t>(it - vertices.begin())];
}

double CornerValues::largestNorm() const {
  double largest = 0.0;
  for (const Vec3& u : values) largest = std::max(largest, u.norm());
  return largest;
}

CornerValues cornerDisplacements(const PolyMesh& mesh, const DgBasis& basis,
                                 const Eigen::VectorXd& coefficients) {
  const std::size_t ne = mesh.numElements();
  std::vector<std::vector<VertexId>> perElement(ne);
  tbb::parallel_for(std::size_t(0), ne,
                    [&](std::size_t i) { perElement[i] = elementVertices(mesh, ElementId(i)); });
  CornerValues c;
  c.begin.assign(ne + 1, 0);
  for (std::size_t i = 0; i < ne; ++i) c.begin[i + 1] = c.begin[i] + perElement[i].size();
  c.vertices.resize(c.begin[ne]);
  c.values.resize(c.begin[ne]);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    for (std::size_t k = 0; k < perElement[i].size(); ++k) {
      const VertexId v = perElement[i][k];
      c.vertices[c.begin[i] + k] = v;
      c.values[c.begin[i] + k] =
          displacementAt(basis, coefficients, ElementId(i), mesh.position(v));
    }
  });
  return c;
}

CornerArray displacementPointData(const CornerValues& corners, std::string name) {
  return CornerArray{std::move(name), 3, [&corners](ElementId e, VertexId v, double* out) {
                       const Vec3& u = corners.at(e, v);
                       out[0] = u.x();
                       out[1] = u.y();
                       out[2] = u.z();
                     }};
}

CornerArray displacementPointData(const PolyMesh& mesh, const DgBasis& basis,
                                  const Eigen::VectorXd& coefficients, std::string name) {
  return CornerArray{std::move(name), 3,
                     [&mesh, &basis, &coefficients](ElementId e, VertexId v, double* out) {
                       const Vec3 u = displacementAt(basis, coefficients, e, mesh.position(v));
                       out[0] = u.x();
                       out[1] = u.y();
                       out[2] = u.z();
                     }};
}

ElementFields elementFields(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const Eigen::VectorXd& coefficients, const Material& material) {
  const std::size_t ne = mesh.numElements();
  ElementFields out;
  out.meanDisplacement.resize(ne, Vec3::Zero());
  out.vonMises.resize(ne, 0.0);
  out.principalStress.resize(ne, 0.0);
  out.principalDirection.resize(ne, Vec3::UnitX());
  out.largestJump.resize(ne, 0.0);
  const double mu = material.mu(), lambda = material.lambda();
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    const double volume = moments.volume(e);
    Vec3 mean = Vec3::Zero();
    Eigen::Matrix3d grad = Eigen::Matrix3d::Zero();
    for (const QuadraturePoint& q : elementQuadrature(mesh, e, basis.degree())) {
      mean += q.weight * displacementAt(basis, coefficients, e, q.point);
      grad += q.weight * displacementGradientAt(basis, coefficients, e, q.point);
    }
    mean /= volume;
    grad /= volume;
    out.meanDisplacement[e] = mean;
    const Eigen::Matrix3d eps = 0.5 * (grad + grad.transpose());
    const Eigen::Matrix3d sigma =
        2.0 * mu * eps + lambda * eps.trace() * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d dev = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
    out.vonMises[e] = std::sqrt(1.5 * dev.squaredNorm());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(sigma);
    const int k = std::abs(eigen.eigenvalues()[0]) > std::abs(eigen.eigenvalues()[2]) ? 0 : 2;
    out.principalStress[e] = eigen.eigenvalues()[k];
    out.principalDirection[e] = eigen.eigenvectors().col(k);
  });
  // Jumps at the vertices of interior faces.
  for (std::size_t i = 0; i < ne; ++i) {
    const ElementId e(i);
    for (const FaceUse& use : mesh.element(e).faces) {
      const Face& face = mesh.face(use.face);
      if (!face.front.valid() || !face.back.valid()) continue;
      const ElementId other = face.front == e ? face.back : face.front;
      double jump = 0.0;
      for (VertexId v : face.vertices) {
        const Vec3& x = mesh.position(v);
        jump = std::max(jump, (displacementAt(basis, coefficients, e, x) -
                               displacementAt(basis, coefficients, other, x))
                                  .norm());
      }
      out.largestJump[e] = std::max(out.largestJump[e], jump);
    }
  }
  return out;
}

ErrorNorms errorNorms(const PolyMesh& mesh, const DgBasis& basis,
                      const Eigen::VectorXd& coefficients,
                      const std::function<Vec3(const Vec3&)>& exact,
                      const GradientField& exactGradient, int quadratureDegree) {
  struct Sums {
    double l2 = 0, h1 = 0, l2e = 0, h1e = 0;
  };
  const Sums s = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.numElements(), 8), Sums{},
      [&](const tbb::blocked_range<std::size_t>& r, Sums acc) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const ElementId e(i);
          for (const QuadraturePoint& q : elementQuadrature(mesh, e, quadratureDegree)) {
            const Vec3 u = exact(q.point);
            const Eigen::Matrix3d g = exactGradient(q.point);
            acc.l2 +=
                q.weight * (u - displacementAt(basis, coefficients, e, q.point)).squaredNorm();
            acc.h1 += q.weight *
                      (g - displacementGradientAt(basis, coefficients, e, q.point)).squaredNorm();
            acc.l2e += q.weight * u.squaredNorm();
            acc.h1e += q.weight * g.squaredNorm();
          }
        }
        return acc;
      },
      [](Sums a, const Sums& b) {
        a.l2 += b.l2;
        a.h1 += b.h1;
        a.l2e += b.l2e;
        a.h1e += b.h1e;
        return a;
      });
  return {std::sqrt(std::max(0.0, s.l2)), std::sqrt(std::max(0.0, s.h1)),
          std::sqrt(std::max(0.0, s.l2e)), std::sqrt(std::max(0.0, s.h1e))};
}

Eigen::VectorXd projectField(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                             const std::function<Vec3(const Vec3&)>& field, int quadratureDegree) {
  const int n = basis.size();
  Eigen::VectorXd out =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.numElements() * 3 * n));
  tbb::parallel_for(std::size_t(0), mesh.numElements(), [&](std::size_t i) {
    const ElementId e(i);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3), mass;
    double phi[kMaxFunctions];
    for (const QuadraturePoint& q : elementQuadrature(mesh, e, quadratureDegree)) {
      basis.values(e, q.point, {phi, static_cast<std::size_t>(n)});
      const Vec3 v = field(q.point);
      for (int r = 0; r < n; ++r)
        for (int d = 0; d < 3; ++d) rhs(r, d) += q.weight * v[d] * phi[r];
    }
    elementMass(basis, moments, e, mass);
    const Eigen::MatrixXd c = mass.ldlt().solve(rhs);
    for (int d = 0; d < 3; ++d)
      for (int r = 0; r < n; ++r) out[static_cast<Eigen::Index>(i * 3 * n + d * n + r)] = c(r, d);
  });
  return out;
}

}  // namespace polydg
