// Exact monomial moments over polygonal faces and polyhedral elements by the divergence theorem
// (volume -> faces -> edges), for arbitrary non-convex elements and faces with holes.
//
// Method. For a polynomial homogeneous of degree k about a point o, Euler's identity
// x.grad f = k f and the divergence theorem give
//     int_P f dV = 1/(k+3) sum_F h_F int_F f dA,   h_F = n_F . (c_F - o),
// with n_F the outward unit normal and c_F any point of face F. In the plane of F the same
// identity about the face's reference point c_F reduces the face integral to one term per edge
// (a, b) (positions relative to c_F):
//     int_F (x-c_F)^alpha dA = sum_edges 2 A_ab alpha!/(k+2)! [c^alpha] h_k(a.c, b.c),
// where A_ab = (a x b).n_F / 2 is the signed area of the triangle (c_F, a, b), h_k(s, t) =
// sum_{i+j=k} s^i t^j, and [c^alpha] takes the coefficient of c^alpha in that polynomial of c
// (the simplex moment formula; a polynomial in the edge's endpoints). Faces with holes and
// non-convex faces need no special treatment: the signed terms cancel outside the face. Moments of
// a face are taken about its reference point c_F (its first vertex) and shifted, per element, to
// the element's local origin by the binomial theorem. All orderings follow integrate/monomials.h.
#pragma once

#include <span>
#include <vector>

#include "polydg/integrate/monomials.h"
#include "polydg/mesh/geometry.h"

namespace polydg {

/// Face moments: out[i] = int_F (x - c_F)^alpha_i dA for i < numMonomials(degree), with c_F =
/// faceReferencePoint(mesh, f) and the area measured positive (independent of which element
/// uses the face). degree <= kMaxMomentDegree. `normal` receives the unit normal used.
void faceMoments(const PolyMesh& mesh, FaceId f, int degree, std::span<double> out, Vec3& normal);

/// Shifts moments taken about point p to moments about point q:
///   out[alpha] = sum_{beta <= alpha} C(alpha, beta) d^(alpha - beta) in[beta],  d = p - q.
/// `in` and `out` may not alias.
void shiftMoments(int degree, const Vec3& d, std::span<const double> in, std::span<double> out);

/// Adds one face's contribution to an element's moments about `origin`:
///   out[alpha] += sign * h / (|alpha| + 3) * int_F (x - origin)^alpha dA,
/// with h = normal . (faceRef - origin) and sign = -1 if the element uses the face reversed.
/// `faceMoments` are about `faceRef`. `scratch` must hold numMonomials(degree) values.
void accumulateElementMoments(int degree, std::span<const double> faceMoments, const Vec3& faceRef,
                              const Vec3& normal, bool reversed, const Vec3& origin,
                              std::span<double> scratch, std::span<double> out);

/// One-shot: element moments int_K (x - origin)^alpha dV, computing each face's moments.
std::vector<double> elementMoments(const PolyMesh& mesh, ElementId e, int degree,
                                   const Vec3& origin);

/// One-shot: element moments about elementReferencePoint(mesh, e).
std::vector<double> elementMoments(const PolyMesh& mesh, ElementId e, int degree);

/// Moments normalized to be scale- and translation-free: m_alpha / (V * s^|alpha|), where V is
/// the volume (moments[0]) and s the given length (typically the element's bounding-box
/// diagonal).
std::vector<double> normalizedMoments(std::span<const double> moments, int degree, double length);

}  // namespace polydg
