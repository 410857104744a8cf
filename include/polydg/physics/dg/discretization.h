// The options of a DG discretization: the method (interior penalty or Babuska-Zlamal), the
// BZ penalty's scaling, the basis and how the penalty is chosen. One struct,
// DiscretizationOptions, that every solve, check, time step and error estimate takes.
#pragma once

#include <optional>

#include "polydg/physics/dg/dg_basis.h"

namespace polydg {

/// The DG method (paper section 4).
enum class Method {
  IP,  ///< symmetric interior penalty, eq. (8): consistent, converges at the optimal rate
  BZ,  ///< Babuska-Zlamal penalty, eq. (6): only the jump penalty; inconsistent
};

/// How the jump penalty of the BZ method scales with the mesh (Method::BZ only).
enum class BzPenalty {
  /// eta_F = facePenalty() as for IP, ~ 1/h. Cheap and as well conditioned as IP, but BZ is
  /// inconsistent: its error does not fall under refinement (a uniaxial bar's end
  /// displacement 87% too large at p = 1, 28% at p = 2, 14% at p = 3, at 8 or 16 cells).
  Fixed,
  /// Babuska and Zlamal's superpenalty, eta_F (L/h)^(2p) ~ h^-(2p+1): the consistency error,
  /// ~ |sigma n|_F / sqrt(eta_F), then falls as h^p, and the L2 error with it, at the price
  /// of a stiffer jump term (condition numbers ~ h^-(2p+2) instead of h^-2). The factor is
  /// FormCoefficients::bzFactor, from superpenaltyFactor() (physics/dg/form_coefficients.h).
  /// For p >= 2 it multiplies the penalty of the whole jump. For p = 1 it multiplies only the
  /// penalty of the jump's mean over each face (the rest of the jump keeps eta_F): on the whole
  /// jump it would force the solution towards continuous complete linears, which on a hex grid
  /// are only the global linears, and the error locked (B1's L2 error stalled at 2e-3).
  /// With continuous face means instead, the limit is a nonconforming P1 method (face-mean
  /// continuity, as Crouzeix-Raviart's), which passes the patch test: for a constant stress
  /// the missing flux term sigma n . int_F [v] vanishes. FormCoefficients::bzFactorOnMean.
  Super,
};

/// How the global penalty eta of eq. (7) is chosen.
enum class PenaltyRule {
  /// eta = safety * the coercivity bound: guaranteed SPD, no trial factorizations. Per
  /// element (elementPenaltyThresholds()) unless PenaltyOptions::local is false, then the
  /// global penaltyThreshold().
  TraceBound,
  /// The paper's rule (section 10): start at `eta` (unset: kFirstDoublingEta) and double
  /// until the Cholesky factorization succeeds. Costs one factorization per attempt.
  Doubling,
  /// eta = `eta`, which must be given.
  Fixed,
};

/// PenaltyRule::Doubling's first eta when none is given.
inline constexpr double kFirstDoublingEta = 1.0;

struct PenaltyOptions {
  PenaltyRule rule = PenaltyRule::TraceBound;
  std::optional<double> eta;  ///< Fixed: the value (required); Doubling: the first value tried
  double safety = 1.0;        ///< TraceBound: multiple of the threshold
  /// TraceBound: each element's own bound eta_K (FormCoefficients::elementEta), so that a
  /// badly shaped element does not raise the penalty, and spoil the accuracy, everywhere; false:
  /// the largest bound for every face, as in the paper's global eta.
  bool local = true;
};

struct DiscretizationOptions {
  Method method = Method::IP;
  /// Method::BZ: how its penalty scales with the mesh; unset: kDefaultBzPenalty, the
  /// superpenalty, because it converges (the fixed penalty is 87% too soft on a uniaxial bar at
  /// any h). Setting it with another method is refused.
  std::optional<BzPenalty> bzPenalty;
  static constexpr BzPenalty kDefaultBzPenalty = BzPenalty::Super;
  /// BzPenalty::Super: the reference length L of superpenaltyFactor(); 0 picks the mesh's
  /// bounding-box diagonal. In the model's length unit.
  double bzReferenceLength = 0.0;
  BasisOptions basis;
  PenaltyOptions penalty;
  /// Degree of exactness of the quadrature for non-polynomial loads (body force function,
  /// Dirichlet data); -1 picks 2p + 2.
  int quadratureDegree = -1;

  /// The BZ penalty in effect (Method::BZ).
  BzPenalty bzPenaltyInEffect() const { return bzPenalty.value_or(kDefaultBzPenalty); }

  /// The one check of a discretization: throws InvalidOption (keys "degree", "bz_penalty",
  /// "eta") unless the degree is 1, 2 or 3, a BZ penalty goes with the BZ method, a fixed
  /// penalty has its eta and any eta is positive and finite.
  void check() const;
};

}  // namespace polydg
