// The coefficients of the DG form that a DiscretizationOptions describes: the penalty by its
// rule (per-element coercivity bounds, or a fixed eta) and the BZ superpenalty's factor.
#pragma once

#include "physics/dg/assembly.h"
#include "polydg/physics/dg/discretization.h"
#include "polydg/physics/dg/material.h"

namespace polydg {

/// The factor (L/h)^(2p) of the BZ superpenalty (BzPenalty::Super), p = basis.degree(): L is
/// `referenceLength`, or the diagonal of the mesh's bounding box if it is 0; h is the largest
/// element length, the bounding-box diagonal of an element (2 DgBasis::scale(), the length the
/// basis is scaled by). Dimensionless, so invariant to the model's unit and position; 1 on a
/// mesh of one element, n^(2p) on an n x n x n grid of a cube (L/h = n). One h for the whole
/// mesh: eta_F already grows as 1/h locally (area(F)/vol(K)), and a small cut piece does not
/// raise the factor (and the condition number) everywhere. Under uniform refinement eta_F then
/// scales as h^-(2p+1), Babuska and Zlamal's rate. Throws std::invalid_argument for a negative
/// or non-finite `referenceLength`.
double superpenaltyFactor(const PolyMesh& mesh, const DgBasis& basis, double referenceLength = 0.0);

/// What a FormCoefficients of the TraceBound rule points to: each element's bound eta_K and the
/// face area a_K its penalty is spread by (FormCoefficients::elementEta, elementFaceArea).
struct ElementPenalties {
  ElementData<double> eta;
  ElementData<double> faceArea;
};

/// The coefficients of the form of `disc` for `material`: the penalty by its rule (TraceBound:
/// the coercivity bounds of penaltyThreshold(), per element into `penalties`, which the form
/// then points to and which must outlive it; Fixed and Doubling: the given eta, on eq. 7's
/// face areas), and the BZ penalty's factor (`disc.bzPenalty`, superpenaltyFactor()).
/// `threshold` is the largest bound. Throws std::invalid_argument for a non-positive eta.
FormCoefficients formCoefficients(const PolyMesh& mesh, const DgBasis& basis,
                                  const MomentCache& moments, const FaceRoles& roles,
                                  const Material& material, const DiscretizationOptions& disc,
                                  ElementPenalties& penalties, double& threshold);

}  // namespace polydg
