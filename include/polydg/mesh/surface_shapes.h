// Closed triangle surfaces made in code, whose enclosed volume is known exactly from their
// vertices: spheres, tori, torus knots, boxes, plates, and their combinations (several shells,
// cavities). Used by tests, benchmarks and examples.
#pragma once

#include "polydg/mesh/surface.h"

namespace polydg {

/// An icosphere: the icosahedron subdivided `levels` times, vertices on the sphere of `radius`
/// about `centre` (20 * 4^levels triangles), outward-oriented.
TriangleSurface icosphere(const Vec3& centre, double radius, int levels);

/// A latitude-longitude sphere with `rings` rings and `segments` segments (2 * segments *
/// (rings - 1) triangles): sizes between the icosphere's powers of four.
TriangleSurface uvSphere(const Vec3& centre, double radius, int rings, int segments);

/// A torus about the z axis through `centre`: tube radius r around a circle of radius R, with
/// `nu` segments around the axis and `nv` around the tube (2 nu nv triangles).
TriangleSurface torus(const Vec3& centre, double R, double r, int nu, int nv);

/// A (p, q) torus knot tube: the curve winds p times around the z axis and q times through the
/// hole of a torus of radii R (major) and `a` (minor of the curve); the tube has radius r,
/// `nu` segments along the curve and `nv` around it (2 nu nv triangles).
TriangleSurface torusKnot(int p, int q, double R, double a, double r, int nu, int nv);

/// The surface of an axis-aligned box, two triangles per side.
TriangleSurface boxSurface(const Box3& box);

/// The union of disjoint surfaces (several shells).
TriangleSurface combine(const TriangleSurface& a, const TriangleSurface& b);

/// The same surface with every triangle reversed (for a cavity inside another shell).
TriangleSurface reversedSurface(const TriangleSurface& s);

/// x -> scale * x + offset for every vertex.
TriangleSurface transformed(const TriangleSurface& s, double scale, const Vec3& offset);

}  // namespace polydg
