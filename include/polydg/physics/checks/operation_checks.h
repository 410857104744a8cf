// The checks after an edit of a mesh (a cut, merge, refinement or coarsening): how much is
// checked (CheckLevel), on which elements, and what was found (OperationCheck). The checks
// themselves are region_checks.h (local) and mesh_checks.h (full); cut/ runs them after each
// operation, its one use of physics/.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// How much checking follows each operation.
enum class CheckLevel {
  None,   ///< volume bookkeeping only
  Local,  ///< geometric checks of the touched elements; DG patch test and rigid-mode count on
          ///< the touched elements plus one ring of neighbours (regionDgChecks() with
          ///< RegionCoupling::HoldingFaces); global volume balance
  Full,   ///< geometric checks of the whole mesh; global patch test and rigid modes
};

/// The outcome of the checks after one operation.
struct OperationCheck {
  CheckLevel level = CheckLevel::None;
  bool passed = true;
  std::size_t elementsChecked = 0;  ///< geometric checks
  std::size_t regionElements = 0;   ///< DG region (touched elements plus one ring)
  double patchTestError = 0.0;  ///< Local: the region's patch-test residual; Full: relative error
  /// Local: components of the region's coupling graph, its elements joined through the faces
  /// that hold them together (RegionCoupling::HoldingFaces); Full: of the mesh.
  std::size_t regionComponents = 0;
  std::size_t zeroModes = 0;    ///< expected: 6 * regionComponents
  double volumeRelError = 0.0;  ///< |V_before - V_removed - V_after| / V_before
  std::string failure;          ///< first failed check, one line; empty when passed
};

/// Relative volume balance above which an operation fails.
inline constexpr double kVolumeBalanceTolerance = 1e-10;

/// The checks of `level` after an operation on the elements it `touched`, with the DG checks
/// of degree `degree`, into `check`. Elements below `sliverThreshold` with no interior face
/// (isolated slivers) are left out of the DG region. `region` is scratch space (one flag per
/// element, zero on entry and exit).
void checkOperation(const PolyMesh& mesh, const MomentCache& moments,
                    const std::vector<ElementId>& touched, std::vector<char>& region,
                    CheckLevel level, int degree, double sliverThreshold, OperationCheck& check);

}  // namespace polydg
