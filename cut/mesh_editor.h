// MeshEditor: a mesh and its moment cache, edited in place by cuts, refinements, coarsenings
// and sliver merges (the operations and their reports are cut.h's).
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "polydg/cut/cut.h"

namespace polydg {

/// Owns a mesh and its moment cache and applies operations to them in place. Element and face
/// ids may change with each operation (removed ones are replaced by the last ones); ids stay
/// dense, so FaceData / ElementData keep working on the result.
class MeshEditor {
 public:
  /// Takes a valid mesh and integrates all its faces once. `referenceVolume` is the volume that
  /// sliver fractions multiply (the grid cell volume of a sliced mesh); 0: the median element
  /// volume of `mesh`.
  explicit MeshEditor(PolyMesh mesh, double referenceVolume = 0.0);
  /// The same with the mesh's moments already integrated (up to date for `mesh`, degree >= 2;
  /// they are taken over, nothing is integrated again); a null or lower-degree cache is
  /// replaced as above.
  MeshEditor(PolyMesh mesh, double referenceVolume, std::unique_ptr<MomentCache> moments);
  ~MeshEditor();
  MeshEditor(MeshEditor&&) noexcept;
  MeshEditor& operator=(MeshEditor&&) noexcept;

  const PolyMesh& mesh() const;
  /// Moments up to degree 2 * the largest validation degree used so far (at least 2), or the
  /// degree last asked of requireMoments().
  const MomentCache& moments() const;
  /// The moments up to at least `degree`: if the cache holds less, every face is integrated
  /// again, once, to that degree (and kept up to date from then on).
  const MomentCache& requireMoments(int degree);
  /// Faces integrated since the editor was made (with the integrations of a cache it was given):
  /// the work the cache saved shows as a count that grows only with what edits changed.
  std::size_t facesIntegrated() const;
  double referenceVolume() const;
  /// Total volume, kept up to date incrementally.
  double volume() const;

  /// Cuts with `blade`. When validation fails the report says so (validation.passed == false,
  /// validation.failure names the check; "split: ..." when a piece could not be closed) and
  /// the mesh must not be used further: callers stop and leave their input untouched.
  /// Throws std::invalid_argument for invalid options.
  OperationReport cut(const Blade& blade, const CutOptions& options = {});

  /// Splits each listed element by its planes (no plane may miss it), keeping the new faces
  /// coupled: neighbours' faces are split so faces stay shared exactly, and only what changed
  /// is integrated again. Checked like a cut (a failure is reported, as by cut()). Throws
  /// std::invalid_argument for an element listed twice, an invalid id or bad options.
  OperationReport refine(std::span<const ElementRefinement> elements,
                         const RefineOptions& options = {});

  /// Merges each group of elements (at least two, face-connected, no element in two groups)
  /// into one element: the faces between them disappear, their other faces become the new
  /// element's (coarsening after refine()). Checked like a cut. Throws std::invalid_argument for
  /// an invalid id, a group of fewer than two or an element listed twice.
  OperationReport coarsen(std::span<const std::vector<ElementId>> groups,
                          CheckLevel checks = CheckLevel::Local, int checkDegree = 1);

  /// Merges every element below `fraction` * referenceVolume() into a neighbour, as after a cut.
  OperationReport mergeSlivers(double fraction, CheckLevel checks = CheckLevel::Local,
                               int checkDegree = 1);

  /// Gives the mesh back (the editor is empty afterwards).
  PolyMesh release();

  struct State;  ///< defined in cut/editor_state.h (private to cut/)

 private:
  OperationReport cutInPlace(const Blade& blade, const CutOptions& options);
  OperationReport refineInPlace(std::span<const ElementRefinement> elements,
                                const RefineOptions& options);
  /// Replaces the moment cache with one of at least `degree` (every face integrated again,
  /// once) if it holds less; returns the number of faces integrated.
  std::size_t raiseMomentDegree(int degree);

  std::unique_ptr<State> state_;
};

}  // namespace polydg
