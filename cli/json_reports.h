// JSON forms of the library's reports, shared by the subcommands' --report files.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/cut/cut.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/validate.h"
#include "polydg/physics/linear_solver.h"
#include "polydg/physics/local_integrators.h"
#include "polydg/physics/validation.h"

namespace polydg::cli {

nlohmann::json toJson(const ValidationReport& r);
/// The element-local DG checks as keys of a report's `validation` section: dg_degree,
/// patch_test_error (max over elements), patch_test_tolerance, patch_test_failures,
/// worst_patch_test_element, rigid_mode_failures (elements whose stiffness has not exactly six
/// zero modes), first_rigid_mode_failure, non_definite_elements, dg_elements_checked, dg_passed,
/// and dg_seconds = `seconds` (wall time of the checks with the moments they need). Element ids
/// are null when there is none.
nlohmann::json toJson(const LocalDgCheck& c, double seconds);
/// One line per failed local DG check (none when they passed), for reports and the terminal.
std::vector<std::string> failureMessages(const LocalDgCheck& c);
nlohmann::json toJson(const Box3& box);
/// The `polydg mesh` report: input, output, volume_rel_error, validation, timings_s.
nlohmann::json toJson(const MeshingReport& r);
/// "none", "local" or "full".
std::string toString(ValidationLevel level);
/// "ip" or "bz", as `--method` takes them.
std::string toString(Method method);
/// "auto", "cholesky" or "cg", as `--solver` takes them.
std::string toString(SolverKind kind);
/// One cut or merge operation, as `polydg cut` and `polydg run` report it: op, elements_split,
/// pieces_created, elements_removed, volume_removed, slivers, slivers_merged,
/// isolated_slivers, faces_reintegrated, faces_total, left_whole {count, first_ids (at most
/// 20)}, validation {passed, level, elements_checked, region_elements, patch_test_error,
/// region_components, zero_modes, volume_rel_error, failure}, time_s.
nlohmann::json toJson(const OperationReport& r);

}  // namespace polydg::cli
