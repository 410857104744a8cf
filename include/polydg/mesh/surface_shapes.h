// Closed triangle surfaces made in code, whose enclosed volume is known exactly from their
// vertices: spheres, a bowl, tori, torus knots, boxes, a twisted tapered prism, blocks with
// through-holes, and their combinations (several shells, cavities). Used by tests, benchmarks
// and examples.
#pragma once

#include <array>
#include <vector>

#include "polydg/mesh/surface.h"

namespace polydg {

/// An icosphere: the icosahedron subdivided `levels` times, vertices on the sphere of `radius`
/// about `centre` (20 * 4^levels triangles), outward-oriented.
TriangleSurface icosphere(const Vec3& centre, double radius, int levels);

/// A latitude-longitude sphere with `rings` rings and `segments` segments (2 * segments *
/// (rings - 1) triangles): sizes between the icosphere's powers of four.
TriangleSurface uvSphere(const Vec3& centre, double radius, int rings, int segments);

/// A hemispherical bowl: the solid shell between the spheres of radii `inner` < `outer` about
/// `centre`, below the plane z = centre.z, where it ends in a flat annular rim. `segments`
/// (>= 4) around the z axis and segments / 4 rings from each bottom pole up to the rim (the two
/// hemispheres' vertices on the same rays): 4 segments rings triangles.
/// Closed, outward-oriented (the inner hemisphere faces the bowl's hollow, the rim faces +z),
/// edge- and vertex-manifold. Its enclosed volume approaches (2/3) pi (outer^3 - inner^3) from
/// below as `segments` grows (the vertices are on the spheres). Throws std::invalid_argument for
/// radii not 0 < inner < outer or fewer than 4 segments.
TriangleSurface bowlSurface(const Vec3& centre, double inner, double outer, int segments);

/// A torus about the z axis through `centre`: tube radius r around a circle of radius R, with
/// `nu` segments around the axis and `nv` around the tube (2 nu nv triangles).
TriangleSurface torus(const Vec3& centre, double R, double r, int nu, int nv);

/// A (p, q) torus knot tube: the curve winds p times around the z axis and q times through the
/// hole of a torus of radii R (major) and `a` (minor of the curve); the tube has radius r,
/// `nu` segments along the curve and `nv` around it (2 nu nv triangles).
TriangleSurface torusKnot(int p, int q, double R, double a, double r, int nu, int nv);

/// The surface of an axis-aligned box, two triangles per side.
TriangleSurface boxSurface(const Box3& box);

/// A CAD-like part: the rectangle `width` x `depth` (centred on the z axis, sides along x and
/// y) extruded `height` along +z in `slices` slices, turning `turns` full turns about the z axis
/// and tapering linearly to a point, the apex, at the top. Slice k (0 .. slices - 1) is the
/// rectangle scaled by 1 - k / slices and turned by 2 pi turns k / slices, at z = height k /
/// slices; the last joins the apex with four triangles. `offset` moves the whole part. 8 slices
/// - 2 triangles, outward-oriented, closed and manifold, without self-intersections for a
/// small turn per slice (1 turn in 200 slices). Its corners come from std::cos and std::sin, so
/// many lie within round-off of a plane they are meant to be on (x = 3.75 at a quarter turn),
/// as a CAD export's do; near the apex its triangles are slivers. Throws std::invalid_argument
/// for a size not positive or fewer than one slice.
TriangleSurface twistedTaperedPrism(const Vec3& offset, double width, double depth, double height,
                                    int slices, double turns);

/// Cell walls along x, y and z of swissCheeseBlock(): each list increasing, first and last
/// the block's sides, so walls[a].size() - 1 cells along axis a.
using CheeseWalls = std::array<std::vector<double>, 3>;

/// A "Swiss cheese": the block [walls[0].front(), walls[0].back()] x ... divided into cells by
/// the walls, with square through-holes one cell wide along all three axes. Hole rows are the
/// cell indices i with i % 3 == 1 and i + 1 < n_a (n_a cells along axis a: never two adjacent,
/// never on the block's sides); every cell with at least two hole indices is removed: the
/// x-holes are the rows (j, k) of hole indices in y and z, likewise along y and z, and each
/// x-hole crosses the y- and z-holes it meets. Each side between a kept cell and a removed or
/// outside cell gives two triangles, outward. The surface is closed, consistently oriented,
/// edge- and vertex-manifold (no two hole rows are adjacent); its vertices are the walls'
/// coordinates, so its enclosed volume is swissCheeseVolume(walls). Throws
/// std::invalid_argument for fewer than 3 cells along an axis or walls not increasing.
TriangleSurface swissCheeseBlock(const CheeseWalls& walls);

/// swissCheeseBlock() with cells[a] equal cells along axis a of `box` (walls at
/// box.min() + box.sizes() * i / cells, exact for an integer box with integer cells).
TriangleSurface swissCheeseBlock(const Box3& box, const std::array<int, 3>& cells);

/// The enclosed volume of swissCheeseBlock(walls): the sum of its kept cells' volumes.
double swissCheeseVolume(const CheeseWalls& walls);

/// The walls of `cells` equal cells along each axis of `box`.
CheeseWalls uniformCheeseWalls(const Box3& box, const std::array<int, 3>& cells);

/// The union of disjoint surfaces (several shells).
TriangleSurface combine(const TriangleSurface& a, const TriangleSurface& b);

/// The same surface with every triangle reversed (for a cavity inside another shell).
TriangleSurface reversedSurface(const TriangleSurface& s);

/// x -> scale * x + offset for every vertex.
TriangleSurface transformed(const TriangleSurface& s, double scale, const Vec3& offset);

}  // namespace polydg
