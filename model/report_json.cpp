#include "polydg/model/report_json.h"

#include "polydg/model/scene.h"

#include "physics/checks/mesh_checks.h"
#include "polydg/model/names.h"

namespace polydg {

using nlohmann::json;

namespace {

json idOrNull(ElementId e) { return e.valid() ? json(e.value) : json(nullptr); }

json vectorJson(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

/// The region of a selection as pipelines write it.
json selectionJson(const FaceSelector& s) {
  const auto plane = [](const Plane& p) {
    return json{p.normal.x(), p.normal.y(), p.normal.z(), p.offset};
  };
  switch (s.kind) {
    case FaceSelector::Kind::AllBoundary: return {{"all", true}};
    case FaceSelector::Kind::Plane: return {{"plane", plane(s.plane)}};
    case FaceSelector::Kind::Below: return {{"below", plane(s.plane)}};
    case FaceSelector::Kind::Box:
      return {{"box", {vectorJson(s.box.min()), vectorJson(s.box.max())}}};
  }
  return nullptr;
}

/// The keys of the local DG checks when they did not run.
void nullLocalKeys(json& v) {
  v["patch_test_error"] = nullptr;
  v["rigid_mode_failures"] = nullptr;
  v["dg_passed"] = nullptr;
  v["dg_seconds"] = nullptr;
}

json timingsJson(const std::vector<std::pair<std::string, double>>& timings) {
  json out = json::object();
  double total = 0.0;
  for (const auto& [phase, seconds] : timings) {
    out[phase] = seconds;
    total += seconds;
  }
  out["total"] = total;
  return out;
}

}  // namespace

json toJson(const Box3& box) {
  if (box.isEmpty()) return nullptr;
  return {{"min", vectorJson(box.min())}, {"max", vectorJson(box.max())}};
}

json toJson(const Provenance& p) {
  json out = {
      {"source", p.source},
      {"cell_size", p.cellSize > 0.0 ? json(p.cellSize) : json(nullptr)},
      {"reference_volume", p.referenceVolume},
      {"reference", p.referenceKind == ReferenceKind::GridCell ? "grid_cell" : "median_element"},
      {"sliver_fraction", p.sliverFraction},
      {"sliver_threshold", p.sliverFraction * p.referenceVolume}};
  if (!p.cuts.empty()) {
    json cuts = json::array();
    for (const Plane& c : p.cuts)
      cuts.push_back({c.normal.x(), c.normal.y(), c.normal.z(), c.offset});
    out["cuts"] = cuts;
  }
  return out;
}

json toJson(const GeometryCheck& r) {
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
          {"closed_by_construction", r.closedByConstruction},
          {"messages", r.messages}};
}

json toJson(const LocalDgCheck& c, double seconds) {
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

json toJson(const MeshCheck& c) {
  json v = c.geometry ? toJson(*c.geometry) : json::object();
  v["passed"] = c.passed();
  v["geometry_passed"] = c.geometryPassed();
  v["dg_checked"] = c.local.has_value();
  v["messages"] = json::array();
  if (c.geometry)
    for (const std::string& m : c.geometry->messages) v["messages"].push_back(m);
  if (c.local) {
    v.update(toJson(*c.local, c.localSeconds));
    for (const std::string& m : failureMessages(*c.local)) v["messages"].push_back(m);
  } else {
    nullLocalKeys(v);
  }
  // Zero modes of the global stiffness without boundary conditions (6 per component).
  if (c.rigid) {
    v["rigid_modes"] = c.rigid->zeroModes;
    v["rigid_modes_global"] = c.rigid->zeroModes;
    v["rigid_modes_per_component"] = c.rigid->zeroModesPerComponent;
    v["rigid_modes_expected"] = 6 * c.rigid->components;
    v["rigid_modes_seconds"] = c.rigidSeconds;
    if (!c.rigidPassed()) v["messages"].push_back(c.failures().back());
  } else {
    v["rigid_modes"] = nullptr;
    v["rigid_modes_global"] = nullptr;
    v["rigid_modes_expected"] = c.geometry ? json(6 * c.geometry->components) : json(nullptr);
  }
  if (c.patch) {
    v["global_patch_test_error"] = c.patch->relativeError;
    v["global_patch_test_seconds"] = c.patchSeconds;
  }
  v["dofs"] = c.dofs;
  v["faces_integrated"] = c.facesIntegrated;
  if (!c.notes.empty()) {
    std::string note;
    for (const std::string& n : c.notes) note += (note.empty() ? "" : "; ") + n;
    v["dg_note"] = note;
  }
  return v;
}

json toJson(const TetOutputReport& r) {
  return {{"tets", r.split.tets},
          {"vertices", r.vertices},
          {"steiner_points", r.split.steinerPoints},
          {"cone_elements", r.split.coneElements},
          {"tetgen_elements", r.split.tetgenElements},
          {"volume", r.volume},
          {"polyhedral_volume", r.polyhedralVolume},
          {"volume_rel_difference", r.volumeRelDifference},
          {"seconds", r.split.seconds},
          {"write_seconds", r.writeSeconds}};
}

json toJson(const MeshReport& report) {
  const MeshingReport& r = report.meshing;
  json timings = timingsJson(r.timings);
  timings["read"] = report.readSeconds;
  if (report.dg.local)
    timings["dg_checks"] = report.dg.localSeconds;
  else
    timings["dg_checks"] = nullptr;
  if (!report.output.empty()) timings["write"] = report.writeSeconds;
  // The whole operation, read to write; less than "total" where phases overlap.
  timings["wall"] = report.wallSeconds;
  // The two parts of "slice" (not added to "total"): plane splits, then the mesh build.
  timings["slice_split"] = r.slice.secondsSplitting;
  timings["slice_build"] = r.slice.secondsBuilding;

  json checks = toJson(r.geometry);
  checks["geometry_passed"] = r.geometry.passed;
  checks["passed"] = report.passed();
  checks["dg_checked"] = report.dg.local.has_value();
  if (report.dg.local) {
    checks.update(toJson(*report.dg.local, report.dg.localSeconds));
    for (const std::string& m : failureMessages(*report.dg.local)) checks["messages"].push_back(m);
  } else {
    nullLocalKeys(checks);
  }
  return {
      {"input",
       {{"vertices", r.inputVertices},
        {"triangles", r.inputTriangles},
        {"closed", r.inputClosed},
        {"manifold", r.inputManifold},
        {"self_intersecting",
         r.selfIntersectionsChecked ? json(r.selfIntersections > 0) : json(nullptr)},
        {"self_intersections", r.selfIntersections},
        {"shells", r.shells},
        {"cavities", r.cavities},
        {"volume", r.inputVolume},
        {"volume_before_repair", r.repairs.empty() ? json(nullptr) : json(r.volumeBeforeRepair)},
        {"repairs", r.repairs}}},
      {"grid",
       {{"origin", vectorJson(r.grid.origin())},
        {"cell_size", r.grid.cellSize},
        {"cells", r.grid.cells}}},
      {"octree", report.levels == 0 && report.coarseCellSize == 0.0
                     ? json(nullptr)
                     : json{{"levels", report.levels},
                            {"coarse_cell_size", report.coarseCellSize},
                            {"finest_cell_size", std::ldexp(report.coarseCellSize, -report.levels)},
                            {"elements_per_level", report.elementsPerLevel},
                            {"refine_seconds", report.refineSeconds}}},
      {"output",
       {{"file", report.output.empty() ? json(nullptr) : json(report.output)},
        {"elements", r.elements},
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
        {"cells_with_several_pieces", r.slice.multiPieceCells},
        {"whole_cells", r.slice.wholeCells}}},
      {"volume_rel_error", r.volumeRelError},
      {"tets", report.tets ? toJson(*report.tets) : json(nullptr)},
      {"validation", checks},
      {"faces_integrated", report.dg.facesIntegrated},
      {"timings_s", timings}};
}

json toJson(const OperationReport& r) {
  const OperationCheck& v = r.check;
  constexpr std::size_t kListedIds = 20;
  std::vector<std::uint32_t> firstIds;
  for (std::size_t i = 0; i < r.leftWhole.size() && i < kListedIds; ++i)
    firstIds.push_back(r.leftWhole[i].value);
  return {{"op", r.op},
          {"elements_split", r.elementsSplit},
          {"pieces_created", r.piecesCreated},
          {"elements_removed", r.elementsRemoved},
          {"volume_removed", r.volumeRemoved},
          {"sliver_threshold", r.sliverThreshold},
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

namespace {

/// An adaptive solve's options and rounds; null for one solve.
json adaptJson(const SolveReport& report) {
  if (!report.options.adapt) return nullptr;
  const AdaptOptions& a = *report.options.adapt;
  const bool exact = static_cast<bool>(report.options.exactDisplacement);
  json rounds = json::array();
  for (const AdaptRound& r : report.rounds)
    rounds.push_back(
        {{"elements", r.elements},
         {"dofs", r.dofs},
         {"estimate", r.estimate},
         {"energy_norm", r.energyNorm},
         {"relative_estimate", r.energyNorm > 0.0 ? r.estimate / r.energyNorm : 0.0},
         {"l2_error", exact ? json(r.l2Error) : json(nullptr)},
         {"energy_error", exact ? json(r.energyError) : json(nullptr)},
         {"effectivity",
          exact && r.energyError > 0.0 ? json(r.estimate / r.energyError) : json(nullptr)},
         {"largest_principal_stress", r.largestStress},
         {"marked", r.marked},
         {"elements_after", r.elementsAfter},
         {"stop", r.stop.empty() ? json(nullptr) : json(r.stop)},
         {"timings_s",
          {{"solve", r.solveSeconds},
           {"estimate", r.estimateSeconds},
           {"refine", r.refineSeconds}}}});
  return {{"criterion", nameOf(adaptCriterionNames(), a.criterion)},
          {"split", nameOf(refineSplitNames(), a.split)},
          {"target_error", a.targetError ? json(*a.targetError) : json(nullptr)},
          {"max_dofs", a.maxDofs ? json(*a.maxDofs) : json(nullptr)},
          {"bulk", a.bulk},
          {"stress_fraction", a.stressFraction},
          {"max_level", a.maxLevel},
          {"max_rounds", a.maxRounds},
          {"rounds", rounds}};
}

}  // namespace

json toJson(const SolveReport& report) {
  const StaticReport& r = report.solve;
  const SolveOptions& o = report.options;
  const double dofs = static_cast<double>(r.dofs);
  json clamps = json::array(), tractions = json::array(), clampForces = json::array();
  for (const Vec3& f : report.clampForces) clampForces.push_back(vectorJson(f));
  for (std::size_t i = 0; i < o.clamps.size(); ++i) {
    json c = selectionJson(o.clamps[i]);
    c["faces"] = i < report.clampFaces.size() ? report.clampFaces[i] : 0;
    clamps.push_back(c);
  }
  for (std::size_t i = 0; i < o.tractions.size(); ++i) {
    json t = selectionJson(o.tractions[i].where);
    t["traction"] = vectorJson(o.tractions[i].traction);
    t["faces"] = i < report.tractionFaces.size() ? report.tractionFaces[i] : 0;
    tractions.push_back(t);
  }
  json j = {
      {"method", toString(o.discretization.method)},
      {"degree", o.discretization.basis.degree},
      {"material",
       {{"E", o.material.youngsModulus},
        {"nu", o.material.poissonRatio},
        {"density", o.material.density}}},
      {"gravity", vectorJson(o.gravity)},
      {"penalty_rule", toString(o.discretization.penalty.rule)},
      {"clamps", clamps},
      {"tractions", tractions},
      {"elements", r.elements},
      {"dofs", r.dofs},
      {"nonzeros", r.nonzeros},
      {"sparsity", dofs > 0 ? static_cast<double>(r.nonzeros) / (dofs * dofs) : 0.0},
      {"eta", r.eta},
      {"eta_threshold", r.etaThreshold},
      {"penalty_attempts", r.penaltyAttempts},
      {"dirichlet_faces", r.dirichletFaces},
      {"traction_faces", r.tractionFaces},
      {"basis_fallbacks", r.basisFallbacks},
      {"solver",
       {{"kind", toString(r.solver.used)},
        {"preconditioner", r.solver.used == SolverKind::ConjugateGradient
                               ? json(toString(r.solver.preconditioner))
                               : json("none")},
        {"success", r.solver.success},
        {"iterations", r.solver.iterations},
        {"residual", r.solver.residual}}},
      {"energy", r.energy},
      {"max_displacement", report.maxDisplacement},
      {"max_von_mises", report.maxVonMises},
      {"max_jump", report.maxJump},
      {"faces_integrated", report.facesIntegrated},
      {"clamp_forces", clampForces},
      {"warnings", report.warnings},
      {"timings_s",
       {{"integrate", r.integrateSeconds},
        {"assemble", r.assembleSeconds},
        {"solve", r.solveSeconds},
        {"factorize", r.solver.factorSeconds}}},
      {"estimate", report.estimate
                       ? json{{"total", report.estimate->total},
                              {"energy_norm", report.energyNorm},
                              {"local", std::sqrt(report.estimate->local)},
                              {"displacement_jump", std::sqrt(report.estimate->displacementJump)},
                              {"dirichlet", std::sqrt(report.estimate->dirichlet)}}
                       : json(nullptr)},
      {"adapt", adaptJson(report)}};
  if (o.tetMethod) {
    // No penalty and no jumps: the tet methods are continuous.
    j["method"] = toString(*o.tetMethod);
    for (const char* dgOnly : {"penalty_rule", "eta", "eta_threshold", "penalty_attempts",
                               "basis_fallbacks", "max_jump", "estimate", "adapt"})
      j.erase(dgOnly);
    if (report.tets) {
      j["nodes"] = report.tets->nodes;
      j["tets"] = report.tets->tets;
      j["held_nodes"] = report.tets->heldNodes;
    }
  } else if (o.discretization.method == Method::BZ) {
    j["bz_penalty"] = toString(o.discretization.bzPenaltyInEffect());
    j["bz_factor"] = r.bzFactor;
  }
  return j;
}

json toJson(const RefineReport& r) {
  json j = toJson(r.operation);
  j["solution_exact"] = r.solutionExact;
  j["solution_extended"] = r.solutionExtended;
  return j;
}

json toJson(const ReadReport& r) {
  return {{"file", r.file},
          {"elements", r.elements},
          {"faces", r.faces},
          {"vertices", r.vertices},
          {"provenance_restored", r.provenanceRestored},
          {"time_s", r.seconds}};
}

json toJson(const WriteReport& r) {
  return {{"file", r.file}, {"with_solution", r.withSolution}, {"time_s", r.seconds}};
}

json toJson(const OpenFoamQuality& q) {
  json worst = json::array();
  for (const OpenFoamFlaggedFace& f : q.worst) {
    json face = {{"face", f.face},         {"cell", f.cell},     {"kind", f.kind},
                 {"skewness", f.skewness}, {"offset", f.offset}, {"width", f.width}};
    if (f.kind == "internal")
      face["non_orthogonality"] = f.nonOrthogonality;
    else
      face["depth"] = f.depth;
    if (f.wrongOriented) face["wrong_oriented"] = true;
    worst.push_back(std::move(face));
  }
  return {{"check_mesh", q.failedChecks().empty() ? "Mesh OK" : "failed"},
          {"failed_checks", q.failedChecks()},
          {"advice", q.advice()},
          {"total_volume", q.totalVolume},
          {"min_volume", q.minVolume},
          {"max_volume", q.maxVolume},
          {"max_non_orthogonality", q.maxNonOrthogonality},
          {"average_non_orthogonality", q.averageNonOrthogonality},
          {"severely_non_orthogonal_faces", q.severelyNonOrthogonal},
          {"non_orthogonality_errors", q.nonOrthogonalityErrors},
          {"max_skewness", q.maxSkewness},
          {"skew_faces", q.skewFaces},
          {"skew_boundary_faces", q.skewBoundaryFaces},
          {"max_aspect_ratio", q.maxAspectRatio},
          {"wrong_oriented_faces", q.wrongOrientedFaces},
          {"worst_faces", worst}};
}

json toJson(const ExportReport& r) {
  json patches = json::array();
  for (const OpenFoamPatchReport& p : r.foam.patches)
    patches.push_back({{"name", p.name}, {"faces", p.faces}});
  return {{"folder", r.folder},
          {"format", r.foam.binary ? "binary" : "ascii"},
          {"cells", r.foam.cells},
          {"points", r.foam.points},
          {"faces", r.foam.faces},
          {"internal_faces", r.foam.internalFaces},
          {"split_faces", r.foam.splitFaces},
          {"patches", patches},
          {"quality", toJson(r.foam.quality)},
          {"time_s", r.seconds}};
}

namespace {

json stateJson(const BodyState& s) {
  return {{"kinetic", s.kinetic},
          {"elastic", s.elastic},
          {"gravity", s.gravity},
          {"traction_potential", s.tractionPotential},
          {"momentum", vectorJson(s.momentum)},
          {"angular_momentum", vectorJson(s.angularMomentum)},
          {"centre_of_mass", vectorJson(s.centreOfMass)}};
}

}  // namespace

json toJson(const Scene& s) {
  json j;
  j["material"] = {{"E", s.material.youngsModulus},
                   {"nu", s.material.poissonRatio},
                   {"density", s.material.density}};
  if (s.tetMethod) {
    j["method"] = toString(*s.tetMethod);
  } else {
    j["method"] = toString(s.discretization.method);
    if (s.discretization.method == Method::BZ)
      j["bz_penalty"] = toString(s.discretization.bzPenaltyInEffect());
    j["degree"] = s.discretization.basis.degree;
  }
  j["corotational"] = s.corotational;
  j["integrator"] = nameOf(integratorNames(), s.integrator);
  j["solver"] = toString(s.solver);
  j["dt"] = s.dt;
  j["steps"] = s.steps;
  j["duration"] = s.steps * s.dt;
  j["gravity"] = vectorJson(s.gravity);
  j["damping"] = {{"mass", s.damping.mass}, {"stiffness", s.damping.stiffness}};
  j["fixed"] = json::array();
  for (const FaceSelector& f : s.fixed) j["fixed"].push_back(selectionJson(f));
  j["loads"] = json::array();
  for (const TimedTraction& t : s.loads) {
    json l = {{"traction", vectorJson(t.traction)}, {"on", selectionJson(t.where)}};
    if (std::isfinite(t.until)) l["until"] = t.until;
    j["loads"].push_back(l);
  }
  j["initial"] = {{"velocity", vectorJson(s.velocity)},
                  {"angular_velocity", vectorJson(s.angularVelocity)}};
  j["output"] = {{"every", s.outputEvery}};
  j["cuts"] = json::array();
  for (const TimedCut& c : s.cuts) {
    json cut = {{"time", c.time}, {"remove_side", nameOf(removeSideNames(), c.request.removeSide)}};
    const Blade& b = c.request.blade;
    if (b.finite()) {
      json corners = json::array();
      for (const Vec3& p : b.polygon) corners.push_back(vectorJson(p));
      cut["polygon"] = corners;
    } else {
      cut["plane"] = {b.normal.x(), b.normal.y(), b.normal.z(), b.offset};
    }
    j["cuts"].push_back(cut);
  }
  if (s.embed.enabled) j["embed"] = s.embed.file.empty() ? json(true) : json(s.embed.file);
  if (s.adapt.enabled)
    j["adapt"] = {{"stress", s.adapt.stress},
                  {"split", nameOf(refineSplitNames(), s.adapt.split)},
                  {"every", s.adapt.every},
                  {"max_level", s.adapt.maxLevel},
                  {"coarsen", s.adapt.coarsen}};
  if (!s.obstacles.empty()) {
    j["obstacles"] = json::array();
    for (const SceneObstacle& o : s.obstacles) {
      json ob;
      if (o.below)
        ob["below"] = {o.below->normal.x(), o.below->normal.y(), o.below->normal.z(),
                       o.below->offset};
      else
        ob["mesh"] = o.mesh;
      if (o.voxel > 0.0) ob["voxel"] = o.voxel;
      ob["velocity"] = vectorJson(o.velocity);
      j["obstacles"].push_back(ob);
    }
    json c = {{"friction", s.contact.friction},
              {"points", nameOf(contactPointNames(), s.contact.points)}};
    if (s.contact.stiffness > 0.0) c["stiffness"] = s.contact.stiffness;
    if (s.contact.slipSpeed > 0.0) c["slip_speed"] = s.contact.slipSpeed;
    j["contact"] = c;
  }
  return j;
}

json toJson(const SimulationReport& r) {
  json j;
  j["scene"] = toJson(r.scene);
  j["elements"] = r.elements;
  j["dofs"] = r.dofs;
  j["fixed_faces"] = r.fixedFaces;
  j["load_faces"] = r.loadFaces;
  j["initial"] = stateJson(r.initial);
  json steps = json::array();
  for (const SimulationStep& s : r.steps) {
    json step = stateJson(s.state);
    step["t"] = s.step.t;
    step["cg_iterations"] = s.step.iterations;
    step["solves"] = s.step.solves;
    step["correction"] = s.step.correction;
    step["residual"] = s.step.residual;
    step["solver"] = s.solver;
    if (!r.scene.obstacles.empty()) {
      step["contacts"] = s.contact.contacts;
      step["deepest_penetration"] = s.contact.deepest;
      step["contact_energy"] = s.contact.energy;
      step["contacts_linearized"] = s.step.contacts;
      step["contact_passes"] = s.step.contactPasses;
      step["collision_seconds"] = s.collisionSeconds;
    }
    step["seconds"] = s.seconds;
    step["rotation_seconds"] = s.step.rotationSeconds;
    step["assembly_seconds"] = s.step.assemblySeconds;
    step["solve_seconds"] = s.step.solveSeconds;
    step["preconditioner_seconds"] = s.step.preconditionerSeconds;
    steps.push_back(std::move(step));
  }
  j["steps"] = std::move(steps);
  json cuts = json::array();
  for (const SimulationCut& c : r.cuts)
    cuts.push_back({{"time", c.time},
                    {"elements_before", c.elementsBefore},
                    {"elements_after", c.elementsAfter},
                    {"exact", c.exact},
                    {"extended", c.extended},
                    {"solver_elements", c.solverElements},
                    {"operation", toJson(c.report)},
                    {"seconds", c.seconds},
                    {"cut_seconds",
                     {{"cut", c.cutSeconds},
                      {"check", c.checkSeconds},
                      {"solver", c.solverSeconds},
                      {"transfer", c.transferSeconds},
                      {"next_step", c.nextStepSeconds ? json(*c.nextStepSeconds) : json(nullptr)},
                      {"next_step_preconditioner", c.nextStepPreconditionerSeconds
                                                       ? json(*c.nextStepPreconditionerSeconds)
                                                       : json(nullptr)},
                      {"latency", c.nextStepSeconds ? json(c.seconds + *c.nextStepSeconds)
                                                    : json(nullptr)}}}});
  j["cuts"] = std::move(cuts);
  json refinements = json::array();
  for (const SimulationRefinement& f : r.refinements)
    refinements.push_back({{"time", f.time},
                           {"marked", f.marked},
                           {"coarsened", f.coarsened},
                           {"elements_before", f.elementsBefore},
                           {"elements_after", f.elementsAfter},
                           {"exact", f.exact},
                           {"extended", f.extended},
                           {"momentum_change", f.momentumChange},
                           {"kinetic_energy_change", f.kineticChange},
                           {"elastic_energy_change", f.elasticChange},
                           {"seconds", f.seconds}});
  j["refinements"] = std::move(refinements);
  json frames = json::array();
  for (const SimulationFrame& f : r.frames)
    frames.push_back({{"step", f.step},
                      {"t", f.t},
                      {"file", f.file},
                      {"surface", f.surfaceFile.empty() ? json(nullptr) : json(f.surfaceFile)}});
  j["frames"] = std::move(frames);
  j["pvd"] = r.pvd.empty() ? json(nullptr) : json(r.pvd);
  j["faces_integrated"] = r.facesIntegrated;
  const SimulationEmbedding& e = r.embedding;
  if (!e.surface.empty() || !e.contactPointKind.empty()) {
    json embedding;
    if (!e.surface.empty()) {
      embedding = {{"surface", e.surface},
                   {"points", e.points},
                   {"triangles", e.triangles},
                   {"samples", e.samples},
                   {"pieces", e.pieces},
                   {"outside", e.outside},
                   {"weight_nonzeros", e.weightNonzeros},
                   {"stored_nonzeros", e.storedNonzeros},
                   {"setup_seconds", e.setupSeconds}};
      json updates = json::array();
      for (const EmbeddingUpdate& u : e.updates)
        updates.push_back({{"recomputed", u.recomputed}, {"kept", u.kept}, {"seconds", u.seconds}});
      embedding["updates"] = updates;
    }
    j["embedding"] = embedding.is_null() ? json(nullptr) : embedding;
    if (!e.contactPointKind.empty())
      j["contact"] = {{"points", e.contactPointKind},
                      {"count", e.contactPoints},
                      {"stiffness", e.contactStiffness},
                      {"slip_speed", e.slipSpeed},
                      {"obstacle_setup_seconds", e.obstacleSetupSeconds},
                      {"obstacle_voxels", e.obstacleVoxels}};
  }
  const double n = std::max<double>(1.0, static_cast<double>(r.steps.size()));
  j["timings_s"] = {{"setup", r.setupSeconds},
                    {"rotation", r.rotationSeconds},
                    {"assembly", r.assemblySeconds},
                    {"solve", r.solveSeconds},
                    {"state", r.stateSeconds},
                    {"cut", r.cutSeconds},
                    {"output", r.outputSeconds},
                    {"surface", r.surfaceSeconds},
                    {"finish", r.finishSeconds},
                    {"wall", r.wallSeconds},
                    {"per_step", (r.rotationSeconds + r.assemblySeconds + r.solveSeconds) / n}};
  return j;
}

}  // namespace polydg
