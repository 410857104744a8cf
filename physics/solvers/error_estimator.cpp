#include "physics/solvers/error_estimator.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "integrate/quadrature.h"
#include "physics/dg/face_quadrature.h"
#include "physics/dg/polynomial_tables.h"

namespace polydg {

namespace {

constexpr int kMaxFunctions = numMonomials(detail::kMaxBasisDegree);

int defaultQuadratureDegree(int degree) { return std::max(degree + 4, 2 * degree + 2); }

/// sigma = 2 mu eps + lambda tr(eps) I of the displacement gradient g.
Eigen::Matrix3d stress(const Eigen::Matrix3d& g, double mu, double lambda) {
  const Eigen::Matrix3d eps = 0.5 * (g + g.transpose());
  return 2.0 * mu * eps + lambda * eps.trace() * Eigen::Matrix3d::Identity();
}

/// div sigma(u_h) of element e's polynomial at x: mu Lap u + (mu + lambda) grad div u.
Vec3 stressDivergenceAt(const DgBasis& basis, const Eigen::VectorXd& u, ElementId e, const Vec3& x,
                        double mu, double lambda) {
  const int n = basis.size();
  double hess[9 * kMaxFunctions];
  basis.hessians(e, x, {hess, static_cast<std::size_t>(9 * n)});
  const double* c = u.data() + e.index() * 3 * n;
  // second(d, k, l) = d^2 u_d / (dx_k dx_l).
  auto second = [&](int d, int k, int l) {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += c[d * n + i] * hess[(3 * k + l) * n + i];
    return s;
  };
  Vec3 out;
  for (int d = 0; d < 3; ++d) {
    double laplacian = 0.0, gradDiv = 0.0;
    for (int k = 0; k < 3; ++k) {
      laplacian += second(d, k, k);
      gradDiv += second(k, k, d);
    }
    out[d] = mu * laplacian + (mu + lambda) * gradDiv;
  }
  return out;
}

/// Largest distance between two of the points.
template <class Range>
double diameter(const PolyMesh& mesh, const Range& vertices) {
  double d2 = 0.0;
  for (auto a = vertices.begin(); a != vertices.end(); ++a)
    for (auto b = std::next(a); b != vertices.end(); ++b)
      d2 = std::max(d2, (mesh.position(*a) - mesh.position(*b)).squaredNorm());
  return std::sqrt(d2);
}

/// The normal of face f pointing out of side s of its uses.
Vec3 outwardNormal(const MomentCache& moments, const FaceUses& uses, FaceId f, int s) {
  return uses.reversed[s] ? Vec3(-moments.faceNormal(f)) : moments.faceNormal(f);
}

/// A face's terms of the estimate, whole (not yet shared between its elements).
struct FaceTermsOfEstimate {
  double traction = 0.0;  ///< h_F / (2 mu p) |[sigma n]|^2 or |t - sigma n|^2
  double jump = 0.0;      ///< mu eta_F |[u_h]|^2 or |u_h - g|^2
};

FaceTermsOfEstimate faceTerms(const PolyMesh& mesh, const DgBasis& basis,
                              const MomentCache& moments, const FaceRoles& roles,
                              const FormCoefficients& form, const LoadCase& loads,
                              const Eigen::VectorXd& u, FaceId f, int quadratureDegree) {
  FaceTermsOfEstimate out;
  const FaceUses& uses = roles.uses[f];
  if (uses.count == 0) return out;
  const FaceKind kind = roles.kind[f];
  const ElementId k = uses.element[0];
  const Vec3 n = outwardNormal(moments, uses, f, 0);
  const double mu = form.mu, lambda = form.lambda;
  const double hF = diameter(mesh, mesh.face(f).vertices);
  const auto rule = faceQuadrature(mesh, f, quadratureDegree);
  double traction = 0.0, jump = 0.0;
  if (kind == FaceKind::Interior) {
    const ElementId l = uses.element[1];
    for (const QuadraturePoint& q : rule) {
      const Eigen::Matrix3d sk = stress(displacementGradientAt(basis, u, k, q.point), mu, lambda);
      const Eigen::Matrix3d sl = stress(displacementGradientAt(basis, u, l, q.point), mu, lambda);
      traction += q.weight * ((sk - sl) * n).squaredNorm();
      jump +=
          q.weight * (displacementAt(basis, u, k, q.point) - displacementAt(basis, u, l, q.point))
                         .squaredNorm();
    }
    out.jump = mu * facePenalty(form, moments, f, k, l) * jump;
  } else if (kind == FaceKind::Dirichlet) {
    const VectorField& g = loads.dirichlet[roles.dirichlet[f]].displacement;
    for (const QuadraturePoint& q : rule) {
      const Vec3 gx = g ? g(q.point) : Vec3::Zero();
      jump += q.weight * (displacementAt(basis, u, k, q.point) - gx).squaredNorm();
    }
    out.jump = mu * facePenalty(form, moments, f, k, ElementId()) * jump;
  } else {  // a Neumann face: a traction condition, or free (t = 0)
    const int t = roles.traction[f];
    const Vec3 prescribed = t >= 0 ? loads.tractions[t].traction : Vec3::Zero();
    for (const QuadraturePoint& q : rule) {
      const Eigen::Matrix3d s = stress(displacementGradientAt(basis, u, k, q.point), mu, lambda);
      traction += q.weight * (prescribed - s * n).squaredNorm();
    }
  }
  out.traction = hF / (basis.degree() * 2.0 * mu) * traction;
  return out;
}

}  // namespace

ErrorEstimate estimateError(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const FaceRoles& roles, const FormCoefficients& form,
                            const Material& material, const LoadCase& loads,
                            const Eigen::VectorXd& coefficients, const EstimatorOptions& options) {
  if (form.method != Method::IP)
    throw std::invalid_argument("estimateError: the estimator is for the IP method");
  const std::size_t ne = mesh.numElements(), nf = mesh.numFaces();
  if (coefficients.size() != static_cast<Eigen::Index>(ne * 3 * basis.size()))
    throw std::invalid_argument("estimateError: the coefficients do not match the basis");
  const int quadrature = options.quadratureDegree >= 0 ? options.quadratureDegree
                                                       : defaultQuadratureDegree(basis.degree());
  const double mu = form.mu, lambda = form.lambda;

  FaceData<FaceTermsOfEstimate> faces(nf);
  tbb::parallel_for(std::size_t(0), nf, [&](std::size_t i) {
    faces[FaceId(i)] =
        faceTerms(mesh, basis, moments, roles, form, loads, coefficients, FaceId(i), quadrature);
  });

  const Vec3 gravityForce = material.density * loads.gravity;
  ElementData<double> residual(ne, 0.0);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    const std::vector<VertexId> vertices = elementVertices(mesh, e);
    const double hK = diameter(mesh, vertices);
    double r = 0.0;
    for (const QuadraturePoint& q : elementQuadrature(mesh, e, quadrature)) {
      Vec3 f = gravityForce;
      if (loads.bodyForce) f += loads.bodyForce(q.point);
      r += q.weight *
           (f + stressDivergenceAt(basis, coefficients, e, q.point, mu, lambda)).squaredNorm();
    }
    const double hOverP = hK / basis.degree();
    residual[e] = hOverP * hOverP / (2.0 * mu) * r;
  });

  // Per element, in element order: the sums do not depend on the schedule.
  ErrorEstimate out;
  out.indicators.resize(ne, 0.0);
  for (std::size_t i = 0; i < ne; ++i) {
    const ElementId e(i);
    double eta2 = residual[e];
    out.residual += residual[e];
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceTermsOfEstimate& t = faces[use.face];
      const FaceKind kind = roles.kind[use.face];
      const double share = kind == FaceKind::Interior ? 0.5 : 1.0;
      eta2 += share * (t.traction + t.jump);
      out.tractionJump += share * t.traction;
      (kind == FaceKind::Dirichlet ? out.dirichlet : out.displacementJump) += share * t.jump;
    }
    out.indicators[e] = eta2;
  }
  out.total = std::sqrt(std::accumulate(out.indicators.begin(), out.indicators.end(), 0.0));
  return out;
}

ErrorEstimate estimateError(const PolyMesh& mesh, const StaticSolver& solver,
                            const Material& material, const LoadCase& loads,
                            const Eigen::VectorXd& coefficients, const EstimatorOptions& options) {
  return estimateError(mesh, solver.basis(), solver.moments(), solver.roles(), solver.form(),
                       material, loads, coefficients, options);
}

double EnergyError::total() const { return std::hypot(broken, jump); }

EnergyError energyError(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                        const FaceRoles& roles, const FormCoefficients& form,
                        const Eigen::VectorXd& coefficients, const VectorField& exact,
                        const GradientField& exactGradient, int quadratureDegree) {
  const std::size_t ne = mesh.numElements(), nf = mesh.numFaces();
  const double mu = form.mu, lambda = form.lambda;
  ElementData<double> elementEnergy(ne, 0.0);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    double s = 0.0;
    for (const QuadraturePoint& q : elementQuadrature(mesh, e, quadratureDegree)) {
      const Eigen::Matrix3d g =
          exactGradient(q.point) - displacementGradientAt(basis, coefficients, e, q.point);
      s += q.weight * stress(g, mu, lambda).cwiseProduct(0.5 * (g + g.transpose())).sum();
    }
    elementEnergy[e] = s;
  });
  FaceData<double> faceJump(nf, 0.0);
  tbb::parallel_for(std::size_t(0), nf, [&](std::size_t i) {
    const FaceId f(i);
    const FaceUses& uses = roles.uses[f];
    const FaceKind kind = roles.kind[f];
    if (uses.count == 0 || kind == FaceKind::Free) return;
    const bool interior = kind == FaceKind::Interior;
    const ElementId k = uses.element[0], l = interior ? uses.element[1] : ElementId();
    double s = 0.0;
    for (const QuadraturePoint& q : faceQuadrature(mesh, f, quadratureDegree)) {
      const Vec3 outside =
          interior ? displacementAt(basis, coefficients, l, q.point) : exact(q.point);
      s += q.weight * (displacementAt(basis, coefficients, k, q.point) - outside).squaredNorm();
    }
    faceJump[f] = mu * facePenalty(form, moments, f, k, l) * s;
  });
  EnergyError out;
  out.broken =
      std::sqrt(std::max(0.0, std::accumulate(elementEnergy.begin(), elementEnergy.end(), 0.0)));
  out.jump = std::sqrt(std::accumulate(faceJump.begin(), faceJump.end(), 0.0));
  return out;
}

std::vector<ElementId> markBulk(const ElementData<double>& indicators, double theta) {
  if (!(theta > 0.0 && theta <= 1.0))
    throw std::invalid_argument("markBulk: theta must lie in (0, 1]");
  std::vector<ElementId> order(indicators.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = ElementId(i);
  std::sort(order.begin(), order.end(), [&](ElementId a, ElementId b) {
    return indicators[a] != indicators[b] ? indicators[a] > indicators[b] : a < b;
  });
  const double total = std::accumulate(indicators.begin(), indicators.end(), 0.0);
  std::vector<ElementId> marked;
  if (!(total > 0.0)) return marked;
  // The last elements that bring the sum to theta * total may fall short by round-off; stop at
  // the first zero indicator at the latest.
  double sum = 0.0;
  for (ElementId e : order) {
    if (sum >= theta * total || !(indicators[e] > 0.0)) break;
    marked.push_back(e);
    sum += indicators[e];
  }
  return marked;
}

std::vector<ElementId> limitToDofBudget(std::vector<ElementId> marked, std::size_t dofs,
                                        std::size_t dofsPerRefinement, std::size_t dofBudget) {
  const std::size_t room = dofBudget > dofs ? dofBudget - dofs : 0;
  const std::size_t fit = dofsPerRefinement > 0 ? room / dofsPerRefinement : marked.size();
  if (marked.size() > fit) marked.resize(fit);
  return marked;
}

}  // namespace polydg
