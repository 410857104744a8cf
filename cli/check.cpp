// polydg check: validation of a simulation mesh (VTU), first geometric (closed, positive,
// planar, properly shared elements), then the DG discretization's invariants on it (local patch
// test and rigid modes of every element, the zero modes of the global stiffness when affordable);
// non-zero exit if any check fails.
#include <chrono>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/json_reports.h"
#include "cli/report.h"
#include "polydg/mesh/validate.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/physics/validation.h"

namespace polydg::cli {

namespace {

/// Largest number of DOFs (elements x 3 numMonomials(degree)) for which `check` counts the zero
/// modes of the global stiffness without boundary conditions (rigidModes(): assembly, then a
/// CHOLMOD factorization and subspace iteration per component). Measured on sliced spheres,
/// degree 1, two cores: 4.9k DOFs 0.22 s, 14k 0.9 s, 22k 1.5 s, 31k 2.6 s, 58k 6.0 s, 100k 12 s;
/// the limit keeps it under 2 s. Larger meshes get the element-local checks only.
constexpr std::size_t kGlobalRigidModesDofLimit = 25'000;

struct CheckOptions {
  std::string input;
  std::string report;
  double planarityTolerance = ValidationOptions{}.planarityTolerance;
  int degree = 1;
  bool skipDg = false;
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// What the DG checks found; nothing is set for checks that did not run.
struct DgChecks {
  std::optional<LocalDgCheck> local;
  double localSeconds = 0.0;  ///< moments included
  std::optional<ZeroModeReport> global;
  double globalSeconds = 0.0;
  std::size_t dofs = 0;
  std::string note;  ///< why a check did not run

  bool globalPassed() const {
    if (!global) return true;
    for (std::size_t modes : global->zeroModesPerComponent)
      if (modes != 6) return false;
    return true;
  }
  bool passed() const { return (!local || local->passed()) && globalPassed(); }
};

DgChecks runDgChecks(const PolyMesh& mesh, const ValidationReport& geometry,
                     const CheckOptions& o) {
  DgChecks dg;
  if (o.skipDg) {
    dg.note = "DG checks skipped (--no-dg)";
    return dg;
  }
  if (!geometry.passed) {
    dg.note = "DG checks skipped: the mesh failed the geometric validation";
    return dg;
  }
  auto t0 = std::chrono::steady_clock::now();
  LocalDgCheckOptions local;
  local.basis.degree = o.degree;
  MomentCache moments(mesh, 2 * o.degree);
  moments.update();
  dg.local = localDgChecks(mesh, moments, local);
  dg.localSeconds = secondsSince(t0);

  dg.dofs = mesh.numElements() * 3 * numMonomials(o.degree);
  if (dg.dofs > kGlobalRigidModesDofLimit) {
    dg.note = "global rigid modes not counted: " + std::to_string(dg.dofs) + " DOFs > " +
              std::to_string(kGlobalRigidModesDofLimit) + "; element-local checks only";
    return dg;
  }
  t0 = std::chrono::steady_clock::now();
  PhysicsCheckOptions global;
  global.basis.degree = o.degree;
  dg.global = rigidModes(mesh, global);
  dg.globalSeconds = secondsSince(t0);
  return dg;
}

/// The `validation` section: the geometric report and the DG checks, `passed` for all.
nlohmann::json validationJson(const ValidationReport& geometry, const DgChecks& dg) {
  nlohmann::json v = toJson(geometry);
  v["passed"] = geometry.passed && dg.passed();
  v["geometry_passed"] = geometry.passed;
  v["dg_checked"] = dg.local.has_value();
  if (dg.local) {
    v.update(toJson(*dg.local, dg.localSeconds));
    for (const std::string& m : failureMessages(*dg.local)) v["messages"].push_back(m);
  } else {
    v["patch_test_error"] = nullptr;
    v["rigid_mode_failures"] = nullptr;
    v["dg_passed"] = nullptr;
  }
  // rigid_modes and rigid_modes_global: zero modes of the global stiffness without boundary
  // conditions (6 per component expected), null when not counted.
  if (dg.global) {
    v["rigid_modes"] = dg.global->zeroModes;
    v["rigid_modes_global"] = dg.global->zeroModes;
    v["rigid_modes_per_component"] = dg.global->zeroModesPerComponent;
    v["rigid_modes_seconds"] = dg.globalSeconds;
    if (!dg.globalPassed())
      v["messages"].push_back("the global stiffness has " + std::to_string(dg.global->zeroModes) +
                              " zero modes, expected 6 per component (" +
                              std::to_string(6 * dg.global->components) + ")");
  } else {
    v["rigid_modes"] = nullptr;
    v["rigid_modes_global"] = nullptr;
  }
  v["rigid_modes_expected"] = 6 * geometry.components;
  if (!dg.note.empty()) v["dg_note"] = dg.note;
  return v;
}

void printDg(const DgChecks& dg) {
  if (dg.local) {
    const LocalDgCheck& c = *dg.local;
    std::cout << "  DG degree " << c.degree << ": local patch test error " << c.maxPatchTestError
              << ", " << c.elementsWithWrongRigidModes << " of " << c.elements
              << " elements with wrong rigid modes (" << dg.localSeconds << " s)";
    if (dg.global)
      std::cout << "; global rigid modes " << dg.global->zeroModes << ", expected "
                << 6 * dg.global->components << " (" << dg.globalSeconds << " s)";
    std::cout << ": " << (dg.passed() ? "passed" : "FAILED") << '\n';
  }
  if (!dg.note.empty()) std::cout << "  " << dg.note << '\n';
}

}  // namespace

void addCheckCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* cmd = app.add_subcommand(
      "check",
      "Validate a simulation mesh: closed, positive, planar, properly shared elements, "
      "and the DG patch test and rigid modes on it");
  cmd->add_option("mesh", options->input, "simulation mesh (.vtu)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--report", options->report, "write the validation as JSON to this file");
  cmd->add_option("--planarity-tolerance", options->planarityTolerance,
                  "largest vertex distance from a face's plane, relative to the face size")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--degree", options->degree, "polynomial degree of the DG checks")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  cmd->add_flag("--no-dg", options->skipDg, "geometric validation only, no DG checks");
  cmd->callback([options, &common, &exitCode] {
    if (!isVolumeMeshPath(options->input))
      throw UserError(options->input +
                      ": check reads simulation meshes (.vtu); for a surface use 'polydg info'");
    const PolyMesh mesh = readVtu(options->input);
    ValidationOptions vo;
    vo.planarityTolerance = options->planarityTolerance;
    const ValidationReport r = validate(mesh, vo);
    const DgChecks dg = runDgChecks(mesh, r, *options);
    const bool passed = r.passed && dg.passed();
    if (!options->report.empty()) {
      requireDistinct(options->report, options->input);
      nlohmann::json report{{"command", "check"}, {"input", options->input}};
      report.update(toJson(r));  // the geometric keys at the top level too
      report["validation"] = validationJson(r, dg);
      report["passed"] = passed;
      writeReport(options->report, report);
    }
    if (!common.quiet) {
      std::cout << options->input << ": " << (passed ? "valid" : "INVALID") << ", " << r.elements
                << " elements, " << r.faces << " faces (" << r.interiorFaces << " interior), "
                << r.components << " component(s), volume " << r.volume << '\n';
      for (const std::string& m : r.messages) std::cout << "  " << m << '\n';
      printDg(dg);
      if (dg.local)
        for (const std::string& m : failureMessages(*dg.local)) std::cout << "  " << m << '\n';
    }
    exitCode = passed ? 0 : 1;
  });
}

}  // namespace polydg::cli
