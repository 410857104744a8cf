// Basic geometric quantities of faces and elements of a PolyMesh: area vectors, planes,
// bounding boxes, signed volumes. Higher moments live in integrate/.
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

using Box3 = Eigen::AlignedBox3d;

/// The face's area vector: area times unit normal, by Newell's formula over all loops (holes,
/// wound the other way, subtract). Computed about the face's first vertex, so it does not lose
/// precision far from the origin.
Vec3 areaVector(const PolyMesh& mesh, FaceId f);

/// Unit normal of the face (zero vector for a degenerate face of zero area).
Vec3 unitNormal(const PolyMesh& mesh, FaceId f);

/// The face's reference point: its first vertex. Face moments are taken about it.
inline const Vec3& faceReferencePoint(const PolyMesh& mesh, FaceId f) {
  return mesh.position(mesh.face(f).vertices.front());
}

/// Bounding box of the face's vertices.
Box3 faceBounds(const PolyMesh& mesh, FaceId f);

/// Bounding box of the element's vertices.
Box3 elementBounds(const PolyMesh& mesh, ElementId e);

/// The element's distinct vertices (those of its faces' loops), in increasing order.
std::vector<VertexId> elementVertices(const PolyMesh& mesh, ElementId e);

/// The element's reference point (local origin): the centre of its bounding box. Element moments
/// are taken about it. Exact in floating point for dyadic coordinates.
Vec3 elementReferencePoint(const PolyMesh& mesh, ElementId e);

/// Signed volume of the element, positive when its faces are oriented outward. Sum of signed
/// cones from the element's reference point to its faces.
double signedVolume(const PolyMesh& mesh, ElementId e);

/// signedVolume() of every element, in element order, computed in parallel.
std::vector<double> signedVolumes(const PolyMesh& mesh);

/// Largest distance of a face vertex from the face's plane (through the vertex mean, with the
/// Newell normal).
double planarityDeviation(const PolyMesh& mesh, FaceId f);

/// planarityDeviation() with the face's areaVector() computed by the caller.
double planarityDeviation(const PolyMesh& mesh, FaceId f, const Vec3& areaVector);

/// Bounding box of all vertices.
Box3 meshBounds(const PolyMesh& mesh);

/// Applies x -> scale * x + offset to every vertex.
void transform(PolyMesh& mesh, double scale, const Vec3& offset);

/// True for an element that is a whole grid cell: six faces, each a single quadrilateral with
/// an exactly axis-aligned normal. All such elements of one grid are congruent boxes.
bool isGridHexahedron(const PolyMesh& mesh, ElementId e);

/// True if the element is convex: every vertex on the inner side of every face plane, within
/// `relativeTolerance` times the element's size (a reporting statistic, not a decision).
bool isConvex(const PolyMesh& mesh, ElementId e, double relativeTolerance = 1e-9);

}  // namespace polydg
