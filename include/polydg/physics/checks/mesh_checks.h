// The checks polydg runs on a whole mesh, composed in one place: the geometric validation, the
// element-local DG checks, and the global patch test and zero-mode count. `polydg check`,
// `polydg mesh`, pipeline check steps, full cut validation and the model API all call
// checkMesh(); the per-operation region checks of a cut are in region_checks.h.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "polydg/mesh/geometry_checks.h"
#include "polydg/physics/checks/dg_checks.h"

namespace polydg {

/// Largest number of DOFs (elements x 3 numMonomials(degree)) for which the global zero modes
/// are counted when GlobalCheck::UpToLimit asks for them (rigidModes(): assembly, then a CHOLMOD
/// factorization and subspace iteration per component). Measured on sliced spheres, degree 1,
/// two cores: 4.9k DOFs 0.22 s, 14k 0.9 s, 22k 1.5 s, 31k 2.6 s, 58k 6.0 s, 100k 12 s; the
/// limit keeps the count under 2 s. Larger meshes get the element-local checks only.
inline constexpr std::size_t kGlobalRigidModesDofLimit = 25'000;

/// When a global check (one assembly and factorization of the whole mesh) runs.
enum class GlobalCheck {
  Never,
  UpToLimit,  ///< up to MeshCheckOptions::globalDofLimit DOFs; a note says when skipped
  Always,
};

struct MeshCheckOptions {
  int degree = 1;  ///< of the DG checks, 1..3
  /// The geometric validation (checkGeometry()). The DG checks presume a valid mesh and run only
  /// after it passed; a caller that validates in parallel itself (meshing) turns it off.
  bool geometry = true;
  GeometryCheckOptions geometryOptions;
  /// The element-local DG checks (localDgChecks(): patch test, rigid modes, definiteness).
  bool local = true;
  /// Local checks of whole grid cells (isGridHexahedron(): congruent boxes) only on the first
  /// one, which stands for all: their local equations are the same up to translation (the
  /// geometric validation still covers each). For meshes fresh from the slicer.
  bool oneGridCellForAll = false;
  GlobalCheck patchTest = GlobalCheck::Never;       ///< patchTest() of the whole mesh
  GlobalCheck rigidModes = GlobalCheck::UpToLimit;  ///< rigidModes(): 6 per component
  std::size_t globalDofLimit = kGlobalRigidModesDofLimit;
  PhysicsCheckOptions
      physics;  ///< method, material, penalty of the DG checks (basis degree is `degree`)
};

/// What checkMesh() found; a check that did not run is empty and `notes` says why.
struct MeshCheck {
  int degree = 1;
  std::size_t dofs = 0;  ///< elements x 3 numMonomials(degree)
  std::optional<GeometryCheck> geometry;
  std::optional<LocalDgCheck> local;
  double localSeconds = 0.0;  ///< wall, with the moments it integrated
  std::optional<PatchTestResult> patch;
  double patchSeconds = 0.0;
  std::optional<ZeroModeReport> rigid;
  double rigidSeconds = 0.0;
  std::size_t facesIntegrated = 0;  ///< faces the checks integrated (0 with the caller's moments)
  std::vector<std::string> notes;   ///< one line per check that did not run, and why

  bool geometryPassed() const { return !geometry || geometry->passed; }
  bool rigidPassed() const;  ///< exactly 6 zero modes per component (true if not counted)
  bool passed() const;
  /// One line per failed check, the geometric problems first (empty when passed).
  std::vector<std::string> failures() const;
};

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
