// Quadrature over planar polygonal faces (non-convex, with holes) for integrands that are not
// polynomials: a signed triangle fan from the face's reference point with a collapsed
// Gauss-Legendre rule on each triangle.
#pragma once

#include <vector>

#include "integrate/quadrature.h"

namespace polydg {

/// A rule over face f, exact for polynomials of total degree <= `degree`: the face is the
/// signed sum of the triangles (c_F, v_i, v_i+1) over the edges of all its loops, c_F its
/// reference point, each signed by its orientation about the face normal (so the parts of
/// the fan outside a non-convex face or inside a hole cancel). Weights may be negative; they
/// sum to the face's area. Degenerate (zero-area) triangles contribute no points.
std::vector<QuadraturePoint> faceQuadrature(const PolyMesh& mesh, FaceId f, int degree);

/// Appends a rule on the triangle (a, b, c) exact to `degree`, weights multiplied by `sign`
/// times its area (Duffy's collapse of the square, Gauss-Legendre in both directions).
void appendTriangleRule(const Vec3& a, const Vec3& b, const Vec3& c, double sign, int degree,
                        std::vector<QuadraturePoint>& out);

}  // namespace polydg
