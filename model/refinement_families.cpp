#include "model/refinement_families.h"

#include <cmath>
#include <unordered_map>

#include "model/field_transfer.h"

namespace polydg {

RefineRequest RefinementFamilies::refinement(const ElementFields& fields,
                                             const SceneAdapt& adapt) const {
  RefineRequest request;
  request.split = adapt.split;
  request.checks = CheckLevel::None;
  for (std::size_t e = 0; e < level_.size(); ++e)
    if (level_[e] < adapt.maxLevel &&
        std::abs(fields.principalStress[ElementId(e)]) > adapt.stress) {
      request.elements.push_back(ElementId(e));
      request.directions.push_back(fields.principalDirection[ElementId(e)]);
    }
  return request;
}

CoarsenRequest RefinementFamilies::coarsening(const ElementFields& fields,
                                              const SceneAdapt& adapt) const {
  CoarsenRequest request;
  request.checks = CheckLevel::None;
  if (!(adapt.coarsen > 0.0)) return request;
  std::vector<std::vector<ElementId>> members(familySize_.size());
  std::vector<char> keep(familySize_.size(), 1);
  for (std::size_t e = 0; e < family_.size(); ++e) {
    if (family_[e] < 0) continue;
    const std::size_t f = static_cast<std::size_t>(family_[e]);
    members[f].push_back(ElementId(e));
    if (std::abs(fields.principalStress[ElementId(e)]) >= adapt.coarsen * adapt.stress) keep[f] = 0;
  }
  for (std::size_t f = 0; f < members.size(); ++f)
    if (keep[f] && members[f].size() == familySize_[f] && members[f].size() >= 2)
      request.groups.push_back(members[f]);
  return request;
}

void RefinementFamilies::afterRefinement(const ElementLineage& lineage, std::size_t elements,
                                         const std::unordered_set<std::uint32_t>& refined) {
  level_ = levelsAfter(level_, lineage, elements, refined);
  familiesAfter(lineage, elements, refined, false);
}

void RefinementFamilies::afterCoarsening(const ElementLineage& lineage, std::size_t elements) {
  std::vector<int> next(elements, 0);
  for (std::size_t e = 0; e < next.size(); ++e) {
    const std::vector<ElementId> sources = lineage.sources(ElementId(e));
    next[e] = level_[sources.front().index()] - (sources.size() > 1 ? 1 : 0);
  }
  level_ = std::move(next);
  familiesAfter(lineage, elements, {}, true);
}

void RefinementFamilies::afterCut(const ElementLineage& lineage, std::size_t elements) {
  level_ = levelsAfter(level_, lineage, elements, {});
  familiesAfter(lineage, elements, {}, false);
}

/// Children of a refined element form a new family (whose parent is the element's family); a
/// merge returns its elements to their parent family; everything else keeps its family.
void RefinementFamilies::familiesAfter(const ElementLineage& lineage, std::size_t elements,
                                       const std::unordered_set<std::uint32_t>& refined,
                                       bool merged) {
  std::unordered_map<std::uint32_t, int> made;  // refined element -> its children's family
  std::vector<int> next(elements, -1);
  for (std::size_t e = 0; e < next.size(); ++e) {
    const std::vector<ElementId> sources = lineage.sources(ElementId(e));
    const ElementId s = sources.front();
    if (refined.count(s.value)) {
      auto [it, inserted] = made.try_emplace(s.value, static_cast<int>(familyParent_.size()));
      if (inserted) {
        familyParent_.push_back(family_[s.index()]);
        familySize_.push_back(0);
      }
      next[e] = it->second;
      ++familySize_[static_cast<std::size_t>(it->second)];
    } else if (merged && sources.size() > 1 && family_[s.index()] >= 0) {
      next[e] = familyParent_[static_cast<std::size_t>(family_[s.index()])];
    } else {
      next[e] = family_[s.index()];
    }
  }
  family_ = std::move(next);
}

}  // namespace polydg
