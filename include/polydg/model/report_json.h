// The JSON form of every report of the model's operations, written in this one place: the
// `--report` files of the polydg commands, the per-input reports of pipelines, and the dicts
// the Python module returns all come from these functions, so their keys agree.
#pragma once

#include <nlohmann/json.hpp>

#include "polydg/model/model.h"
#include "polydg/model/scene.h"

namespace polydg {

nlohmann::json toJson(const Box3& box);  ///< {min, max}, null for an empty box
nlohmann::json toJson(const Provenance& p);
/// The geometric validation: passed, counts, volume range, problems {...}, messages.
nlohmann::json toJson(const GeometryCheck& r);
/// The element-local DG checks as keys of a report's `validation` section: dg_degree,
/// patch_test_error (max over elements), patch_test_tolerance, patch_test_failures,
/// worst_patch_test_element, rigid_mode_failures (elements whose stiffness has not exactly six
/// zero modes), first_rigid_mode_failure, non_definite_elements, dg_elements_checked, dg_passed,
/// dg_seconds = `seconds`. Element ids are null when there is none.
nlohmann::json toJson(const LocalDgCheck& c, double seconds);
/// A whole-mesh check (`polydg check`, check steps): the geometric keys of toJson(
/// ValidationReport) when validated, then passed, geometry_passed, dg_checked, the local keys
/// (null when not run), rigid_modes / rigid_modes_global / rigid_modes_per_component /
/// rigid_modes_expected / rigid_modes_seconds, global_patch_test_error when run, dofs,
/// faces_integrated, messages (failures) and dg_note (why a check did not run).
nlohmann::json toJson(const MeshCheck& c);
/// `polydg mesh --tets`: tets, vertices, steiner_points, cone_elements, tetgen_elements, volume
/// (the tets'), polyhedral_volume, volume_rel_difference, seconds (the split), write_seconds.
nlohmann::json toJson(const TetOutputReport& r);
/// `polydg mesh`: input, grid, output, volume_rel_error, tets (toJson(TetOutputReport); null
/// without --tets), validation (geometry and DG checks), provenance, timings_s.
nlohmann::json toJson(const MeshReport& r);
/// One cut or merge: op, elements_split, pieces_created, elements_removed, volume_removed,
/// sliver_threshold, slivers, slivers_merged, isolated_slivers, faces_reintegrated,
/// faces_total, left_whole {count, first_ids (at most 20)}, validation {passed, level,
/// elements_checked, region_elements, patch_test_error, region_components, zero_modes,
/// volume_rel_error, failure}, time_s.
nlohmann::json toJson(const OperationReport& r);
/// toJson(OperationReport) with solution_exact and solution_extended.
nlohmann::json toJson(const RefineReport& r);
/// A static solve: method, degree, material, penalty_rule, selections {clamps, tractions: each
/// region and faces}, elements, dofs, nonzeros, sparsity, eta, eta_threshold, penalty_attempts,
/// dirichlet_faces, traction_faces, basis_fallbacks, solver {kind, preconditioner, success,
/// iterations, residual}, energy, max_displacement, max_von_mises, max_jump,
/// faces_integrated, timings_s {integrate, assemble, solve, factorize}.
nlohmann::json toJson(const SolveReport& r);
nlohmann::json toJson(const ReadReport& r);
nlohmann::json toJson(const WriteReport& r);
nlohmann::json toJson(const OpenFoamQuality& q);
nlohmann::json toJson(const ExportReport& r);

/// A scene in its own format, every key explicit.
nlohmann::json toJson(const Scene& scene);
/// A simulation: scene (every key explicit), elements, dofs, fixed_faces, load_faces, initial
/// {state}, steps [{t, kinetic, elastic, gravity, traction_potential, momentum,
/// angular_momentum, centre_of_mass, cg_iterations, solves, correction, residual, solver,
/// seconds}], cuts [{time, elements_before, elements_after, exact, extended, operation (as
/// toJson(OperationReport)), seconds}], frames [{step, t, file}], pvd, faces_integrated,
/// timings_s {setup, rotation, assembly, solve, cut, output, wall, per_step}.
nlohmann::json toJson(const SimulationReport& r);

}  // namespace polydg
