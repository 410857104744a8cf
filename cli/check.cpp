// polydg check: validation of a simulation mesh (VTU, or a tet mesh from TetGen or Gmsh), first
// geometric (closed, positive, planar, properly shared elements), then the DG discretization's
// invariants on it (local patch test and rigid modes of every element, the zero modes of the
// global stiffness when affordable): Model::check(). Non-zero exit if any check fails.
#include <iostream>

#include "cli/commands.h"
#include "cli/options.h"
#include "model/files.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/model/report_json.h"

namespace polydg::cli {

namespace {

struct CheckCommandOptions {
  std::string input, report;
  MeshCheckOptions check;
  bool skipDg = false;
};

void print(const std::string& input, const MeshCheck& c) {
  const GeometryCheck& r = *c.geometry;
  std::cout << input << ": " << (c.passed() ? "valid" : "INVALID") << ", " << r.elements
            << " elements, " << r.faces << " faces (" << r.interiorFaces << " interior), "
            << r.components << " component(s), volume " << r.volume << '\n';
  if (c.local) {
    const LocalDgCheck& l = *c.local;
    std::cout << "  DG degree " << l.degree << ": local patch test error " << l.maxPatchTestError
              << ", " << l.elementsWithWrongRigidModes << " of " << l.elements
              << " elements with wrong rigid modes (" << c.localSeconds << " s)";
    if (c.rigid)
      std::cout << "; global rigid modes " << c.rigid->zeroModes << ", expected "
                << 6 * c.rigid->components << " (" << c.rigidSeconds << " s)";
    std::cout << '\n';
  }
  for (const std::string& m : c.failures()) std::cout << "  " << m << '\n';
  for (const std::string& n : c.notes) std::cout << "  " << n << '\n';
}

/// A tet mesh from TetGen (.ele) or Gmsh (.msh): read and checked as such (readTetMesh refuses
/// what is not a conforming tet mesh, naming the element), then as a simulation mesh.
void run(CheckCommandOptions o, const CommonOptions& common, int& exitCode) {
  if (!isVolumeMeshPath(o.input) && !isTetMeshFile(o.input))
    throw InputError(o.input +
                     ": check reads simulation meshes (.vtu) and tet meshes (TetGen .ele, Gmsh "
                     ".msh); for a surface use 'polydg info'");
  if (!o.report.empty()) requireOutput(o.report, {o.input});
  Model model = Model::read(o.input);
  if (o.skipDg) {
    o.check.local = false;
    o.check.rigidModes = GlobalCheck::Never;
  }
  MeshCheck c = model.check(o.check);
  if (o.skipDg) c.notes.push_back("DG checks skipped (--no-dg)");
  if (!o.report.empty()) {
    nlohmann::json report{{"command", "check"}, {"input", o.input}};
    report.update(toJson(*c.geometry));  // the geometric keys at the top level too
    report["validation"] = toJson(c);
    report["passed"] = c.passed();
    writeJsonFile(o.report, report);
  }
  if (!common.quiet) print(o.input, c);
  exitCode = c.passed() ? 0 : 1;
}

}  // namespace

void addCheckCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<CheckCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "check",
      "Validate a simulation mesh: closed, positive, planar, properly shared elements, and the "
      "DG patch test and rigid modes on it");
  cmd->add_option("mesh", o->input, "simulation mesh (.vtu), or a tet mesh (.vtu, .ele, .msh)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--report", o->report, "write the validation as JSON to this file");
  cmd->add_option("--planarity-tolerance", o->check.geometryOptions.planarityTolerance,
                  "largest vertex distance from a face's plane, relative to the face size")
      ->check(kPositive)
      ->capture_default_str();
  cmd->add_option("--degree", o->check.physics.discretization.basis.degree,
                  "polynomial degree of the DG checks")
      ->check(kDegree)
      ->capture_default_str();
  cmd->add_flag("--no-dg", o->skipDg, "geometric validation only, no DG checks");
  cmd->callback([o, &common, &exitCode] { run(*o, common, exitCode); });
}

}  // namespace polydg::cli
