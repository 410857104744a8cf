// The checks after a cut or merge (ValidationLevel): which elements, which checks. The checks
// themselves are physics/: region_checks.h (local) and mesh_checks.h (full). Private to cut/.
#pragma once

#include <vector>

#include "polydg/cut/cut.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg::cut_detail {

/// Relative volume balance above which an operation fails.
inline constexpr double kVolumeBalanceTolerance = 1e-10;

/// The checks after an operation on the elements it touched (see ValidationLevel).
void validateOperation(const PolyMesh& mesh, const MomentCache& moments,
                       const std::vector<ElementId>& touched, std::vector<char>& region,
                       ValidationLevel level, int degree, double sliverThreshold,
                       OperationValidation& v);

}  // namespace polydg::cut_detail
