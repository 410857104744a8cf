// What the checks of a mesh are asked and what they found: the DG checks (patch test, rigid
// modes, definiteness, element by element or global), the composed checks of a whole mesh
// (checkMesh()) and the checks after an edit. physics/checks/ runs them.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "polydg/mesh/geometry_checks.h"
#include "polydg/physics/dg/discretization.h"
#include "polydg/physics/dg/material.h"

namespace polydg {

/// The discretization checked (material and penalty as in a solve).
struct PhysicsCheckOptions {
  Material material;
  DiscretizationOptions discretization;
};

struct PatchTestResult {
  double relativeError = 0.0;    ///< |u_h - u|_L2 / |u|_L2 over the mesh
  double maxElementError = 0.0;  ///< max over elements of |u_h - u|_L2(K) / |u|_L2(K)
  double eta = 0.0;
  double residual = 0.0;  ///< of the linear solve
};

/// An element passes the local patch test when its error (LocalDgCheck::maxPatchTestError) is
/// below this, the global patch test's tolerance. Valid meshes give 1e-17 .. 1e-14 (a sliced
/// sphere, meshes scaled by 1e+-6 or translated by 1e6), up to 2.3e-10 on the corpus' sliver of
/// relative thickness 1e-6 at degree 3 (its local system is ill-conditioned). A vertex moved off
/// its faces' planes by 1e-3 of the element size gives ~1e-5 (so a mesh whose faces are planar
/// only to single precision, which the geometric check accepts, fails it: such a mesh reproduces
/// linear fields only to about its planarity), a reversed face ~1e-2. An inverted element
/// passes (it is consistent with the opposite orientation) but fails the other two checks.
inline constexpr double kLocalPatchTestTolerance = 1e-9;

/// The discretization of the local checks: the IP method (BZ is inconsistent and fails any
/// patch test), with the basis and material as in a solve.
struct LocalDgCheckOptions {
  BasisOptions basis;
  Material material;
  /// If not empty (one entry per element), only elements with a non-zero entry are checked;
  /// the others still give their neighbours the exact linear trace.
  std::vector<char> only;
};

/// Result of localDgChecks(). Element ids refer to the mesh checked.
struct LocalDgCheck {
  int degree = 0;
  std::size_t elements = 0;  ///< elements checked (all, or those selected by `only`)
  /// Max over elements of the local patch-test error (see localDgChecks()); +inf when a local
  /// solve produced a non-finite value.
  double maxPatchTestError = 0.0;
  ElementId worstPatchTestElement;              ///< where the maximum is (invalid if none)
  std::size_t patchTestFailures = 0;            ///< elements above kLocalPatchTestTolerance
  std::size_t elementsWithWrongRigidModes = 0;  ///< stiffness without exactly 6 zero modes
  ElementId firstWrongRigidModeElement;         ///< lowest such id (invalid if none)
  /// Elements whose local IP matrix was not positive definite (a pivot of its LDL^T was not
  /// positive; the error is then computed with a full-pivoting LU solve). The local penalty
  /// makes it SPD on every valid element.
  std::size_t nonDefiniteElements = 0;
  double seconds = 0.0;  ///< wall time, bases included (moments excluded)
  /// Faces whose moments the checks integrated (localDgChecksOfSelection(); 0 when the caller
  /// gave the moments).
  std::size_t facesIntegrated = 0;

  bool passed() const {
    return maxPatchTestError < kLocalPatchTestTolerance && elementsWithWrongRigidModes == 0 &&
           nonDefiniteElements == 0;
  }
};

struct ZeroModeReport {
  std::size_t components = 0;                      ///< connected through shared faces
  std::vector<std::size_t> zeroModesPerComponent;  ///< eigenvalues below kZeroModeThreshold
  std::size_t zeroModes = 0;                       ///< their sum
  double largestZeroEigenvalue = 0.0;              ///< largest of those (Jacobi-scaled)
  double smallestNonzeroEigenvalue = 0.0;  ///< smallest eigenvalue above the threshold found
  /// max over the 6 rigid motions r of each component of |S r| / |r|, S the scaled matrix.
  double rigidMotionResidual = 0.0;
};

/// Largest number of DOFs (elements x 3 numMonomials(degree)) for which the global zero modes
/// are counted when GlobalCheck::UpToLimit asks for them (rigidModes(): assembly, then a CHOLMOD
/// factorization and subspace iteration per component), whose cost grows faster than the DOFs:
/// the limit keeps it under about 2 s on two cores (docs/benchmarks.md). Larger meshes get the
/// element-local checks only.
inline constexpr std::size_t kGlobalRigidModesDofLimit = 25'000;

/// When a global check (one assembly and factorization of the whole mesh) runs.
enum class GlobalCheck {
  Never,
  UpToLimit,  ///< up to MeshCheckOptions::globalDofLimit DOFs; a note says when skipped
  Always,
};

struct MeshCheckOptions {
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
  PhysicsCheckOptions physics;  ///< material and discretization of the DG checks

  /// The degree of the DG checks (physics.discretization.basis.degree).
  int degree() const { return physics.discretization.basis.degree; }
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

/// How much checking follows each operation.
enum class CheckLevel {
  None,   ///< volume bookkeeping only
  Local,  ///< geometric checks of the touched elements; DG patch test and rigid-mode count on
          ///< the touched elements plus one ring of neighbours (regionDgChecks() with
          ///< RegionCoupling::HoldingFaces); global volume balance
  Full,   ///< geometric checks of the whole mesh; global patch test and rigid modes
};

/// The outcome of the checks after one operation.
struct OperationCheck {
  CheckLevel level = CheckLevel::None;
  bool passed = true;
  std::size_t elementsChecked = 0;  ///< geometric checks
  std::size_t regionElements = 0;   ///< DG region (touched elements plus one ring)
  double patchTestError = 0.0;  ///< Local: the region's patch-test residual; Full: relative error
  /// Local: components of the region's coupling graph, its elements joined through the faces
  /// that hold them together (RegionCoupling::HoldingFaces); Full: of the mesh.
  std::size_t regionComponents = 0;
  std::size_t zeroModes = 0;    ///< expected: 6 * regionComponents
  double volumeRelError = 0.0;  ///< |V_before - V_removed - V_after| / V_before
  std::string failure;          ///< first failed check, one line; empty when passed
  double seconds = 0.0;         ///< wall time of the checks
};

}  // namespace polydg
