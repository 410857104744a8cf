// What the a posteriori error estimate of a static IP-DG solution reports, and the true
// error in the same norm (physics/solvers/error_estimator.h computes both).
#pragma once

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

struct EstimatorOptions {
  /// Degree of exactness of the element and face rules (the body force and the Dirichlet data
  /// are not polynomials); -1 picks max(p + 4, 2p + 2), the degree of the B1 error norms.
  int quadratureDegree = -1;
};

/// The estimate of the error e = u - u_h in the DG energy norm (energyError()). Element K's
/// indicator is, for degree p,
///   eta_K^2 = a_K(phi_K, phi_K)                                    (local problem)
///           + sum_{F of K interior}  1/2 mu eta_F |[u_h]|^2_F       (displacement jump)
///           + sum_{F of K Dirichlet} mu eta_F |u_h - g|^2_F
/// where phi_K solves the element's Neumann problem (the equilibrated residual method of
/// Ainsworth and Oden, with the DG numerical flux as the boundary traction): phi_K in
/// P_{p+1}(K)^3, L2-orthogonal to the rigid motions, with
///   a_K(phi_K, v) = int_K f.v - a_K(u_h, v) + int_dK sigma^ n . v   for every such v,
/// f the body force (LoadCase::bodyForce; gravity, constant, does no work on such v), a_K the
/// element's elastic energy form, and sigma^ n the IP form's flux {sigma(u_h)} n - mu eta_F
/// [u_h] (on a Dirichlet face with u_L = g, on a Neumann face the prescribed traction, 0 on a
/// free one). phi_K is the error
/// on K up to the flux's own error, so no constant is tuned: its energy is the broken part of
/// the estimate. The flux leaves out the IP form's lambda lifting term; the rigid-motion
/// constraints' multipliers take up what it leaves unbalanced (such an imbalance is not
/// measured). The jump terms are the penalty
/// part of the DG energy norm itself (mu eta_F from facePenalty(), eq. 7), so they equal the
/// jump part of energyError() exactly (the exact solution does not jump). Interior faces give
/// half to each side, so that the sum over elements counts every face once. The estimate
/// vanishes when u_h is exact. Measured effectivity (estimate / energyError().total()): 0.9 to
/// 1.6 on B12, a wider bump, an L-prism and the torus (tests/physics/solvers/
/// error_estimator_test.cpp, docs/benchmarks.md).
struct ErrorEstimate {
  ElementData<double> indicators;  ///< eta_K^2 per element
  double total = 0.0;              ///< eta = sqrt(sum_K eta_K^2)
  /// The sums over the mesh of each group of terms above (squared; they add up to total^2).
  double local = 0.0;             ///< the local problems' energies
  double displacementJump = 0.0;  ///< interior displacement jumps
  double dirichlet = 0.0;         ///< Dirichlet faces
};

/// The error of a solution against a known exact solution u in the DG energy norm
///   |e|_DG^2 = sum_K int_K sigma(e) : eps(e) + sum_F mu eta_F |[e]|^2_F,
/// e = u - u_h, over interior faces ([e] = -[u_h]) and Dirichlet faces (u - u_h), the norm that
/// ErrorEstimate estimates (effectivity index: estimate.total / error.total()).
struct EnergyError {
  double broken = 0.0;  ///< sqrt(sum_K int_K sigma(e) : eps(e)): the broken energy norm
  double jump = 0.0;    ///< sqrt(sum_F mu eta_F |[e]|^2_F)
  /// Per element, as ErrorEstimate::indicators: int_K sigma(e) : eps(e) plus the jump terms of
  /// its faces (half of each interior face's); they add up to total()^2.
  ElementData<double> elements;
  double total() const;
};

}  // namespace polydg
