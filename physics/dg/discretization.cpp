#include "physics/dg/form_coefficients.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace polydg {

void DiscretizationOptions::check() const {
  if (basis.degree < 1 || basis.degree > 3) throw InvalidOption("degree", "must be 1, 2 or 3");
  if (bzPenalty && method != Method::BZ)
    throw InvalidOption("bz_penalty", "a BZ penalty is for the BZ method: use method bz");
  if (penalty.rule == PenaltyRule::Fixed && !penalty.eta)
    throw InvalidOption("eta", "a fixed penalty needs its eta");
  if (penalty.eta && !(*penalty.eta > 0.0 && *penalty.eta < 1e300))
    throw InvalidOption("eta", "the penalty must be a positive number");
}

double superpenaltyFactor(const PolyMesh& mesh, const DgBasis& basis, double referenceLength) {
  if (!(referenceLength >= 0.0 && std::isfinite(referenceLength)))
    throw std::invalid_argument("the BZ reference length must be positive and finite (or 0)");
  double length = referenceLength;
  if (length == 0.0) {
    Eigen::AlignedBox3d box;
    for (const Vec3& x : mesh.positions()) box.extend(x);
    length = box.isEmpty() ? 0.0 : box.diagonal().norm();
  }
  double h = 0.0;
  for (std::size_t i = 0; i < mesh.numElements(); ++i)
    h = std::max(h, 2.0 * basis.scale(ElementId(i)));
  if (!(h > 0.0 && length > 0.0)) return 1.0;  // no elements: no faces to penalize
  return std::pow(length / h, 2 * basis.degree());
}

FormCoefficients formCoefficients(const PolyMesh& mesh, const DgBasis& basis,
                                  const MomentCache& moments, const FaceRoles& roles,
                                  const Material& material, const DiscretizationOptions& disc,
                                  ElementPenalties& penalties, double& threshold) {
  FormCoefficients form;
  form.method = disc.method;
  form.mu = material.mu();
  form.lambda = material.lambda();
  penalties.faceArea = meanCoupledFaceAreas(mesh, moments, roles);
  ElementData<double>& elementEta = penalties.eta;
  elementEta = elementPenaltyThresholds(mesh, basis, moments, roles, penalties.faceArea);
  threshold =
      elementEta.size() == 0 ? 0.0 : *std::max_element(elementEta.begin(), elementEta.end());
  switch (disc.penalty.rule) {
    case PenaltyRule::TraceBound:
      form.eta = disc.penalty.safety * threshold;
      if (form.eta <= 0.0) form.eta = 1.0;  // no coupled faces: any positive value
      form.elementFaceArea = &penalties.faceArea;
      if (disc.penalty.local) {
        // Elements without coupled faces have no penalty terms; any positive value does.
        for (double& eta : elementEta) eta = eta > 0.0 ? disc.penalty.safety * eta : form.eta;
        form.elementEta = &elementEta;
      }
      break;
    case PenaltyRule::Fixed: form.eta = disc.penalty.eta.value_or(0.0); break;
    case PenaltyRule::Doubling: form.eta = disc.penalty.eta.value_or(kFirstDoublingEta); break;
  }
  if (!(form.eta > 0.0)) throw std::invalid_argument("the penalty eta must be positive");
  if (disc.method == Method::BZ && disc.bzPenaltyInEffect() == BzPenalty::Super) {
    form.bzFactor = superpenaltyFactor(mesh, basis, disc.bzReferenceLength);
    form.bzFactorOnMean = basis.degree() == 1;  // see BzPenalty::Super
  }
  return form;
}

}  // namespace polydg
