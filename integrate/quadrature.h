// Quadrature for integrands that are not polynomials (or to check exact integration): Gauss-
// Legendre rules, a conical-product rule on tetrahedra, and rules over arbitrary (non-convex)
// polyhedral elements through a signed cone decomposition.
#pragma once

#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg {

struct QuadraturePoint {
  Vec3 point;
  double weight;  ///< may be negative: signed cones of a non-convex element
};

/// n-point Gauss-Legendre rule on [0, 1]; exact for polynomials of degree <= 2n - 1.
void gaussLegendre01(int n, std::vector<double>& nodes, std::vector<double>& weights);

/// A rule on the tetrahedron (a, b, c, d), exact for polynomials of total degree <= `degree`
/// (Stroud's conical product of Gauss-Legendre rules). Weights carry the tetrahedron's signed
/// volume (positive when (b-a).((c-a)x(d-a)) > 0). Appends to `out`.
void appendTetrahedronRule(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, int degree,
                           std::vector<QuadraturePoint>& out);

/// A rule over element e, exact for polynomials of total degree <= `degree`, valid for
/// non-convex elements and faces with holes: the element is the signed sum of the cones from
/// its reference point o to each face, each cone the signed sum of tetrahedra (o, c_F, v_i,
/// v_i+1) over the face's edges, c_F the face's reference point.
std::vector<QuadraturePoint> elementQuadrature(const PolyMesh& mesh, ElementId e, int degree);

}  // namespace polydg
