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
#include "polydg/physics/checks/check_reports.h"

namespace polydg {

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
