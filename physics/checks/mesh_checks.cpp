#include "physics/checks/mesh_checks.h"

#include <memory>
#include <sstream>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "polydg/integrate/monomials.h"
#include "polydg/mesh/geometry.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// Whether a global check runs for `dofs` unknowns; if not (but asked for), a note says why.
bool wanted(GlobalCheck when, std::size_t dofs, const MeshCheckOptions& options, const char* what,
            std::vector<std::string>& notes) {
  switch (when) {
    case GlobalCheck::Never: return false;
    case GlobalCheck::Always: return true;
    case GlobalCheck::UpToLimit:
      if (dofs <= options.globalDofLimit) return true;
      notes.push_back(std::string(what) + " not computed: " + std::to_string(dofs) + " DOFs > " +
                      std::to_string(options.globalDofLimit) + "; element-local checks only");
      return false;
  }
  return false;
}

/// The elements the local checks cover when whole grid cells are checked once for all.
std::vector<char> oneGridCellForAll(const PolyMesh& mesh) {
  std::vector<char> only(mesh.numElements(), 1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numElements(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e)
                        only[e] = isGridHexahedron(mesh, ElementId(e)) ? 0 : 1;
                    });
  for (char& flag : only)  // the first grid cell stands for all
    if (flag == 0) {
      flag = 1;
      break;
    }
  return only;
}

}  // namespace

bool MeshCheck::rigidPassed() const {
  if (!rigid) return true;
  for (std::size_t modes : rigid->zeroModesPerComponent)
    if (modes != 6) return false;
  return true;
}

bool MeshCheck::passed() const {
  return geometryPassed() && (!local || local->passed()) &&
         (!patch || patch->relativeError < kLocalPatchTestTolerance) && rigidPassed();
}

std::vector<std::string> MeshCheck::failures() const {
  std::vector<std::string> out;
  if (geometry && !geometry->passed) {
    if (geometry->messages.empty()) out.push_back("geometry: the mesh is invalid");
    for (const std::string& m : geometry->messages) out.push_back("geometry: " + m);
  }
  if (local)
    for (std::string& m : failureMessages(*local)) out.push_back(std::move(m));
  if (patch && !(patch->relativeError < kLocalPatchTestTolerance)) {
    std::ostringstream s;
    s << "global patch test (degree " << degree << "): relative error " << patch->relativeError
      << " above " << kLocalPatchTestTolerance;
    out.push_back(s.str());
  }
  if (!rigidPassed())
    out.push_back("the global stiffness has " + std::to_string(rigid->zeroModes) +
                  " zero modes, expected 6 per component (" +
                  std::to_string(6 * rigid->components) + ")");
  return out;
}

MeshCheck checkMesh(const PolyMesh& mesh, const MeshCheckOptions& options,
                    const MomentCache* moments) {
  options.physics.discretization.check();
  if (moments && moments->degree() < 2 * options.degree())
    throw std::invalid_argument("checkMesh: the moments are of degree " +
                                std::to_string(moments->degree()) + ", the checks need " +
                                std::to_string(2 * options.degree()));
  MeshCheck c;
  c.degree = options.degree();
  c.dofs = mesh.numElements() * 3 * numMonomials(options.degree());
  if (options.geometry) c.geometry = checkGeometry(mesh, options.geometryOptions);
  if (!c.geometryPassed()) {
    c.notes.push_back("DG checks skipped: the mesh failed the geometric validation");
    return c;
  }
  const PhysicsCheckOptions& physics = options.physics;
  const bool patch = wanted(options.patchTest, c.dofs, options, "global patch test", c.notes);
  const bool rigid = wanted(options.rigidModes, c.dofs, options, "global rigid modes", c.notes);
  // A global check reads every element's moments: integrate them once for all the checks.
  std::unique_ptr<MomentCache> own;
  if (!moments && (patch || rigid)) {
    own = std::make_unique<MomentCache>(mesh, 2 * options.degree());
    c.facesIntegrated += own->update();
    moments = own.get();
  }

  if (options.local) {
    const Stopwatch watch;
    LocalDgCheckOptions local;
    local.basis = physics.discretization.basis;
    local.material = physics.material;
    if (options.oneGridCellForAll) local.only = oneGridCellForAll(mesh);
    if (moments) {
      c.local = localDgChecks(mesh, *moments, local);
    } else {
      if (local.only.empty()) local.only.assign(mesh.numElements(), 1);
      c.local = localDgChecksOfSelection(mesh, local);
      c.facesIntegrated += c.local->facesIntegrated;
    }
    c.localSeconds = watch.seconds();
  }
  if (patch) {
    const Stopwatch watch;
    c.patch = patchTest(mesh, physics, moments);
    c.patchSeconds = watch.seconds();
  }
  if (rigid) {
    const Stopwatch watch;
    c.rigid = rigidModes(mesh, physics, moments);
    c.rigidSeconds = watch.seconds();
  }
  return c;
}

std::vector<std::string> failureMessages(const LocalDgCheck& c) {
  std::vector<std::string> out;
  if (!(c.maxPatchTestError < kLocalPatchTestTolerance)) {
    std::ostringstream s;
    s << "local patch test (degree " << c.degree << "): " << c.patchTestFailures
      << " element(s) above the tolerance " << kLocalPatchTestTolerance << ", worst "
      << c.maxPatchTestError << " at element " << c.worstPatchTestElement.value;
    out.push_back(s.str());
  }
  if (c.elementsWithWrongRigidModes > 0) {
    std::ostringstream s;
    s << c.elementsWithWrongRigidModes
      << " element stiffness matrices without exactly 6 zero modes, the first element "
      << c.firstWrongRigidModeElement.value;
    out.push_back(s.str());
  }
  if (c.nonDefiniteElements > 0) {
    std::ostringstream s;
    s << c.nonDefiniteElements << " element(s) whose local IP matrix is not positive definite";
    out.push_back(s.str());
  }
  return out;
}

}  // namespace polydg
