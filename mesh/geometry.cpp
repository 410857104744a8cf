#include "polydg/mesh/geometry.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <boost/container/small_vector.hpp>

namespace polydg {

Vec3 areaVector(const PolyMesh& mesh, FaceId f) {
  const Face& face = mesh.face(f);
  const Vec3& c = faceReferencePoint(mesh, f);
  Vec3 twiceArea = Vec3::Zero();
  // Each corner's offset is taken once and serves the two edges it ends; the sum runs over the
  // edges in loop order, closing edge last. The outer loop starts at c: its first corner's
  // offset is zero, and the two products with it (first and closing edge) are zeros, which the
  // sum (+0 so far, and never -0) does not change: they are skipped.
  const auto outer = face.numLoops() > 0 ? face.loop(0) : std::span<const VertexId>();
  if (outer.size() > 1) {
    Vec3 a = mesh.position(outer[1]) - c;
    for (std::size_t i = 2; i < outer.size(); ++i) {
      const Vec3 b = mesh.position(outer[i]) - c;
      twiceArea += a.cross(b);
      a = b;
    }
  }
  for (std::size_t k = 1; k < face.numLoops(); ++k) {
    const auto loop = face.loop(k);
    if (loop.empty()) continue;
    const Vec3 first = mesh.position(loop[0]) - c;
    Vec3 a = first;
    for (std::size_t i = 1; i < loop.size(); ++i) {
      const Vec3 b = mesh.position(loop[i]) - c;
      twiceArea += a.cross(b);
      a = b;
    }
    twiceArea += a.cross(first);
  }
  return 0.5 * twiceArea;
}

namespace {
Vec3 normalized(const Vec3& a) {
  const double norm = a.norm();
  return norm > 0.0 ? Vec3(a / norm) : Vec3::Zero();
}
}  // namespace

Vec3 unitNormal(const PolyMesh& mesh, FaceId f) { return normalized(areaVector(mesh, f)); }

Box3 faceBounds(const PolyMesh& mesh, FaceId f) {
  Box3 box;
  for (VertexId v : mesh.face(f).vertices) box.extend(mesh.position(v));
  return box;
}

Box3 elementBounds(const PolyMesh& mesh, ElementId e) {
  Box3 box;
  for (const FaceUse& use : mesh.element(e).faces)
    for (VertexId v : mesh.face(use.face).vertices) box.extend(mesh.position(v));
  return box;
}

std::vector<VertexId> elementVertices(const PolyMesh& mesh, ElementId e) {
  std::vector<VertexId> vertices;
  for (const FaceUse& use : mesh.element(e).faces)
    for (VertexId v : mesh.face(use.face).vertices) vertices.push_back(v);
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  return vertices;
}

Vec3 elementReferencePoint(const PolyMesh& mesh, ElementId e) {
  const Box3 box = elementBounds(mesh, e);
  return 0.5 * (box.min() + box.max());
}

double signedVolume(const PolyMesh& mesh, ElementId e) {
  // Signed cones from the centre of the element's bounding box (elementReferencePoint()):
  // cone volume = height * area / 3, and a.dot(c - o) = area * height.
  const Vec3 o = elementReferencePoint(mesh, e);
  double threeVolume = 0.0;
  for (const FaceUse& use : mesh.element(e).faces) {
    const double h = areaVector(mesh, use.face).dot(faceReferencePoint(mesh, use.face) - o);
    threeVolume += use.reversed ? -h : h;
  }
  return threeVolume / 3.0;
}

std::vector<double> signedVolumes(const PolyMesh& mesh) {
  std::vector<double> volumes(mesh.numElements());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, volumes.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e)
                        volumes[e] = signedVolume(mesh, ElementId(e));
                    });
  return volumes;
}

double planarityDeviation(const PolyMesh& mesh, FaceId f) {
  return planarityDeviation(mesh, f, areaVector(mesh, f));
}

double planarityDeviation(const PolyMesh& mesh, FaceId f, const Vec3& areaVector) {
  const Face& face = mesh.face(f);
  const Vec3 n = normalized(areaVector);
  const Vec3& c = faceReferencePoint(mesh, f);
  Vec3 mean = Vec3::Zero();
  for (VertexId v : face.vertices) mean += mesh.position(v) - c;
  mean /= static_cast<double>(face.vertices.size());
  double worst = 0.0;
  for (VertexId v : face.vertices)
    worst = std::max(worst, std::abs(n.dot(mesh.position(v) - c - mean)));
  return worst;
}

Box3 meshBounds(const PolyMesh& mesh) {
  Box3 box;
  for (const Vec3& p : mesh.positions()) box.extend(p);
  return box;
}

void transform(PolyMesh& mesh, double scale, const Vec3& offset) {
  for (Vec3& p : mesh.positions()) p = scale * p + offset;
}

bool isGridHexahedron(const PolyMesh& mesh, ElementId e) {
  const Element& element = mesh.element(e);
  if (element.faces.size() != 6) return false;
  for (const FaceUse& use : element.faces) {
    const Face& face = mesh.face(use.face);
    if (face.numLoops() != 1 || face.vertices.size() != 4) return false;
    const Vec3 n = unitNormal(mesh, use.face);
    if (std::abs(n.x()) != 1.0 && std::abs(n.y()) != 1.0 && std::abs(n.z()) != 1.0) return false;
  }
  return true;
}

bool isConvex(const PolyMesh& mesh, ElementId e, double relativeTolerance) {
  // The corners of every face, in one array: a vertex met more than once is tested more than
  // once, which changes no answer and costs less than finding the distinct ones.
  boost::container::small_vector<Vec3, 64> corners;
  Box3 box;
  for (const FaceUse& use : mesh.element(e).faces)
    for (VertexId v : mesh.face(use.face).vertices) {
      corners.push_back(mesh.position(v));
      box.extend(corners.back());
    }
  const double tolerance = relativeTolerance * box.diagonal().norm();
  for (const FaceUse& use : mesh.element(e).faces) {
    // A face narrower than the tolerance (area / diameter) cannot show non-convexity at that
    // tolerance, and the normal of a face of round-off width means nothing.
    const Vec3 a = areaVector(mesh, use.face);
    if (a.norm() <= tolerance * faceBounds(mesh, use.face).diagonal().norm()) continue;
    Vec3 n = a.normalized();
    if (use.reversed) n = -n;
    const Vec3& c = faceReferencePoint(mesh, use.face);
    for (const Vec3& x : corners)
      if (n.dot(x - c) > tolerance) return false;
  }
  return true;
}

}  // namespace polydg
