// What a simulation's adaptivity (scene "adapt") may refine again or merge back: each
// element's refinement level and the families (the children of one refined element), followed
// across every edit of the mesh. Private to model/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "polydg/model/model.h"
#include "polydg/model/scene.h"

namespace polydg {

class RefinementFamilies {
 public:
  explicit RefinementFamilies(std::size_t elements) : level_(elements, 0), family_(elements, -1) {}

  /// The elements to split: a principal stress above adapt.stress in absolute value and a level
  /// below adapt.maxLevel, with their principal directions (for halves).
  RefineRequest refinement(const ElementFields& fields, const SceneAdapt& adapt) const;
  /// The families to merge back: all children still there, none refined further, every
  /// principal stress below adapt.coarsen * adapt.stress (none if adapt.coarsen is 0).
  CoarsenRequest coarsening(const ElementFields& fields, const SceneAdapt& adapt) const;

  /// After an edit: a refinement of the elements `refined`, a coarsening, or a cut.
  void afterRefinement(const ElementLineage& lineage, std::size_t elements,
                       const std::unordered_set<std::uint32_t>& refined);
  void afterCoarsening(const ElementLineage& lineage, std::size_t elements);
  void afterCut(const ElementLineage& lineage, std::size_t elements);

 private:
  void familiesAfter(const ElementLineage& lineage, std::size_t elements,
                     const std::unordered_set<std::uint32_t>& refined, bool merged);

  std::vector<int> level_;
  /// Each element's family (-1: none), each family's parent family and its number of children.
  std::vector<int> family_, familyParent_;
  std::vector<std::size_t> familySize_;
};

}  // namespace polydg
