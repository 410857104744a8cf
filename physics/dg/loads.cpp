#include "polydg/physics/dg/loads.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace polydg {

FaceSelector FaceSelector::inBox(const Box3& b) {
  if (!b.min().allFinite() || !b.max().allFinite())
    throw std::invalid_argument("the box's corners must be finite");
  if ((b.min().array() > b.max().array()).any())
    throw std::invalid_argument("the box's first corner must not exceed its second in any axis");
  return {Kind::Box, Plane(), b};
}

std::string FaceSelector::describe() const {
  std::ostringstream s;
  s.precision(17);
  auto vector = [&](const Vec3& v) { s << v.x() << ',' << v.y() << ',' << v.z(); };
  switch (kind) {
    case Kind::AllBoundary: s << "the whole boundary"; break;
    case Kind::Plane:
      if (plane.axis >= 0) {
        s << "the plane " << char('x' + plane.axis) << " = " << plane.offset;
      } else {
        s << "the plane ";
        vector(plane.normal);
        s << ',' << plane.offset;
      }
      break;
    case Kind::Below:
      s << "below ";
      vector(plane.normal);
      s << ',' << plane.offset;
      break;
    case Kind::Box:
      s << "the box [";
      vector(box.min());
      s << "]-[";
      vector(box.max());
      s << ']';
      break;
  }
  return s.str();
}

bool selects(const FaceSelector& selector, const PolyMesh& mesh, FaceId f, double meshDiagonal) {
  const Face& face = mesh.face(f);
  switch (selector.kind) {
    case FaceSelector::Kind::AllBoundary: return true;
    case FaceSelector::Kind::Plane: {
      const Plane& p = selector.plane;
      const double tolerance = kPlaneSelectorTolerance * meshDiagonal * p.normal.norm();
      for (VertexId v : face.vertices)
        if (std::abs(p.normal.dot(mesh.position(v)) - p.offset) > tolerance) return false;
      return true;
    }
    case FaceSelector::Kind::Below:
      for (VertexId v : face.vertices)
        if (selector.plane.side(mesh.position(v)) > 0) return false;
      return true;
    case FaceSelector::Kind::Box:
      for (VertexId v : face.vertices)
        if (!selector.box.contains(mesh.position(v))) return false;
      return true;
  }
  return false;
}

}  // namespace polydg
