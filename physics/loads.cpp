#include "polydg/physics/loads.h"

#include <cmath>

namespace polydg {

bool selects(const FaceSelector& selector, const PolyMesh& mesh, FaceId f, double meshDiagonal) {
  const Face& face = mesh.face(f);
  switch (selector.kind) {
    case FaceSelector::Kind::AllBoundary: return true;
    case FaceSelector::Kind::Plane: {
      const double tolerance = kPlaneSelectorTolerance * meshDiagonal;
      for (VertexId v : face.vertices)
        if (std::abs(mesh.position(v)[selector.axis] - selector.value) > tolerance) return false;
      return true;
    }
  }
  return false;
}

}  // namespace polydg
