#include "physics/checks/operation_checks.h"

#include <algorithm>
#include <sstream>
#include <string>

#include "physics/checks/mesh_checks.h"
#include "physics/checks/region_checks.h"
#include "polydg/mesh/geometry_checks.h"

namespace polydg {

void checkOperation(const PolyMesh& mesh, const MomentCache& moments,
                    const std::vector<ElementId>& touched, std::vector<char>& region,
                    CheckLevel level, int degree, double sliverThreshold, OperationCheck& v) {
  v.level = level;
  auto fail = [&](const std::string& message) {
    if (v.passed) v.failure = message;
    v.passed = false;
  };
  if (level == CheckLevel::None) return;
  if (level == CheckLevel::Local) {
    const GeometryCheck geometry = checkGeometryOf(mesh, touched);
    v.elementsChecked = touched.size();
    if (!geometry.passed)
      fail("geometry: " + (geometry.messages.empty() ? std::string("invalid element")
                                                     : geometry.messages.front()));
    if (touched.empty() || !geometry.passed) return;
    region.resize(mesh.numElements(), 0);
    std::vector<ElementId> members;
    auto add = [&](ElementId e) {
      if (!region[e.index()]) {
        region[e.index()] = 1;
        members.push_back(e);
      }
    };
    // Isolated slivers (below the sliver threshold, no interior face) are left out of the DG
    // region: they are reported as isolated and are too thin for a meaningful solve.
    auto isolatedSliver = [&](ElementId e) {
      if (!(moments.volume(e) < sliverThreshold)) return false;
      const auto& uses = mesh.element(e).faces;
      return std::none_of(uses.begin(), uses.end(),
                          [&](const FaceUse& u) { return !mesh.face(u.face).isBoundary(); });
    };
    for (ElementId e : touched) {
      if (isolatedSliver(e)) continue;
      add(e);
      for (const FaceUse& use : mesh.element(e).faces) {
        const Face& face = mesh.face(use.face);
        if (face.front.valid()) add(face.front);
        if (face.back.valid()) add(face.back);
      }
    }
    if (members.empty()) return;
    LocalDgCheckOptions options;
    options.basis.degree = degree;
    // Elements the region holds only through faces too narrow to hold their rotations count as
    // bodies of their own: what holds them is the rest of the mesh, outside the region.
    const RegionDgCheck dg =
        regionDgChecks(mesh, moments, region, options, RegionCoupling::HoldingFaces);
    for (ElementId e : members) region[e.index()] = 0;
    v.regionElements = dg.elements;
    v.regionComponents = dg.components;
    v.zeroModes = dg.zeroModes;
    v.patchTestError = dg.patchTestResidual;
    if (!dg.passed()) {
      std::ostringstream msg;
      msg << "DG region check: patch test residual " << dg.patchTestResidual << ", " << dg.zeroModes
          << " zero modes for " << dg.components << " components (expected " << 6 * dg.components
          << ")";
      fail(msg.str());
    }
    return;
  }
  // Full: the whole-mesh checks of `polydg check`, both global checks whatever the size.
  MeshCheckOptions options;
  options.physics.discretization.basis.degree = degree;
  options.local = false;
  options.patchTest = GlobalCheck::Always;
  options.rigidModes = GlobalCheck::Always;
  const MeshCheck c = checkMesh(mesh, options, moments.degree() >= 2 * degree ? &moments : nullptr);
  v.elementsChecked = mesh.numElements();
  if (c.patch) {
    v.regionElements = mesh.numElements();
    v.patchTestError = c.patch->relativeError;
  }
  if (c.rigid) {
    v.regionComponents = c.rigid->components;
    v.zeroModes = c.rigid->zeroModes;
  }
  if (!c.passed()) fail(c.failures().front());
}

}  // namespace polydg
