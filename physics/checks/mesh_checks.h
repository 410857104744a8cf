// The checks polydg runs on a whole mesh, composed in one place: the geometric validation, the
// element-local DG checks, and the global patch test and zero-mode count. `polydg check`,
// `polydg mesh`, pipeline check steps, full cut validation and the model API all call
// checkMesh(); the per-operation region checks of a cut are in region_checks.h.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "physics/checks/dg_checks.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/physics/checks/check_reports.h"

namespace polydg {

/// Runs the checks `options` asks for: the geometric validation first; then, if it passed (or
/// was not asked for), the element-local DG checks and the global checks.
///
/// `moments`: the mesh's moment cache, up to date and of degree >= 2 * options.degree, or null.
/// With a cache nothing is integrated again; without, the local checks integrate only the
/// elements they check and their face neighbours (localDgChecksOfSelection()) and each global
/// check the whole mesh. Throws std::invalid_argument for a degree outside 1..3 or a cache of
/// too low degree.
MeshCheck checkMesh(const PolyMesh& mesh, const MeshCheckOptions& options,
                    const MomentCache* moments = nullptr);

/// One line per failed local DG check (none when they passed).
std::vector<std::string> failureMessages(const LocalDgCheck& c);

}  // namespace polydg
