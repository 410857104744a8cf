// The inside of a Model (model/model.cpp, model/simulate.cpp): its parts and the steps its
// operations share. Private to model/.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cut/mesh_editor.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/model/model.h"
#include "polydg/util/error.h"

namespace polydg {

/// The model's parts. Until the first edit the model holds the mesh and its moment cache
/// itself; the first cut or merge hands both to a MeshEditor, which owns them from then on.
struct Model::State {
  Provenance provenance;
  PolyMesh mesh;                         ///< until the first edit
  std::unique_ptr<MomentCache> moments;  ///< until the first edit (null until needed)
  std::unique_ptr<MeshEditor> editor;    ///< from the first edit
  std::size_t retiredIntegrations = 0;   ///< faces integrated by caches replaced before it
  /// Whether the mesh is known to pass checkGeometry(): set by a passed validation, kept by edits
  /// whose own validation passed, unknown (nullopt) after an unvalidated edit.
  std::optional<bool> valid;
  /// Set by an operation that failed part-way: the mesh must not be used further.
  std::string broken;
  std::optional<Solution> solution;

  const PolyMesh& currentMesh() const { return editor ? editor->mesh() : mesh; }
  const MomentCache* currentMoments() const { return editor ? &editor->moments() : moments.get(); }
  MeshEditor& edit() {
    if (!editor) {
      if (!(provenance.referenceVolume > 0.0))
        throw InputError(
            "the mesh's median element volume is not positive (inverted or flat "
            "elements), so no sliver rule applies; run 'polydg check' on it");
      editor = std::make_unique<MeshEditor>(std::move(mesh), provenance.referenceVolume,
                                            std::move(moments));
      mesh = PolyMesh();
    }
    return *editor;
  }
  void requireUsable() const {
    if (!broken.empty())
      throw CheckFailure("the model cannot be used after a failed operation (" + broken +
                         "); start again from its input");
  }
  /// Validates the mesh unless known valid; throws CheckFailure naming the first defect.
  void requireValid();
  /// Counts the boundary faces each clamp and load selects; throws InputError naming a
  /// selection that picks none ("CLAMPWORD REGION selects no boundary face ...").
  void checkSelections(const std::vector<FaceSelector>& clamps,
                       const std::vector<const FaceSelector*>& loads,
                       std::vector<std::size_t>& clampFaces, std::vector<std::size_t>& loadFaces,
                       const char* clampWord = "the clamp",
                       const char* loadWord = "the traction on") const;
  /// Makes `coefficients` in `basis` the model's solution (corner values and element fields).
  void adoptSolution(std::unique_ptr<DgBasis> basis, Eigen::VectorXd coefficients,
                     const Material& material, const MomentCache& moments);
  /// Makes a tet method's nodal displacement (node-major) on `tets`, whose tet t is element t,
  /// the model's solution: linear on each tet, so exactly DG degree 1 (tetCoefficients).
  void adoptTetSolution(const TetMesh& tets, const Eigen::VectorXd& displacement,
                        const Material& material, const MomentCache& moments);
  /// What follows every edit (cut or merge): the solution no longer fits the mesh; an edit that
  /// left no element fails; a failed one breaks the model; an unvalidated one leaves its
  /// validity unknown.
  void finishEdit(OperationReport& report, CheckLevel checks) {
    solution.reset();
    if (currentMesh().numElements() == 0 && report.check.passed) {
      report.check.passed = false;
      report.check.failure =
          "the " + report.op + " left no element (everything was removed); nothing to write";
    }
    if (!report.check.passed)
      broken = report.op + " failed: " + report.check.failure;
    else if (checks == CheckLevel::None)
      valid.reset();
  }
};

/// Runs an option struct's check(): what it refuses is the caller's input (InputError).
template <class Check>
void refuseInvalid(Check&& check) {
  try {
    check();
  } catch (const InvalidOption& e) {
    throw InputError(e.what());
  }
}

/// The options cuts and merges share, checked before the mesh is touched.
inline void checkEditOptions(double sliverFraction, int checkDegree) {
  if (!(sliverFraction >= 0.0 && sliverFraction <= 1.0))
    throw InputError("the sliver fraction must be a number in [0, 1]");
  if (checkDegree < 1 || checkDegree > 3)
    throw InputError("the validation degree must be 1, 2 or 3");
}

/// Model::solve() with SolveOptions::adapt set (adapt.cpp).
SolveReport solveAdaptively(Model& model, const SolveOptions& options);

}  // namespace polydg
