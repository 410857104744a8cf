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
///   eta_K^2 = (h_K / p)^2 / (2 mu) |f + div sigma(u_h)|^2_K                      (residual)
///           + sum_{F of K interior}  1/2 h_F / (2 mu p) |[sigma(u_h) n]|^2_F   (traction jump)
///           + sum_{F of K Neumann}   h_F / (2 mu p) |t - sigma(u_h) n|^2_F      (free: t = 0)
///           + sum_{F of K interior}  1/2 mu eta_F |[u_h]|^2_F               (displacement jump)
///           + sum_{F of K Dirichlet} mu eta_F |u_h - g|^2_F
/// with f the body force (density * gravity + LoadCase::bodyForce), h_K and h_F the diameters of
/// the element and the face (largest distance between their vertices), and mu eta_F the
/// solver's own penalty coefficient (facePenalty(), eq. 7) of the jump. Interior faces give
/// half to each side, so that the sum over elements counts every face once.
///
/// Constants: all are 1, in the form of Houston, Schoetzau and Wihler's hp estimator for SIPG
/// (M3AS 2007), written for elasticity: the residual weighed by (h/p)^2 and the traction jumps
/// by h/p (without the 1/p, the residual of a degree p+1 error is an inverse inequality,
/// ~(p+1)^2 / h, times its gradient, and the estimate grows with p). Residual and traction
/// terms measure sigma in the dual norm of the energy, whose coercivity constant is 2 mu
/// (a(v, v) >= 2 mu |eps(v)|^2 for every lambda), hence the division by 2 mu. The jump terms
/// are the penalty part of the DG energy norm itself, so they equal the jump part of
/// energyError() exactly (the exact solution does not jump); they are linear in the penalty
/// (Karakashian and Pascal's bound of the nonconforming part), not quadratic as in Houston et
/// al.'s proof. The lambda lifting terms of the IP form are left out of both. The estimate
/// vanishes when u_h is exact. Measured effectivity (estimate / energyError().total()): see
/// tests/physics/solvers/error_estimator_test.cpp.
struct ErrorEstimate {
  ElementData<double> indicators;  ///< eta_K^2 per element
  double total = 0.0;              ///< eta = sqrt(sum_K eta_K^2)
  /// The sums over the mesh of each group of terms above (squared; they add up to total^2).
  double residual = 0.0;          ///< element residuals
  double tractionJump = 0.0;      ///< interior traction jumps and Neumann face residuals
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
  double total() const;
};

}  // namespace polydg
