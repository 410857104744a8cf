#include "cli/json_reports.h"

#include <sstream>

namespace polydg::cli {

namespace {
nlohmann::json idOrNull(ElementId e) {
  return e.valid() ? nlohmann::json(e.value) : nlohmann::json(nullptr);
}
}  // namespace

nlohmann::json toJson(const ValidationReport& r) {
  return {{"passed", r.passed},
          {"elements", r.elements},
          {"faces", r.faces},
          {"interior_faces", r.interiorFaces},
          {"boundary_faces", r.boundaryFaces},
          {"components", r.components},
          {"volume", r.volume},
          {"min_element_volume", r.minElementVolume},
          {"max_element_volume", r.maxElementVolume},
          {"problems",
           {{"open_elements", r.openElements},
            {"non_positive_elements", r.nonPositiveElements},
            {"non_planar_faces", r.nonPlanarFaces},
            {"degenerate_faces", r.degenerateFaces},
            {"duplicate_faces", r.duplicateFaces},
            {"inconsistent_faces", r.inconsistentFaces},
            {"empty_elements", r.emptyElements}}},
          {"messages", r.messages}};
}

nlohmann::json toJson(const LocalDgCheck& c, double seconds) {
  return {{"dg_degree", c.degree},
          {"patch_test_error", c.maxPatchTestError},
          {"patch_test_tolerance", kLocalPatchTestTolerance},
          {"patch_test_failures", c.patchTestFailures},
          {"worst_patch_test_element", idOrNull(c.worstPatchTestElement)},
          {"rigid_mode_failures", c.elementsWithWrongRigidModes},
          {"first_rigid_mode_failure", idOrNull(c.firstWrongRigidModeElement)},
          {"non_definite_elements", c.nonDefiniteElements},
          {"dg_elements_checked", c.elements},
          {"dg_passed", c.passed()},
          {"dg_seconds", seconds}};
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

nlohmann::json toJson(const Box3& box) {
  if (box.isEmpty()) return nullptr;
  return {{"min", {box.min().x(), box.min().y(), box.min().z()}},
          {"max", {box.max().x(), box.max().y(), box.max().z()}}};
}

nlohmann::json toJson(const MeshingReport& r) {
  nlohmann::json timings = nlohmann::json::object();
  double total = 0.0;
  for (const auto& [phase, seconds] : r.timings) {
    timings[phase] = seconds;
    total += seconds;
  }
  timings["total"] = total;
  return {
      {"input",
       {{"vertices", r.inputVertices},
        {"triangles", r.inputTriangles},
        {"closed", r.inputClosed},
        {"manifold", r.inputManifold},
        {"self_intersecting", r.selfIntersectionsChecked ? nlohmann::json(r.selfIntersections > 0)
                                                         : nlohmann::json(nullptr)},
        {"self_intersections", r.selfIntersections},
        {"shells", r.shells},
        {"cavities", r.cavities},
        {"volume", r.inputVolume},
        {"volume_before_repair",
         r.repairs.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.volumeBeforeRepair)},
        {"repairs", r.repairs}}},
      {"grid",
       {{"origin", {r.grid.origin().x(), r.grid.origin().y(), r.grid.origin().z()}},
        {"cell_size", r.grid.cellSize},
        {"cells", r.grid.cells}}},
      {"output",
       {{"elements", r.elements},
        {"hexahedra", r.hexahedra},
        {"polyhedra", r.polyhedra},
        {"nonconvex", r.nonconvex},
        {"faces", r.faces},
        {"interior_faces", r.interiorFaces},
        {"boundary_faces", r.boundaryFaces},
        {"volume", r.outputVolume},
        {"slivers", r.slivers.slivers},
        {"slivers_merged", r.slivers.merged},
        {"isolated_slivers", r.slivers.isolated},
        {"sliver_threshold", r.slivers.threshold},
        {"cells_with_several_pieces", r.slice.multiPieceCells}}},
      {"volume_rel_error", r.volumeRelError},
      {"validation", toJson(r.validation)},
      {"timings_s", timings}};
}

std::string toString(ValidationLevel level) {
  switch (level) {
    case ValidationLevel::None: return "none";
    case ValidationLevel::Local: return "local";
    case ValidationLevel::Full: return "full";
  }
  return "unknown";
}

std::string toString(Method method) { return method == Method::IP ? "ip" : "bz"; }

std::string toString(SolverKind kind) {
  switch (kind) {
    case SolverKind::Cholesky: return "cholesky";
    case SolverKind::ConjugateGradient: return "cg";
    case SolverKind::Auto: break;
  }
  return "auto";
}

nlohmann::json toJson(const OperationReport& r) {
  const OperationValidation& v = r.validation;
  constexpr std::size_t kListedIds = 20;
  std::vector<std::uint32_t> firstIds;
  for (std::size_t i = 0; i < r.leftWhole.size() && i < kListedIds; ++i)
    firstIds.push_back(r.leftWhole[i].value);
  return {{"op", r.op},
          {"elements_split", r.elementsSplit},
          {"pieces_created", r.piecesCreated},
          {"elements_removed", r.elementsRemoved},
          {"volume_removed", r.volumeRemoved},
          {"slivers", r.slivers},
          {"slivers_merged", r.sliversMerged},
          {"isolated_slivers", r.isolatedSlivers},
          {"faces_reintegrated", r.facesReintegrated},
          {"faces_total", r.facesTotal},
          {"left_whole", {{"count", r.leftWhole.size()}, {"first_ids", firstIds}}},
          {"validation",
           {{"passed", v.passed},
            {"level", toString(v.level)},
            {"elements_checked", v.elementsChecked},
            {"region_elements", v.regionElements},
            {"patch_test_error", v.patchTestError},
            {"region_components", v.regionComponents},
            {"zero_modes", v.zeroModes},
            {"volume_rel_error", v.volumeRelError},
            {"failure", v.failure}}},
          {"time_s", r.seconds}};
}

}  // namespace polydg::cli
