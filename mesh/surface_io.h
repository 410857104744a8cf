// Reads a triangle surface from any file format assimp understands (OBJ, STL, PLY, OFF, glTF,
// ...), with node transforms baked in, polygons triangulated exactly, and vertices welded by
// exact position across all meshes.
#pragma once

#include <cstddef>
#include <string>

#include "mesh/surface.h"

namespace polydg {

/// What readSurface() found and did. Counts are over the whole scene after node transforms are
/// applied (a mesh used by two nodes counts twice).
struct SurfaceReadInfo {
  std::size_t meshes = 0;             ///< meshes in the scene (assimp joins them per material)
  std::size_t inputVertices = 0;      ///< vertices over all meshes, before welding
  std::size_t weldedVertices = 0;     ///< vertices of the result (distinct positions)
  std::size_t triangles = 0;          ///< triangles of the result
  std::size_t polygons = 0;           ///< faces of four or more corners, triangulated here
  std::size_t fannedPolygons = 0;     ///< of those, split into a fan: zero area or self-crossing
  std::size_t droppedDegenerate = 0;  ///< triangles dropped: two corners at one position
  std::size_t ignoredPoints = 0;      ///< point primitives skipped
  std::size_t ignoredLines = 0;       ///< line primitives skipped
};

/// Reads the triangles of every mesh in the file at `path`, in any format assimp reads.
///
/// Every node's transform is applied to the meshes it references (instanced meshes appear once
/// per instance). Corners are welded across all meshes: two corners become one vertex exactly
/// when their coordinates are bitwise equal, -0.0 counting as 0.0. Attributes (normals, texture
/// coordinates, materials) play no part. A face of four or more corners is replaced by the
/// exact constrained triangulation of its projection onto the coordinate plane where it is
/// largest (triangulateFace, mesh/face_triangulation.h): n - 2 triangles over its own corners,
/// wound like the face, non-convex faces included. assimp's aiProcess_Triangulate is not used:
/// its ear clipping returns overlapping triangles for some non-convex faces. A face of zero area
/// or with crossing edges has no such triangulation and becomes a fan from its first corner.
/// A triangle with two corners at one position is dropped and counted; every other triangle is
/// kept as it is, with the winding the file gives it (no reorientation, no removal of zero-area
/// or duplicate triangles). Point and line primitives are skipped and counted.
///
/// Before assimp reads an OFF or PLY file, its header's vertex, face and element counts are
/// checked against the file size: assimp allocates what they declare before reading the data.
///
/// The result holds only vertices used by a kept triangle, numbered in order of first use
/// (meshes in scene order, triangles in mesh order, corners in triangle order); coordinates are
/// those of the file as assimp parsed them (single precision, widened exactly to double), with
/// -0.0 stored as 0.0.
///
/// If `info` is not null it receives the counts above. Throws std::runtime_error with a
/// one-line message naming the file when the file is missing, its header declares more items
/// than it can hold, assimp cannot read it, it holds no meshes or only points and lines, no
/// triangle survives welding, or a used vertex has a non-finite coordinate. Nothing is printed:
/// polydg never creates assimp's DefaultLogger, so assimp logs to its null logger unless the
/// application installs one itself.
TriangleSurface readSurface(const std::string& path, SurfaceReadInfo* info = nullptr);

}  // namespace polydg
