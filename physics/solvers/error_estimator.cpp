#include "physics/solvers/error_estimator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <Eigen/LU>

#include "integrate/quadrature.h"
#include "physics/dg/face_quadrature.h"
#include "physics/dg/polynomial_tables.h"

namespace polydg {

namespace {

int defaultQuadratureDegree(int degree) { return std::max(degree + 4, 2 * degree + 2); }

/// sigma = 2 mu eps + lambda tr(eps) I of the displacement gradient g.
Eigen::Matrix3d stress(const Eigen::Matrix3d& g, double mu, double lambda) {
  const Eigen::Matrix3d eps = 0.5 * (g + g.transpose());
  return 2.0 * mu * eps + lambda * eps.trace() * Eigen::Matrix3d::Identity();
}

/// sigma(g) : eps(g), the elastic energy density (times 2) of the displacement gradient g.
double energyDensity(const Eigen::Matrix3d& g, double mu, double lambda) {
  return stress(g, mu, lambda).cwiseProduct(0.5 * (g + g.transpose())).sum();
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

/// mu eta_F |u_h,K - outside|^2 over face f by `rule`, the face's penalty part of the DG energy
/// norm: `outside` is the other element's u_h on an interior face and `boundary` (null: 0) on a
/// Dirichlet face; 0 on a face without face terms. Whole, not yet shared between its elements.
double penaltyJump(const MomentCache& moments, const FaceRoles& roles, const FormCoefficients& form,
                   const DgBasis& basis, const Eigen::VectorXd& u, FaceId f,
                   const std::vector<QuadraturePoint>& rule, const VectorField* boundary) {
  const FaceUses& uses = roles.uses[f];
  const FaceKind kind = roles.kind[f];
  if (uses.count == 0 || kind == FaceKind::Free) return 0.0;
  const ElementId k = uses.element[0];
  const ElementId l = kind == FaceKind::Interior ? uses.element[1] : ElementId();
  double jump = 0.0;
  for (const QuadraturePoint& q : rule) {
    const Vec3 outside = l.valid()                 ? displacementAt(basis, u, l, q.point)
                         : (boundary && *boundary) ? (*boundary)(q.point)
                                                   : Vec3::Zero();
    jump += q.weight * (displacementAt(basis, u, k, q.point) - outside).squaredNorm();
  }
  return form.mu * facePenalty(form, moments, f, k, l) * jump;
}

/// The numerical flux of the IP form, sigma^ n = {sigma(u_h)} n - mu eta_F [u_h] (the prescribed
/// traction on a Neumann face, 0 on a free one), at point x of face f, with n pointing out of
/// the face's first element.
Vec3 numericalFlux(const FaceRoles& roles, const FormCoefficients& form, const LoadCase& loads,
                   const DgBasis& basis, const Eigen::VectorXd& u, FaceId f, const Vec3& n,
                   double penalty, const Vec3& x) {
  const FaceUses& uses = roles.uses[f];
  const FaceKind kind = roles.kind[f];
  const ElementId k = uses.element[0];
  if (kind == FaceKind::Free) {
    const int t = roles.traction[f];
    return t >= 0 ? loads.tractions[static_cast<std::size_t>(t)].traction : Vec3::Zero();
  }
  const Eigen::Matrix3d sk = stress(displacementGradientAt(basis, u, k, x), form.mu, form.lambda);
  if (kind == FaceKind::Interior) {
    const ElementId l = uses.element[1];
    const Eigen::Matrix3d sl = stress(displacementGradientAt(basis, u, l, x), form.mu, form.lambda);
    return 0.5 * (sk + sl) * n -
           penalty * (displacementAt(basis, u, k, x) - displacementAt(basis, u, l, x));
  }
  const VectorField& g = loads.dirichlet[roles.dirichlet[f]].displacement;
  return sk * n - penalty * (displacementAt(basis, u, k, x) - (g ? g(x) : Vec3::Zero()));
}

/// The monomials xi^a (|a| <= degree) in graded order and the position of each exponent.
class Monomials {
 public:
  explicit Monomials(int degree) : degree_(degree), side_(degree + 1) {
    index_.assign(static_cast<std::size_t>(side_ * side_ * side_), -1);
    for (int d = 0; d <= degree; ++d)
      for (int a = d; a >= 0; --a)
        for (int b = d - a; b >= 0; --b) {
          const int c = d - a - b;
          index_[static_cast<std::size_t>((a * side_ + b) * side_ + c)] =
              static_cast<int>(exponents_.size());
          exponents_.push_back({a, b, c});
        }
  }
  int size() const { return static_cast<int>(exponents_.size()); }
  int degree() const { return degree_; }
  const std::array<int, 3>& exponent(int i) const {
    return exponents_[static_cast<std::size_t>(i)];
  }
  /// The position of exponent (a, b, c), or -1 if its degree is above the table's.
  int of(int a, int b, int c) const {
    if (a < 0 || b < 0 || c < 0 || a + b + c > degree_) return -1;
    return index_[static_cast<std::size_t>((a * side_ + b) * side_ + c)];
  }
  int of(const std::array<int, 3>& e) const { return of(e[0], e[1], e[2]); }
  /// Every monomial's value at xi into `out` (size()).
  void values(const Vec3& xi, double* out) const {
    double power[3][kMaxLocalDegree + 1];
    for (int k = 0; k < 3; ++k) {
      power[k][0] = 1.0;
      for (int j = 1; j <= degree_; ++j) power[k][j] = power[k][j - 1] * xi[k];
    }
    for (std::size_t i = 0; i < exponents_.size(); ++i)
      out[i] = power[0][exponents_[i][0]] * power[1][exponents_[i][1]] * power[2][exponents_[i][2]];
  }

  static constexpr int kMaxLocalDegree = 2 * (detail::kMaxBasisDegree + 1);

 private:
  int degree_, side_;
  std::vector<std::array<int, 3>> exponents_;
  std::vector<int> index_;
};

/// The energy of element e's local Neumann problem (the equilibrated residual method of
/// Ainsworth and Oden, with the DG numerical flux as the equilibrated boundary traction): phi in
/// P_q(K)^3, L2-orthogonal to the rigid motions, with
///   a_K(phi, v) = int_K f.v - a_K(u_h, v) + int_dK sigma^ n . v   for every such v,
/// returned as a_K(phi, phi). The element stiffness a_K, the constraints and the gravity load
/// come from the element's moments of the scaled monomials xi = (x - c) / s, computed with
/// sigma(u_h) : grad v by a rule exact for them; a body force (not a polynomial) by a finer rule.
/// The multipliers of the rigid-motion constraints take up what the flux leaves unbalanced (the IP
/// form's lambda lifting term is not in it).
struct LocalProblem {
  const PolyMesh& mesh;
  const DgBasis& basis;
  const MomentCache& moments;
  const FaceRoles& roles;
  const FormCoefficients& form;
  const LoadCase& loads;
  const Eigen::VectorXd& u;
  int q;               ///< degree of the local space, p + 1
  int elementDegree;   ///< exactness of the body force's rule
  int faceDegree;      ///< exactness of the face rules
  Monomials space{q};  ///< P_q
  /// The moments a_K and the constraints need; sigma(u_h) : grad v is of no higher degree.
  Monomials table{std::max(2 * q - 2, q + 1)};

  double energy(ElementId e) const;
};

double LocalProblem::energy(ElementId e) const {
  const int m = space.size(), size = 3 * m;
  const Vec3 c = moments.centroid(e);
  const double s = 0.5 * diameter(mesh, elementVertices(mesh, e));
  const double mu = form.mu, lambda = form.lambda;
  std::vector<double> mom(static_cast<std::size_t>(table.size()), 0.0);
  std::vector<double> phi(static_cast<std::size_t>(table.size()));
  Eigen::VectorXd b = Eigen::VectorXd::Zero(size);
  // Polynomial element integrals, exact: the moments and -int sigma(u_h) : grad v.
  for (const QuadraturePoint& qp : elementQuadrature(mesh, e, table.degree())) {
    const Vec3 xi = (qp.point - c) / s;
    table.values(xi, phi.data());
    for (int i = 0; i < table.size(); ++i)
      mom[static_cast<std::size_t>(i)] += qp.weight * phi[static_cast<std::size_t>(i)];
    const Eigen::Matrix3d sigma = stress(displacementGradientAt(basis, u, e, qp.point), mu, lambda);
    for (int a = 0; a < m; ++a) {
      const std::array<int, 3>& ea = space.exponent(a);
      Vec3 grad;
      for (int k = 0; k < 3; ++k) {
        std::array<int, 3> lower = ea;
        lower[static_cast<std::size_t>(k)] -= 1;
        grad[k] = ea[static_cast<std::size_t>(k)] > 0
                      ? ea[static_cast<std::size_t>(k)] *
                            phi[static_cast<std::size_t>(table.of(lower))] / s
                      : 0.0;
      }
      const Vec3 sg = sigma * grad;  // row d: sum_k sigma_dk d_k phi_a
      for (int d = 0; d < 3; ++d) b[d * m + a] -= qp.weight * sg[d];
    }
  }
  // int f.v for a body force (not a polynomial) by the finer rule. Gravity, constant, does no
  // work on fields orthogonal to the translations: it enters through the flux alone.
  if (loads.bodyForce)
    for (const QuadraturePoint& qp : elementQuadrature(mesh, e, elementDegree)) {
      const Vec3 f = loads.bodyForce(qp.point);
      space.values((qp.point - c) / s, phi.data());
      for (int a = 0; a < m; ++a)
        for (int d = 0; d < 3; ++d)
          b[d * m + a] += qp.weight * f[d] * phi[static_cast<std::size_t>(a)];
    }
  // Face integrals of the numerical flux out of e.
  for (const FaceUse& use : mesh.element(e).faces) {
    const FaceId f = use.face;
    const FaceUses& uses = roles.uses[f];
    if (uses.count == 0) continue;
    const int side = uses.element[0] == e ? 0 : 1;
    const Vec3 n = outwardNormal(moments, uses, f, 0);
    const FaceKind kind = roles.kind[f];
    const double penalty =
        kind == FaceKind::Free
            ? 0.0
            : mu * facePenalty(form, moments, f, uses.element[0],
                               kind == FaceKind::Interior ? uses.element[1] : ElementId());
    const double sign = side == 0 ? 1.0 : -1.0;
    for (const QuadraturePoint& qp : faceQuadrature(mesh, f, faceDegree)) {
      const Vec3 g = sign * numericalFlux(roles, form, loads, basis, u, f, n, penalty, qp.point);
      space.values((qp.point - c) / s, phi.data());
      for (int a = 0; a < m; ++a)
        for (int d = 0; d < 3; ++d)
          b[d * m + a] += qp.weight * g[d] * phi[static_cast<std::size_t>(a)];
    }
  }
  // a_K(phi_a e_d, phi_b e_e) = mu (delta_de G^kk_ab + G^ed_ab) + lambda G^de_ab with
  // G^kl_ab = int d_k phi_a d_l phi_b = a_k b_l / s^2 int xi^(a + b - e_k - e_l).
  auto gram = [&](int a, int b, int k, int l) {
    std::array<int, 3> e = space.exponent(a);
    const std::array<int, 3>& eb = space.exponent(b);
    const int ak = e[static_cast<std::size_t>(k)], bl = eb[static_cast<std::size_t>(l)];
    if (ak == 0 || bl == 0) return 0.0;
    for (int j = 0; j < 3; ++j) e[static_cast<std::size_t>(j)] += eb[static_cast<std::size_t>(j)];
    e[static_cast<std::size_t>(k)] -= 1;
    e[static_cast<std::size_t>(l)] -= 1;
    return ak * bl / (s * s) * mom[static_cast<std::size_t>(table.of(e))];
  };
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(size + 6, size + 6);
  for (int a = 0; a < m; ++a)
    for (int bb = 0; bb < m; ++bb) {
      double g[3][3];
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) g[k][l] = gram(a, bb, k, l);
      const double trace = g[0][0] + g[1][1] + g[2][2];
      for (int d = 0; d < 3; ++d)
        for (int e2 = 0; e2 < 3; ++e2)
          kkt(d * m + a, e2 * m + bb) =
              mu * ((d == e2 ? trace : 0.0) + g[e2][d]) + lambda * g[d][e2];
    }
  // Constraints int v . t = 0 for the translations e_j and the rotations e_j x xi, scaled like
  // the stiffness (the solution does not depend on it).
  const double scale = mu / (s * s);
  for (int a = 0; a < m; ++a) {
    const std::array<int, 3>& ea = space.exponent(a);
    for (int d = 0; d < 3; ++d) {
      const double translation = scale * mom[static_cast<std::size_t>(table.of(ea))];
      kkt(size + d, d * m + a) = kkt(d * m + a, size + d) = translation;
      for (int j = 0; j < 3; ++j) {
        // (e_j x xi)_d = eps_{d j k} xi_k, k the index other than d and j.
        if (j == d) continue;
        const int k = 3 - d - j;
        const double eps = ((d - j + 3) % 3 == 1) ? -1.0 : 1.0;  // eps_{djk}
        std::array<int, 3> up = ea;
        up[static_cast<std::size_t>(k)] += 1;
        const double rotation = scale * eps * mom[static_cast<std::size_t>(table.of(up))];
        kkt(size + 3 + j, d * m + a) += rotation;
        kkt(d * m + a, size + 3 + j) += rotation;
      }
    }
  }
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(size + 6);
  rhs.head(size) = b;
  const Eigen::VectorXd x = kkt.partialPivLu().solve(rhs);
  const Eigen::VectorXd v = x.head(size);
  return std::max(0.0, v.dot(kkt.topLeftCorner(size, size) * v));
}

}  // namespace

ErrorEstimate estimateError(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const FaceRoles& roles, const FormCoefficients& form,
                            const LoadCase& loads, const Eigen::VectorXd& coefficients,
                            const EstimatorOptions& options) {
  if (form.method != Method::IP)
    throw std::invalid_argument("estimateError: the estimator is for the IP method");
  const std::size_t ne = mesh.numElements(), nf = mesh.numFaces();
  if (coefficients.size() != static_cast<Eigen::Index>(ne * 3 * basis.size()))
    throw std::invalid_argument("estimateError: the coefficients do not match the basis");
  const int quadrature = options.quadratureDegree >= 0 ? options.quadratureDegree
                                                       : defaultQuadratureDegree(basis.degree());

  FaceData<double> jumps(nf, 0.0);
  tbb::parallel_for(std::size_t(0), nf, [&](std::size_t i) {
    const FaceId f(i);
    const VectorField* g = roles.kind[f] == FaceKind::Dirichlet
                               ? &loads.dirichlet[roles.dirichlet[f]].displacement
                               : nullptr;
    jumps[f] = penaltyJump(moments, roles, form, basis, coefficients, f,
                           faceQuadrature(mesh, f, quadrature), g);
  });

  const int p = basis.degree();
  const LocalProblem local{mesh,
                           basis,
                           moments,
                           roles,
                           form,
                           loads,
                           coefficients,
                           p + 1,
                           std::max(quadrature, 2 * (p + 1)),
                           std::max(quadrature, 2 * p + 1)};
  ElementData<double> energies(ne, 0.0);
  tbb::parallel_for(std::size_t(0), ne,
                    [&](std::size_t i) { energies[ElementId(i)] = local.energy(ElementId(i)); });

  // Per element, in element order: the sums do not depend on the schedule.
  ErrorEstimate out;
  out.indicators.resize(ne, 0.0);
  for (std::size_t i = 0; i < ne; ++i) {
    const ElementId e(i);
    double eta2 = energies[e];
    out.local += energies[e];
    for (const FaceUse& use : mesh.element(e).faces) {
      const FaceKind kind = roles.kind[use.face];
      const double share = kind == FaceKind::Interior ? 0.5 : 1.0;
      eta2 += share * jumps[use.face];
      (kind == FaceKind::Dirichlet ? out.dirichlet : out.displacementJump) +=
          share * jumps[use.face];
    }
    out.indicators[e] = eta2;
  }
  out.total = std::sqrt(std::accumulate(out.indicators.begin(), out.indicators.end(), 0.0));
  return out;
}

ErrorEstimate estimateError(const PolyMesh& mesh, const StaticSolver& solver, const LoadCase& loads,
                            const Eigen::VectorXd& coefficients, const EstimatorOptions& options) {
  return estimateError(mesh, solver.basis(), solver.moments(), solver.roles(), solver.form(), loads,
                       coefficients, options);
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
      s += q.weight * energyDensity(g, mu, lambda);
    }
    elementEnergy[e] = s;
  });
  FaceData<double> faceJump(nf, 0.0);
  tbb::parallel_for(std::size_t(0), nf, [&](std::size_t i) {
    const FaceId f(i);
    faceJump[f] = penaltyJump(moments, roles, form, basis, coefficients, f,
                              faceQuadrature(mesh, f, quadratureDegree), &exact);
  });
  EnergyError out;
  out.elements = elementEnergy;
  for (std::size_t i = 0; i < ne; ++i)
    for (const FaceUse& use : mesh.element(ElementId(i)).faces)
      out.elements[ElementId(i)] +=
          (roles.kind[use.face] == FaceKind::Interior ? 0.5 : 1.0) * faceJump[use.face];
  out.broken =
      std::sqrt(std::max(0.0, std::accumulate(elementEnergy.begin(), elementEnergy.end(), 0.0)));
  out.jump = std::sqrt(std::accumulate(faceJump.begin(), faceJump.end(), 0.0));
  return out;
}

double brokenEnergyDifference(const PolyMesh& fineMesh, const DgBasis& fineBasis,
                              const Eigen::VectorXd& fine, const DgBasis& coarseBasis,
                              const Eigen::VectorXd& coarse, const std::vector<ElementId>& parent,
                              const Material& material, int quadratureDegree) {
  const std::size_t ne = fineMesh.numElements();
  if (parent.size() != ne)
    throw std::invalid_argument("brokenEnergyDifference: one parent per fine element");
  const double mu = material.mu(), lambda = material.lambda();
  std::vector<double> energy(ne, 0.0);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId k(i);
    double s = 0.0;
    for (const QuadraturePoint& q : elementQuadrature(fineMesh, k, quadratureDegree)) {
      const Eigen::Matrix3d g = displacementGradientAt(fineBasis, fine, k, q.point) -
                                displacementGradientAt(coarseBasis, coarse, parent[i], q.point);
      s += q.weight * energyDensity(g, mu, lambda);
    }
    energy[i] = s;
  });
  return std::sqrt(std::max(0.0, std::accumulate(energy.begin(), energy.end(), 0.0)));
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
